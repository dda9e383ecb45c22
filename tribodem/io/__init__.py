"""Input/output: validated configs, atomic result files, VTK snapshots."""
