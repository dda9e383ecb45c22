"""Where a DEM step's time goes, kernel by kernel, on one thread.

Runs a benchmark case (``tribodem.dem.bench_cases``) with the compiled loop's own kernels
called one at a time from Python in the loop's order (``engine._run_steps``: rebuild
test -> pair contacts -> ``ext_force``/``ext_torque`` cleared -> each interaction's
compiled step -> wall pass -> particle update -> wall motion), and the loop's own
bookkeeping between segments (``Simulation._compiled_begin`` / ``_compiled_end``: the
neighbour rebuilds, the walls' state, the interactions' ``after_compiled`` hooks). Each
kernel's CPU time (``time.process_time``) is summed over ``--steps`` steps after
``--warmup`` steps, so every kernel runs on the caches the others leave, as in the real
loop (timing a kernel alone, on restored arrays, measures a colder or a warmer cache).
Then the same number of steps through ``Simulation.step`` (the compiled loop) gives the
real per-step time to compare with the kernels' sum (the difference: the ~1 us of Python
per kernel call here, and the loop's stability checks).

    .venv/bin/python benchmarks/profile_step.py --case bonded3d [--particles N]
        [--steps 400] [--warmup 300] [--json]

Serial builds only (one thread): the threaded loop runs other kernels (``pair_forces_
cross`` / ``pair_forces_blocked``).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numba
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tribodem.dem import engine as E  # noqa: E402
from tribodem.dem.bench import CASES, simulation_from_case  # noqa: E402
from tribodem.dem.compiled import NoStep  # noqa: E402
from tribodem.dem.contact import N_PCONST, pair_constants  # noqa: E402


def _segment(sim: E.Simulation, states: tuple, nmax: int, tim: dict[str, float]) -> int:
    """Up to ``nmax`` steps, kernel by kernel, until a rebuild or an event is due (as
    ``_run_steps`` on its serial build); adds CPU seconds per kernel into ``tim``."""
    pc = time.process_time
    t0 = pc()
    c, limit = sim._compiled_begin(nmax)
    pconst = np.empty((c.pair_i.shape[0], N_PCONST))
    pair_constants(c.radius, c.mass, c.inertia, c.mat, c.pair_i, c.pair_j, c.pairtab,
                   c.elin, c.dim, c.thickness, pconst)
    tim["rebuild + pair constants"] += pc() - t0
    pairs = E._pairs_2d if c.dim == 2 else E._pairs_3d
    alone = [(type(st).__name__, (st, NoStep())) for st in states if not isinstance(st, NoStep)]
    t = c.clock[0]
    k = 0
    while k < limit:
        t0 = pc()
        if k > 0 and E._must_rebuild(c):
            tim["rebuild test"] += pc() - t0
            break
        t1 = pc()
        tim["rebuild test"] += t1 - t0
        pairs(c.pos, c.vel, c.omega, c.radius, c.mass, c.inertia, c.mat, c.pair_i, c.pair_j,
              c.hist, c.pairtab, c.elin, c.length, c.periodic, c.dim, c.thickness, c.dt,
              c.fpair, c.tpair_i, c.tpair_j, c.pinfo, c.force, c.torque, pconst)
        t0 = pc()
        tim["pair contacts"] += t0 - t1
        ev = 0
        if c.has_ext:
            c.ext_force[:] = 0.0
            c.ext_torque[:] = 0.0
            t1 = pc()
            tim["clear ext_force/ext_torque"] += t1 - t0
            for name, one in alone:
                ev |= E._interactions(one, c)
                t0 = pc()
                tim[f"interaction {name}"] = tim.get(f"interaction {name}", 0.0) + t0 - t1
                t1 = t0
        t0 = pc()
        if c.wall_point.shape[0]:
            E._walls_pass(c.pos, c.vel, c.omega, c.radius, c.mass, c.inertia, c.mat, c.wstart,
                          c.wid, c.wpart, c.wbstart, c.wall_point, c.wall_normal, c.wall_vel,
                          c.wall_mat, c.wall_hist, c.wall_info, c.wsum, c.pairtab, c.elin,
                          c.dim, c.thickness, c.dt, c.wforce, c.wtorque, c.wall_tot)
            c.wall_nf[:] = -(c.wall_tot[:, :3] * c.wall_normal).sum(axis=1)
        t1 = pc()
        tim["wall pass"] += t1 - t0
        E._advance_serial(c.pos, c.vel, c.omega, c.radius, c.mass, c.inertia, c.fixed,
                          c.wstart, c.wforce, c.wtorque, c.dt, c.gravity, c.viscous, c.local,
                          c.has_ext, c.ext_force, c.ext_torque, c.force, c.torque, c.ref_pos,
                          c.ref_radius, c.lo, c.length, c.periodic, c.drift)
        t0 = pc()
        tim["particle update"] += t0 - t1
        E._move_walls(c)
        tim["wall motion"] += pc() - t0
        t += c.dt
        k += 1
        if ev:
            break
    c.clock[0] = t
    t0 = pc()
    sim._compiled_end(c, states, k)
    tim["between segments (Python)"] += pc() - t0
    return k


def new_timers() -> dict[str, float]:
    """Zeroed CPU-second sums per kernel (interactions add their own keys)."""
    return dict.fromkeys(("rebuild test", "rebuild + pair constants", "pair contacts",
                          "clear ext_force/ext_torque", "wall pass", "particle update",
                          "wall motion", "between segments (Python)"), 0.0)


def step_by_kernel(sim: E.Simulation, steps: int, tim: dict[str, float]) -> None:
    """``sim.step(steps)`` on one thread, kernel by kernel (the same kernels and order, so
    the same bits as the compiled loop: ``tests/test_dem_profile_step.py``)."""
    states = sim._compiled_states()
    if states is None:
        raise SystemExit("profile_step: this simulation does not run the compiled loop")
    done = 0
    while done < steps:
        done += _segment(sim, states, steps - done, tim)


def profile(case_name: str, n: int | None, steps: int, warmup: int) -> dict:
    """Per-kernel CPU time per step of ``steps`` steps of case ``case_name`` (one thread)."""
    numba.set_num_threads(1)
    kw = {} if n is None else {"n": n}
    case = CASES[case_name](**kw)
    sim = simulation_from_case(case)
    sim.step(warmup)  # compiles the loop and settles the state
    step_by_kernel(sim, 2, new_timers())  # compiles the per-interaction calls
    tim = new_timers()
    step_by_kernel(sim, steps, tim)
    c0 = time.process_time()
    sim.step(steps)
    loop = (time.process_time() - c0) / steps
    total = sum(tim.values()) / steps
    counts = {"particles": int(sim.p.n), "listed pairs": int(sim.nl.n_pairs),
              "contacts": int(sim.n_contacts())}
    for inter in sim.interactions:
        if hasattr(inter, "broken_count"):
            counts["bonds"] = int(inter.i.size)
    return {"case": case_name, "steps": steps, "warmup": warmup, "counts": counts,
            "kernels_us_per_step": {k: 1e6 * v / steps for k, v in tim.items()},
            "kernels_sum_us_per_step": 1e6 * total,
            "compiled_loop_us_per_step": 1e6 * loop,
            "compiled_loop_particle_steps_per_s": sim.p.n / loop}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--case", default="bonded3d", choices=sorted(CASES))
    ap.add_argument("--particles", type=int, default=None)
    ap.add_argument("--steps", type=int, default=400)
    ap.add_argument("--warmup", type=int, default=300)
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    r = profile(a.case, a.particles, a.steps, a.warmup)
    if a.json:
        print(json.dumps(r, indent=1))
        return
    tot = r["kernels_sum_us_per_step"]
    print(f"{a.case}: {r['counts']}, {a.steps} steps after {a.warmup}, one thread, CPU time")
    print("| kernel | us/step | share |\n|---|---|---|")
    for k, v in r["kernels_us_per_step"].items():
        print(f"| {k} | {v:.1f} | {100 * v / tot:.1f} % |")
    print(f"| **sum** | **{tot:.1f}** | |")
    print(f"compiled loop, same steps: {r['compiled_loop_us_per_step']:.1f} us/step "
          f"({r['compiled_loop_particle_steps_per_s']:.3e} particle-steps/s)")


if __name__ == "__main__":
    main()
