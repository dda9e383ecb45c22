"""Clump throughput: 80,000 debris clumps (thirds of spherical / chunk / rubbing, d = 0.6 um,
steel, Hertz-Mindlin CoR 0.72, mu 0.6, mu_r 0.001) settling on a plane under gravity with a
light boundary-moving top load (Lu (2018) eqs 3.2-3.6), periodic in x and y.

    .venv/bin/python benchmarks/bench_clumps.py [--clumps 80000] [--steps 300] [--threads 1 2]

Start: a dense lattice (spacing 0.85 x the largest clump's bounding diameter) with random
orientations re-drawn until no members of different clumps overlap, random velocities of
2 m/s (agitation, so contacts form within the timed steps).
Prints JSON: particle-steps/s counted on members and on bodies.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numba
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from tribodem.dem import Box, Material, PlaneWall, Simulation, neighbors  # noqa: E402
from tribodem.dem.clumps import (  # noqa: E402
    DEBRIS_SHAPES,
    debris_template,
    make_clumps,
    random_quaternions,
)

STEEL = Material(name="steel", young=2.1e11, poisson=0.3, density=7850.0, cor=0.72,
                 friction=0.6, rolling_friction=0.001)


def build(n_clumps: int, d: float = 0.6e-6, seed: int = 0) -> tuple[Simulation, object]:
    """The settling bed: n clumps on a lattice, floor wall, top servo wall."""
    rng = np.random.default_rng(seed)
    temps = [debris_template(s, d) for s in DEBRIS_SHAPES]
    bound = max(float((np.linalg.norm(t.offsets, axis=1) + t.radii).max()) for t in temps)
    s = 2.0 * bound * 0.85
    nx = ny = max(2, int(round(math.sqrt(n_clumps / 30))))  # ~30 layers deep
    nz = int(math.ceil(n_clumps / (nx * ny)))
    idx = np.arange(n_clumps)
    pos = np.stack([(idx % nx + 0.5) * s, (idx // nx % ny + 0.5) * s,
                    idx // (nx * ny) * s + 1.001 * bound], axis=1)
    kind = idx % 3
    vel = rng.normal(0, 2.0 / math.sqrt(3), (n_clumps, 3))
    quat = random_quaternions(n_clumps, rng)
    lx, ly, top = nx * s, ny * s, (nz - 1) * s + 2.002 * bound
    lo, hi, per = np.array([0, 0, -s]), np.array([lx, ly, top + s]), np.array([1, 1, 0], bool)
    for _ in range(200):  # re-draw orientations of clumps whose members overlap others
        p, cl = make_clumps(temps, kind, pos, quat, density=7850.0, vel=vel)
        nl = cl.filter_pairs(neighbors.build(p.pos, p.radius, 0.0, lo, hi, per))
        if nl.n_pairs == 0:
            break
        bad = np.unique(cl.body_of[np.concatenate([nl.pair_i, nl.pair_j])])
        quat[bad] = random_quaternions(bad.size, rng)
    else:
        raise RuntimeError("bench_clumps: could not place the clumps without overlaps")
    floor = PlaneWall([0, 0, 0], [0, 0, 1], name="floor")
    lid = PlaneWall([0, 0, top], [0, 0, -1], mode="boundary", target_force=1e-6,
                    servo_mass=float(cl.mass.sum()), max_speed=1.0, name="top")
    sim = Simulation(p, [STEEL], Box(lo, hi, per),
                     walls=[floor, lid], gravity=(0, 0, -9.81), local_damping=0.0)
    sim.add_interaction(cl)
    return sim, cl


def point(n_clumps: int, steps: int, threads: int) -> dict:
    numba.set_num_threads(threads)
    sim, cl = build(n_clumps)
    sim.step(5)  # compile / warm
    t0 = time.perf_counter()
    sim.step(steps)
    wall = time.perf_counter() - t0
    return {"case": "clumps_settle", "clumps": cl.n, "members": int(cl.members.size),
            "steps": steps, "threads": numba.get_num_threads(), "seconds": wall,
            "member_steps_per_s": cl.members.size * steps / wall,
            "body_steps_per_s": cl.n * steps / wall, "contacts_end": sim.n_contacts(),
            "floor_contacts_end": sim.walls[0].contacts, "neighbor_builds": sim.nl.builds,
            "dt_s": sim.dt}


def main(argv: list[str] | None = None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--clumps", type=int, default=80_000)
    ap.add_argument("--steps", type=int, default=300)
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    args = ap.parse_args(argv)
    out = [point(args.clumps, args.steps, t) for t in args.threads]
    print(json.dumps(out, indent=1))
    return out


if __name__ == "__main__":
    main()
