"""VTK output for ParaView: particles as vertex clouds, force chains as line cells.

Files are VTK XML unstructured grids (``.vtu``, written by meshio, atomically) plus a
``.pvd`` collection indexing the snapshots with their simulated times.
"""

from __future__ import annotations

from pathlib import Path

import meshio
import numpy as np

from tribodem.io.results import atomic_write, write_text


def write_points(path: str | Path, points: np.ndarray, point_data: dict[str, np.ndarray]
                 ) -> Path:
    """Particles as VTK vertices with per-point data (vectors as (N, 3) arrays)."""
    pts = np.ascontiguousarray(points, dtype=np.float64)
    cells = [("vertex", np.arange(pts.shape[0], dtype=np.int64).reshape(-1, 1))]
    mesh = meshio.Mesh(pts, cells, point_data={k: np.asarray(v) for k, v in point_data.items()})
    return atomic_write(path, lambda p: meshio.write(p, mesh, file_format="vtu"))


def write_lines(path: str | Path, points: np.ndarray, lines: np.ndarray,
                cell_data: dict[str, np.ndarray]) -> Path:
    """Line cells between ``points`` (force chains: contacts, bonds) with per-line data."""
    pts = np.ascontiguousarray(points, dtype=np.float64)
    ln = np.asarray(lines, dtype=np.int64).reshape(-1, 2)
    mesh = meshio.Mesh(pts, [("line", ln)],
                       cell_data={k: [np.asarray(v)] for k, v in cell_data.items()})
    return atomic_write(path, lambda p: meshio.write(p, mesh, file_format="vtu"))


def write_pvd(path: str | Path, entries: list[tuple[float, str]]) -> Path:
    """ParaView collection: ``entries`` are (time s, relative file name)."""
    rows = "\n".join(f'    <DataSet timestep="{t:.9g}" part="0" file="{f}"/>' for t, f in entries)
    text = ('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n'
            f"  <Collection>\n{rows}\n  </Collection>\n</VTKFile>\n")
    return write_text(path, text)
