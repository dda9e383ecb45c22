"""DE phase of the debris third body: N debris clumps loaded to equilibrium (docs/debris.md).

The default case: crossed 8 mm cylinders at 100 N (window 128^2), a worn scar shaped like
the contact pressure holding the volume of N particles of d = 0.6 um (equal thirds of the
three shapes), the target from eqs 3.11-3.15, servo to 1e-4. Prints one JSON line.

    .venv/bin/python benchmarks/bench_debris.py --particles 80000
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time

import numba
import numpy as np

from tribodem.contact import HalfSpaceSolver
from tribodem.fretting.debris import DebrisField, DebrisSettings, debris_target, run_de_phase


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--particles", type=int, default=80_000)
    ap.add_argument("--n", type=int, default=128, help="solver window points per side")
    ap.add_argument("--threads", type=int, default=numba.config.NUMBA_NUM_THREADS)
    args = ap.parse_args()
    numba.set_num_threads(args.threads)
    sol = HalfSpaceSolver(n=args.n, tolerance=1e-6)
    p, gap = sol.loaded_solution(0.0)
    c = sol.coords
    xw, yw = np.meshgrid(c, c, indexing="ij")
    s = DebrisSettings(seed=0)
    field = DebrisField(s)
    depth = p / p.sum() * args.particles * s.particle_volume / sol.dx**2
    field.generate(1, [(depth, c, c)], sol.dx**2)
    target = debris_target(field, p, c, sol.dx, sol.load)
    t0 = time.perf_counter()
    res = run_de_phase(field, np.asarray(sol.lower(xw, yw)), gap, c, target)
    wall = time.perf_counter() - t0
    sol.set_debris_pressure(res.pressure)
    p_with = sol.loaded_solution(0.0, debris=True)[0]
    solid = p_with - sol.debris_pressure
    print(json.dumps({
        "case": "debris DE phase, crossed cylinders 100 N", "particles": res.particles,
        "active_particles": res.active_particles, "members": res.members,
        "debris_load_fraction": sol.debris_load / sol.load,
        "max_pressure_without_debris_Pa": float(p.max()),
        "max_pressure_with_debris_Pa": float(p_with.max()),
        "max_solid_pressure_with_debris_Pa": float(solid.max()),
        "target_N": res.target_N, "rel_error": res.rel_error, "converged": res.converged,
        "steps": res.steps, "wall_s": wall, "threads": args.threads,
        "member_steps_per_s": res.members * res.steps / wall,
        "load_average": os.getloadavg()[0], "machine": platform.processor() or platform.machine(),
    }))


if __name__ == "__main__":
    main()
