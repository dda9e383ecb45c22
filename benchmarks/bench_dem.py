"""DEM engine benchmark: tribodem cases on 1 and 2 threads, peers on the cases they run.

    .venv/bin/python benchmarks/bench_dem.py [--quick] [--threads 1 2] [--no-peers]
                                             [--cases settle3d dense3d ...]

(a) ``settle3d``: 20,000 Hertz-Mindlin spheres settling in an open-top box, 2,000 steps.
(b) ``compress2d``: 50,000 linear-contact disks compressed between platens, 2,000 steps.
(c) ``dense3d``: 20,000 Hertz-Mindlin spheres held compressed between six walls
    (coordination ~6), 2,000 steps.
(d) ``bonded3d``: 20,000 spheres with ~3 parallel bonds each, uniaxial compression.
tribodem runs in a fresh process per point (``tribodem bench dem --json``; kernels are
warmed up before timing). Yade and LIGGGHTS, when installed, run case (a) on the very same
particles, LIGGGHTS also case (c), Yade with JCFpm bonds case (d) (``benchmarks/peers.py``);
the script prints tribodem's per-thread ratio to each. Prints a markdown table and a JSON
list (for BENCHMARKS.md).
"""

from __future__ import annotations

import argparse
import json
import platform
import subprocess
import sys
import tempfile
from datetime import date
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent))


#: case -> ((particles, steps) full, (particles, steps) --quick)
ALL_CASES = {"settle3d": ((20_000, 2000), (2000, 200)),
             "compress2d": ((50_000, 2000), (5000, 200)),
             "dense3d": ((20_000, 2000), (2000, 200)),
             "bonded3d": ((20_000, 2000), (2000, 200))}
PEER_CASES = {"settle3d": ("yade", "liggghts"), "dense3d": ("liggghts",),
              "bonded3d": ("yade-jcfpm",)}


def tribodem_point(case: str, n: int, steps: int, threads: int) -> dict:
    cmd = [sys.executable, "-m", "tribodem.cli", "bench", "dem", "--case", case,
           "--particles", str(n), "--steps", str(steps), "--threads", str(threads), "--json"]
    out = subprocess.run(cmd, capture_output=True, text=True, check=True, cwd=HERE.parent)
    return json.loads(out.stdout)


def cpu_name() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def main(argv: list[str] | None = None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="2,000 / 5,000 particles, 200 steps")
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--no-peers", action="store_true")
    ap.add_argument("--repeat", type=int, default=2, help="runs per point; fastest kept")
    ap.add_argument("--cases", nargs="+", default=list(ALL_CASES), choices=list(ALL_CASES))
    args = ap.parse_args(argv)
    sizes = {c: (ALL_CASES[c][1] if args.quick else ALL_CASES[c][0]) for c in args.cases}
    results: list[dict] = []
    for case, (n, steps) in sizes.items():
        for t in args.threads:
            runs = [tribodem_point(case, n, steps, t) for _ in range(args.repeat)]
            best = max(runs, key=lambda r: r["particle_steps_per_s"])
            results.append(best)
            print(f"# tribodem {case} threads={t}: {best['particle_steps_per_s']:.4g} "
                  "particle-steps/s", file=sys.stderr)
    if not args.no_peers:
        import peers

        from tribodem.dem import bench_cases

        runners = {"yade": peers.run_yade, "liggghts": peers.run_liggghts,
                   "yade-jcfpm": peers.run_yade_jcfpm}
        with tempfile.TemporaryDirectory(prefix="tribodem_peers_") as tmp:
            for cname, codes in PEER_CASES.items():
                if cname not in sizes:
                    continue
                n, steps = sizes[cname]
                case = getattr(bench_cases, f"{cname}_case")(n=n, steps=steps)
                for code in codes:
                    for t in args.threads:
                        reps = [r for r in (runners[code](case, t, tmp)
                                            for _ in range(args.repeat)) if r]
                        if reps:
                            best = max(reps, key=lambda r: r["particle_steps_per_s"])
                            results.append(best)
                            print(f"# {best['code']} {cname} threads={t}: "
                                  f"{best['particle_steps_per_s']:.4g} particle-steps/s",
                                  file=sys.stderr)
    print(f"\nMachine: {cpu_name()}, {len(args.threads)} thread counts, date {date.today()}")
    print("Command: .venv/bin/python benchmarks/bench_dem.py"
          + (" --quick" if args.quick else "") + "\n")
    print("| code | case | particles | steps | threads | particle-steps/s | contacts at end |")
    print("|---|---|---|---|---|---|---|")
    for r in results:
        print(f"| {r['code']} | {r.get('case', 'settle3d')} | {r['particles']} | {r['steps']} | "
              f"{r['threads']} | {r['particle_steps_per_s']:.3e} | {r.get('contacts_end', '')} |")
    ours = {(r["case"], r["threads"]): r["particle_steps_per_s"] for r in results
            if r["code"] == "tribodem"}
    print()
    for r in results:
        key = (r.get("case", "settle3d"), r["threads"])
        if r["code"] != "tribodem" and key in ours:
            ratio = ours[key] / r["particle_steps_per_s"]
            print(f"tribodem / {r['code']} on {r['threads']} thread(s), {key[0]}: {ratio:.2f}x")
    print("\n" + json.dumps(results, indent=1))
    return results


if __name__ == "__main__":
    main()
