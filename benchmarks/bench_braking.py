"""CPU time per step of the braking cell's sliding loop, without the run's I/O.

Builds the interface of ``tribodem braking run --condition 5`` (``--quick``: the quick
cell), starts the sliding and the braking loop's drive (``SlidingDrive``), warms the
kernels up for 200 steps, then times ``--steps`` steps with ``time.process_time`` and
prints one JSON line: particles, bonds, listed pairs, neighbour builds, CPU us per step
and a checksum of the positions (the sum of all coordinates: equal checksums = the same
trajectory, to check that a change leaves the results bitwise alone).

    .venv/bin/python benchmarks/bench_braking.py --steps 20000
    PYTHONPATH=/path/to/other/tree .venv/bin/python benchmarks/bench_braking.py  # A/B
"""

from __future__ import annotations

import argparse
import json
import time

from tribodem.braking.config import resolve_config, setup_from_config
from tribodem.braking.drive import SlidingDrive
from tribodem.braking.model import build_interface, start_sliding


def main() -> None:
    """Parse the options, build the cell, time the steps, print the JSON line."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--steps", type=int, default=20000, help="timed steps (default 20000)")
    ap.add_argument("--condition", type=int, default=5, help="table 4 condition (default 5)")
    ap.add_argument("--quick", action="store_true", help="the --quick cell")
    a = ap.parse_args()
    s = setup_from_config(resolve_config(condition=a.condition, quick=a.quick))
    iface = build_interface(s.geometry, s.pressure_Pa, s.micro, s.wall_mass_ratio,
                            s.dt_safety, s.local_damping, s.backing, s.plate_areal_mass)
    start_sliding(iface, s.speed_m_s)
    sim = iface.sim
    sim.add_interaction(SlidingDrive(iface, 0, 0, s.speed_m_s))
    sim.step(200)  # kernels compiled or loaded, first neighbour builds
    c0 = time.process_time()
    sim.step(a.steps)
    cpu = time.process_time() - c0
    print(json.dumps({
        "condition": a.condition, "quick": a.quick, "particles": sim.p.n,
        "bonds": iface.bonds.n_bonds, "pairs": sim.nl.n_pairs, "steps": a.steps,
        "neighbor_builds": sim.nl.builds, "broken_bonds": iface.bonds.broken_count(),
        "cpu_s": cpu, "cpu_us_per_step": 1e6 * cpu / a.steps,
        "pos_checksum": repr(float(sim.p.pos.sum()))}))


if __name__ == "__main__":
    main()
