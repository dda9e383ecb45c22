"""CalculiX FE backend: one plane-strain elastic fretting cycle, the mesh convergence study,
and the fe backend against the half-space one on the same fretting run.

    .venv/bin/python benchmarks/bench_fe.py [--threads 1 2] [--h-over-a 0.125] [--n 16]
    .venv/bin/python benchmarks/bench_fe.py --study 0.5 0.25 0.125 0.0625
    .venv/bin/python benchmarks/bench_fe.py --compare OUT [--cycles 5] [--h-over-a 0.25]
    .venv/bin/python benchmarks/bench_fe.py --plastic-cycles 5 [--h-over-a 0.25] [--penalty 10]

Compare: ``examples/fretting_cylinder_on_flat.toml`` (R 4 mm, 100 N/mm, +-0.1 mm, 16
increments, n 64, energy criterion) for ``--cycles`` cycles, run by the installed command
with ``--solver elastic`` and ``--solver fe`` (``[fe] h_over_a``; 1 ccx thread) into
OUT/elastic and OUT/fe (a finished run there is reused); prints worn volumes, maximum depths,
dissipated energy and seconds per cycle, with the fe profile per job from OUT/fe/fe/jobs.csv
(meshing + morphing + deck, ccx, reading, mapping to the window) and the rest of the cycle
(criterion, loop, outputs), and the load average before and after.

Plastic cycles: bilinear EN24T on both bodies, P = 200 N/mm (p0 = 2.13 Y), +-5 um, 32
increments per cycle, 10 load increments, the backend's sliding contact set-up
(node-to-surface, one step per quarter) with the normal penalty ``--penalty`` E/h, all
cycles in one ccx job (plastic strain and residual stress carry over); prints per cycle the
PEEQ maxima of the flat's and the pad's fine zones, the PEEQ sum over their Gauss points
and Q / (mu P) at +A and -A.

Cycle: EN24T pad R 4 mm on a flat, 100 N/mm (p0 1.02 GPa, a 62 um), mu 0.6, tangential cycle
0 -> +3 um -> 0 -> -3 um -> 0 (gross slip at about 1.7 um) in ``--n`` increments; timed:
meshing + deck, ccx, reading the .dat. Study: the normal load only (no tangential step), for
each element size at the contact h / a: elements, ccx time, errors of p0 and a against Hertz,
p0 / max von Mises (Johnson: first yield at p0 = 1.79 Y).
Prints JSON lines. Needs ``ccx`` on PATH (apt-get install calculix-ccx).
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
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


ROOT = Path(__file__).resolve().parent.parent


def compare(out: Path, cycles: int, h_over_a: float) -> dict[str, object]:
    """The same cylinder-on-flat energy run on the half-space and on the fe backend."""
    out.mkdir(parents=True, exist_ok=True)
    text = (ROOT / "examples" / "fretting_cylinder_on_flat.toml").read_text()
    lines = [ln for ln in text.splitlines() if not ln.startswith("cycles")]
    cfg = out / "case.toml"
    cfg.write_text(f"cycles = {cycles}\n" + "\n".join(lines)
                   + f"\n\n[fe]\nh_over_a = {h_over_a}\n")
    exe = Path(sys.executable).with_name("tribodem")
    res: dict[str, object] = {"case": "compare", "cycles": cycles, "h_over_a": h_over_a,
                              "config": str(cfg)}
    for solver in ("elastic", "fe"):
        run = out / solver
        load0 = os.getloadavg()
        if not (run / "summary.json").is_file():
            subprocess.run([str(exe), "fretting", "run", "--config", str(cfg), "--solver",
                            solver, "--threads", "1", "--out", str(run), "--no-progress"],
                           check=True)
        summ = json.loads((run / "summary.json").read_text())
        row = {k: summ[k] for k in ("wear_volume_upper_m3", "wear_volume_lower_m3",
                                    "wear_depth_upper_m", "wear_depth_lower_m",
                                    "dissipated_energy_total_J", "wall_time_s")}
        row["seconds_per_cycle"] = summ["wall_time_s"] / summ["cycles_simulated"]
        row["load_average_before_after"] = [round(load0[0], 2),
                                            round(os.getloadavg()[0], 2)]
        if solver == "fe":
            with open(run / "fe" / "jobs.csv") as fh:
                jobs = list(csv.DictReader(fh))
            keys = ("seconds_mesh", "seconds_ccx", "seconds_read", "seconds_map")
            prof = {k: sum(float(j[k]) for j in jobs) / len(jobs) for k in keys}
            prof["seconds_criterion_loop_output"] = (summ["wall_time_s"]
                                                     - sum(prof.values()) * len(jobs)) / len(jobs)
            row |= {"jobs": len(jobs), "elements": int(jobs[0]["elements"]),
                    "refined_jobs": sum(int(j["refine"]) > 1 for j in jobs),
                    "profile_per_job_s": {k: round(v, 3) for k, v in prof.items()},
                    "mesh_worn_volume_upper_m3": float(jobs[-1]["worn_volume_upper_m3"]),
                    "mesh_worn_volume_lower_m3": float(jobs[-1]["worn_volume_lower_m3"])}
        res[solver] = row
    el, fe = res["elastic"], res["fe"]
    assert isinstance(el, dict) and isinstance(fe, dict)
    res["fe_over_elastic"] = {k: round(fe[k] / el[k], 4) for k in (
        "wear_volume_upper_m3", "wear_volume_lower_m3", "wear_depth_upper_m",
        "wear_depth_lower_m", "dissipated_energy_total_J", "seconds_per_cycle")}
    return res


def plastic_cycles(cycles: int, h_over_a: float, penalty: float) -> dict[str, object]:
    """Several elastic-plastic cycles in one job (see the module docstring)."""
    import dataclasses

    import numpy as np

    from tribodem.contact.fe import FEMaterial, LoadCase, read_results, run_ccx, write_deck
    from tribodem.contact.fe.deck import sliding_contact
    from tribodem.contact.fe.mesh import PadOnFlat, cylinder_on_flat

    mat = FEMaterial(yield_strength=680e6)
    delta, load = 5e-6, 2e5
    case = LineCase(load=load, delta=delta, h_over_a=h_over_a, lower=mat, upper=mat)
    p0, a = case.hertz
    mesh = cylinder_on_flat(PadOnFlat(radius=case.radius, a=a, h_fine=h_over_a * a,
                                      stroke=delta, size_factor=case.size_factor))
    contact = dataclasses.replace(sliding_contact(0.6, p0), penalty_factor=penalty)
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench_fe_") as tmp:
        deck = write_deck(Path(tmp) / "job.inp", mesh,
                          LoadCase(load=load, delta=delta, n_increments=32, split_cycle=True,
                                   load_increments=10, cycles=cycles), mat, mat, contact)
        run = run_ccx(deck, threads=1, timeout=3600)
        res = read_results(run.job, mesh)
    lower = set(mesh.element_sets["LFINE"].tolist())
    prev = 0.0
    for k in range(cycles + 1):
        t = 2.0 + 4.0 * k
        elems, pe = res.peeq(res.times[res.at(t)])
        low = np.array([int(e) in lower for e in elems])
        q = [float(-res.tangential_force[res.at(t - d)] / (0.6 * res.normal_force[res.at(t - d)]))
             if k else 0.0 for d in (3.0, 1.0)]
        rows.append({"cycle": k, "peeq_max_flat": float(pe[low].max()),
                     "peeq_max_pad": float(pe[~low].max()), "peeq_sum": float(pe.sum()),
                     "peeq_sum_increment": float(pe.sum() - prev),
                     "Q_over_muP_at_plus_A": round(q[0], 4),
                     "Q_over_muP_at_minus_A": round(q[1], 4)})
        prev = float(pe.sum())
    return {"case": "plastic_cycles", "cycles": cycles, "h_over_a": h_over_a,
            "penalty": penalty, "p0_over_Y": round(p0 / 680e6, 3),
            "elements": mesh.n_elements, "seconds_ccx": round(run.seconds, 1), "rows": rows}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--h-over-a", type=float, default=LineCase.h_over_a)
    ap.add_argument("--n", type=int, default=16, help="increments of the cycle")
    ap.add_argument("--size-factor", type=float, default=LineCase.size_factor)
    ap.add_argument("--study", type=float, nargs="*", help="h / a values of the study")
    ap.add_argument("--compare", type=Path, help="folder of the fe / half-space comparison")
    ap.add_argument("--cycles", type=int, default=5, help="cycles of the comparison")
    ap.add_argument("--plastic-cycles", type=int, help="elastic-plastic cycles in one job")
    ap.add_argument("--penalty", type=float, default=10.0, help="normal penalty / (E / h)")
    args = ap.parse_args()
    if args.plastic_cycles:
        print(json.dumps(plastic_cycles(args.plastic_cycles, args.h_over_a, args.penalty),
                         indent=1))
        return
    if args.compare is not None:
        print(json.dumps(compare(args.compare, args.cycles, args.h_over_a), indent=1))
        return
    if args.study:
        for h in args.study:
            print(json.dumps(study(h, args.threads[0], args.size_factor)), flush=True)
        return
    for th in args.threads:
        print(json.dumps(cycle(th, args.h_over_a, args.n, args.size_factor)), flush=True)


if __name__ == "__main__":
    main()
