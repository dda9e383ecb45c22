"""CalculiX FE backend: one plane-strain elastic fretting cycle, and the mesh convergence study.

    .venv/bin/python benchmarks/bench_fe.py [--threads 1 2] [--h-over-a 0.125] [--n 16]
    .venv/bin/python benchmarks/bench_fe.py --study 0.5 0.25 0.125 0.0625

Cycle: EN24T pad R 4 mm on a flat, 100 N/mm (p0 1.02 GPa, a 62 um), mu 0.6, tangential cycle
0 -> +3 um -> 0 -> -3 um -> 0 (gross slip at about 1.7 um) in ``--n`` increments; timed:
meshing + deck, ccx, reading the .dat. Study: the normal load only (no tangential step), for
each element size at the contact h / a: elements, ccx time, errors of p0 and a against Hertz,
p0 / max von Mises (Johnson: first yield at p0 = 1.79 Y).
Prints JSON lines. Needs ``ccx`` on PATH (apt-get install calculix-ccx).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from tribodem.contact.fe.model import LineCase, run_line_case  # noqa: E402
from tribodem.contact.fe.validate import half_width_fit, yield_checks  # noqa: E402


def cycle(threads: int, h_over_a: float, n: int, size_factor: float) -> dict[str, object]:
    """Time one full elastic cycle."""
    case = LineCase(load=1e5, delta=3e-6, n_increments=n, h_over_a=h_over_a,
                    size_factor=size_factor)
    with tempfile.TemporaryDirectory(prefix="bench_fe_") as tmp:
        t0 = time.perf_counter()
        run = run_line_case(case, tmp, threads=threads, timeout=1800, fine_stress=False)
        total = time.perf_counter() - t0
    res = run.results
    q = res.tangential_force[res.times > 2.0]
    return {"case": "cycle", "threads": threads, "h_over_a": h_over_a, "increments": n,
            "size_factor": size_factor, "elements": run.mesh.n_elements,
            "nodes": run.mesh.n_nodes, "seconds_total": round(total, 2),
            "seconds_mesh_deck": round(run.seconds_mesh, 3),
            "seconds_ccx": round(run.run.seconds, 2), "seconds_read": round(run.seconds_read, 3),
            "seconds_per_increment": round(run.run.seconds / (n + 7), 2),
            "max_Q_over_muP": round(float(abs(q).max() / (0.6 * case.load)), 4)}


def study(h_over_a: float, threads: int, size_factor: float) -> dict[str, object]:
    """Hertz errors of the normal load for one element size."""
    case = LineCase(load=1e5, delta=0.0, h_over_a=h_over_a, size_factor=size_factor)
    p0, a = case.hertz
    with tempfile.TemporaryDirectory(prefix="bench_fe_") as tmp:
        run = run_line_case(case, tmp, threads=threads, timeout=1800, fine_stress=True)
    st = run.results.contact[run.results.at(2.0)]
    a_fit, _ = half_width_fit(st, p0)
    vm = yield_checks(run)[0]
    return {"case": "study", "h_over_a": h_over_a, "h_um": round(h_over_a * a * 1e6, 2),
            "size_factor": size_factor, "elements": run.mesh.n_elements,
            "seconds_ccx": round(run.run.seconds, 2),
            "p0_error": round(float(st.pressure.max() / p0 - 1.0), 5),
            "a_error": round(a_fit / a - 1.0, 5),
            "yield_factor": round(vm["value"], 4),
            "yield_factor_error": round(vm["value"] / vm["reference"] - 1.0, 4)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--h-over-a", type=float, default=LineCase.h_over_a)
    ap.add_argument("--n", type=int, default=16, help="increments of the cycle")
    ap.add_argument("--size-factor", type=float, default=LineCase.size_factor)
    ap.add_argument("--study", type=float, nargs="*", help="h / a values of the study")
    args = ap.parse_args()
    if args.study:
        for h in args.study:
            print(json.dumps(study(h, args.threads[0], args.size_factor)), flush=True)
        return
    for th in args.threads:
        print(json.dumps(cycle(th, args.h_over_a, args.n, args.size_factor)), flush=True)


if __name__ == "__main__":
    main()
