"""CPU time per step of the braking cell's sliding loop, without the run's I/O.

Builds the interface of ``tribodem braking run --condition 5`` (``--quick``: the quick
cell; ``--config FILE``: a config's cell), starts the sliding and the braking loop's drive
(``SlidingDrive``), warms the kernels up for 200 steps, then times ``--steps`` steps with
``time.process_time`` and prints one JSON line: particles, bonds, listed pairs, neighbour
builds, CPU us per step, particle-steps per CPU second, CPU seconds per mm of sliding
and a checksum of the positions (the sum of all coordinates: equal checksums = the same
trajectory, to check that a change leaves the results bitwise alone). ``--profile``
adds the step's CPU time by kernel (``benchmarks/profile_step.py``'s kernel-by-kernel
loop: the same kernels in the same order, so the same bits).

    .venv/bin/python benchmarks/bench_braking.py --steps 20000
    .venv/bin/python benchmarks/bench_braking.py --config CELL.toml --steps 2000 --profile
    PYTHONPATH=/path/to/other/tree .venv/bin/python benchmarks/bench_braking.py  # A/B
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numba

sys.path.insert(0, str(Path(__file__).resolve().parent))

from profile_step import new_timers, step_by_kernel  # noqa: E402

from tribodem.braking.config import resolve_config, setup_from_config  # noqa: E402
from tribodem.braking.drive import SlidingDrive  # noqa: E402
from tribodem.braking.model import build_interface, start_sliding  # noqa: E402


def main() -> None:
    """Parse the options, build the cell, time the steps, print the JSON line."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--steps", type=int, default=20000, help="timed steps (default 20000)")
    ap.add_argument("--condition", type=int, default=5, help="table 4 condition (default 5)")
    ap.add_argument("--quick", action="store_true", help="the --quick cell")
    ap.add_argument("--config", default=None, help="a braking config (TOML) for the cell")
    ap.add_argument("--profile", action="store_true",
                    help="also the CPU time per step by kernel (as many steps again)")
    a = ap.parse_args()
    numba.set_num_threads(1)
    s = setup_from_config(resolve_config(a.config, condition=a.condition, quick=a.quick))
    t0 = time.perf_counter()
    iface = build_interface(s.geometry, s.pressure_Pa, s.micro, s.wall_mass_ratio,
                            s.dt_safety, s.local_damping, s.backing, s.plate_areal_mass)
    build = time.perf_counter() - t0
    start_sliding(iface, s.speed_m_s)
    sim = iface.sim
    sim.add_interaction(SlidingDrive(iface, 0, 0, s.speed_m_s))
    sim.step(200)  # kernels compiled or loaded, first neighbour builds
    c0 = time.process_time()
    sim.step(a.steps)
    cpu = time.process_time() - c0
    us = 1e6 * cpu / a.steps
    out = {
        "condition": a.condition, "quick": a.quick, "config": a.config,
        "particles": sim.p.n, "bonds": iface.bonds.n_bonds, "pairs": sim.nl.n_pairs,
        "steps": a.steps, "dt_s": sim.dt, "build_wall_s": build,
        "neighbor_builds": sim.nl.builds, "broken_bonds": iface.bonds.broken_count(),
        "cpu_s": cpu, "cpu_us_per_step": us,
        "particle_steps_per_cpu_s": sim.p.n / (us * 1e-6),
        "cpu_s_per_mm": us * 1e-6 * 1e-3 / (s.speed_m_s * sim.dt),
        "pos_checksum": repr(float(sim.p.pos.sum()))}
    if a.profile:
        step_by_kernel(sim, 2, new_timers())  # compiles the per-interaction calls
        tim = new_timers()
        step_by_kernel(sim, a.steps, tim)
        out["kernels_us_per_step"] = {k: round(1e6 * v / a.steps, 2) for k, v in tim.items()}
    print(json.dumps(out))


if __name__ == "__main__":
    main()
