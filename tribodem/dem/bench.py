"""Engine throughput: particle-steps per second on the shared benchmark cases."""

from __future__ import annotations

import time
from typing import Any

import numba
import numpy as np

from tribodem.dem.bench_cases import (
    BenchCase,
    bonded3d_case,
    compress2d_case,
    dense3d_case,
    settle3d_case,
)
from tribodem.dem.contact import Material
from tribodem.dem.engine import Simulation
from tribodem.dem.space import Box
from tribodem.dem.state import ParticleState
from tribodem.dem.walls import PlaneWall

CASES = {"settle3d": settle3d_case, "compress2d": compress2d_case, "dense3d": dense3d_case,
         "bonded3d": bonded3d_case}


def simulation_from_case(case: BenchCase) -> Simulation:
    """Build the tribodem simulation of a benchmark case (walls on the box faces, fixed dt,
    the case's parallel bonds)."""
    mat = Material(name="bench", young=case.young, poisson=case.poisson, density=case.density,
                   cor=case.cor, friction=case.friction, law=case.law,
                   beta_n=0.1 if case.law == "linear" else 0.0)
    p = ParticleState(dim=case.dim, pos=case.positions, radius=case.radii,
                      density=case.density, thickness=case.thickness)
    lo, hi = case.box_lo, case.box_hi
    walls = []
    if case.dim == 3:
        walls = [PlaneWall([0, 0, lo[2]], [0, 0, 1], name="floor"),
                 PlaneWall([lo[0], 0, 0], [1, 0, 0], name="x-"),
                 PlaneWall([hi[0], 0, 0], [-1, 0, 0], name="x+"),
                 PlaneWall([0, lo[1], 0], [0, 1, 0], name="y-"),
                 PlaneWall([0, hi[1], 0], [0, -1, 0], name="y+")]
        if case.lid:
            v = case.wall_speed
            walls.append(PlaneWall([0, 0, hi[2]], [0, 0, -1], name="lid",
                                   mode="velocity" if v else "fixed", velocity=[0, 0, -v]))
    else:
        v = case.wall_speed
        walls = [PlaneWall([0, lo[1], 0], [0, 1, 0], mode="velocity", velocity=[0, v, 0],
                           name="bottom"),
                 PlaneWall([0, hi[1], 0], [0, -1, 0], mode="velocity", velocity=[0, -v, 0],
                           name="top"),
                 PlaneWall([lo[0], 0, 0], [1, 0, 0], name="left"),
                 PlaneWall([hi[0], 0, 0], [-1, 0, 0], name="right")]
    sim = Simulation(p, [mat], Box(lo, hi), walls=walls, gravity=case.gravity, dt=case.dt,
                     skin=0.15 * 2.0 * float(case.radii.mean()))
    if case.bonds:
        from tribodem.dem.bonds import install_bonds_by_gap

        install_bonds_by_gap(sim, **case.bonds)
    return sim


def run_case(name: str, n: int | None = None, steps: int | None = None,
             threads: int | None = None) -> dict[str, Any]:
    """Time ``steps`` steps of case ``name`` (after a short warm-up that compiles kernels)."""
    if name not in CASES:
        raise ValueError(f"bench: case = {name!r}: must be one of {sorted(CASES)}")
    kw: dict[str, Any] = {}
    if n is not None:
        kw["n"] = n
    if steps is not None:
        kw["steps"] = steps
    case = CASES[name](**kw)
    if threads is not None:
        numba.set_num_threads(int(threads))
    warm = simulation_from_case(CASES[name](n=min(case.n, 5000), steps=10))
    warm.step(10)
    sim = simulation_from_case(case)
    t0 = time.perf_counter()
    c0 = time.process_time()
    sim.step(case.steps)
    dt_wall = time.perf_counter() - t0
    dt_cpu = time.process_time() - c0
    z = sim.p.pos[:, 2] if case.dim == 3 else sim.p.pos[:, 1]
    extra: dict[str, Any] = {}
    for inter in sim.interactions:  # parallel bonds: count, intact, bytes per bond
        nb = int(getattr(inter, "i", np.zeros(0)).size)
        if nb and hasattr(inter, "broken_count"):
            arrays = [a for a in vars(inter).values()
                      if isinstance(a, np.ndarray) and a.ndim and a.shape[0] == nb]
            extra = {"bonds": nb, "bonds_broken": int(inter.broken_count()),
                     "bytes_per_bond": sum(a.nbytes for a in arrays) / nb}
    return {
        "code": "tribodem",
        "case": name,
        "particles": case.n,
        "steps": case.steps,
        "threads": numba.get_num_threads(),
        "threading_layer": _threading_layer(),
        "seconds": dt_wall,
        "cpu_seconds": dt_cpu,  # all threads of this process (loaded machines: see this)
        "particle_steps_per_s": case.n * case.steps / dt_wall,
        "contacts_end": sim.n_contacts(),
        "coordination_end": 2.0 * sim.n_contacts() / case.n,
        "neighbor_builds": sim.nl.builds,
        "mean_height_end_m": float(np.mean(z)),
        "dt_s": sim.dt,
        "memory": {**sim.memory(), **extra, "peak_rss_bytes": _peak_rss()},
    }


def _threading_layer() -> str:
    """numba's threading layer in use (``omp`` first, ``dem.jit``), or ``none`` if no
    threaded region ran (one thread: every kernel on its serial build)."""
    try:
        return str(numba.threading_layer())
    except ValueError:
        return "none"


def _peak_rss() -> float:
    """Peak resident memory of this process, bytes (Linux: ru_maxrss in KiB)."""
    import resource

    return float(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss) * 1024.0


#: ``bench dem --quick``: particles and steps when not given.
QUICK_PARTICLES, QUICK_STEPS = 2000, 200


def benchmark(case: str = "settle3d", *, quick: bool = False, particles: int | None = None,
              steps: int | None = None, threads: int | None = None) -> dict[str, Any]:
    """What ``tribodem bench dem`` measures: :func:`run_case` after checking the case, the
    threads against the cores and the particles against the memory (``ConfigError`` naming
    the option, the value and what is allowed). ``quick``: :data:`QUICK_PARTICLES`
    particles and :data:`QUICK_STEPS` steps unless given."""
    from tribodem.dem.state import BYTES_PER_PARTICLE
    from tribodem.io import runs
    from tribodem.io.config import ConfigError

    if case not in CASES:
        raise ConfigError(f"bench dem: --case = {case!r}: must be one of {sorted(CASES)}")
    if quick:
        particles = particles or QUICK_PARTICLES
        steps = steps or QUICK_STEPS
    if threads is not None:
        runs.check_threads(threads, "--threads", zero_means_all=False)
    if particles is not None:
        runs.check_memory(particles, BYTES_PER_PARTICLE, "--particles")
    return run_case(case, n=particles, steps=steps, threads=threads)


def describe(res: dict[str, Any]) -> str:
    """One line of a :func:`benchmark` result: case, size, threads, particle-steps/s."""
    return (f"{res['case']}: {res['particles']} particles x {res['steps']} steps on "
            f"{res['threads']} thread(s): {res['particle_steps_per_s']:.3e} particle-steps/s")
