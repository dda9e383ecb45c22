"""tribodem against a peer, interleaved: one run of each per round, with the CPU share that
other processes took during each run.

    .venv/bin/python benchmarks/side_by_side.py --case settle3d --threads 2 --rounds 3
    .venv/bin/python benchmarks/side_by_side.py --case bonded3d --peer yade --threads 1

A VM's speed can drift by tens of percent from one minute to the next, so a ratio is only
worth something between runs made in the same minute: each round runs ``tribodem bench dem
... --json`` and then ``benchmarks/peers.py`` on the same case and thread count, and prints
both rates, their ratio and "others" (the share of all CPUs busy outside the run, from
``/proc/stat`` around it; Linux only). Before each run it waits (``--wait-idle`` s at most)
until the other processes are using less than 15 % of the CPUs. One markdown row per round.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _cpu_ticks() -> tuple[int, int]:
    """(all ticks, idle + iowait ticks) of the machine so far (``/proc/stat``)."""
    v = [int(x) for x in Path("/proc/stat").read_text().split("\n", 1)[0].split()[1:]]
    return sum(v), v[3] + v[4]


def _others(cmd: list[str]) -> tuple[str, float]:
    """Run ``cmd``; its stdout and the share of the machine's CPU time that other processes
    used meanwhile (0..1)."""
    t0, i0 = _cpu_ticks()
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    out = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT, check=True).stdout
    t1, i1 = _cpu_ticks()
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    own = (r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime) * os.sysconf("SC_CLK_TCK")
    total = t1 - t0
    busy = total - (i1 - i0)
    return out, max(0.0, (busy - own) / total) if total else 0.0


def _wait_idle(limit_s: float) -> None:
    """Wait until other processes use < 15 % of the CPUs over 0.5 s (``limit_s`` at most)."""
    end = time.monotonic() + limit_s
    while time.monotonic() < end:
        t0, i0 = _cpu_ticks()
        time.sleep(0.5)
        t1, i1 = _cpu_ticks()
        if t1 > t0 and (t1 - t0 - (i1 - i0)) / (t1 - t0) < 0.15:
            return


def _rate(out: str) -> float:
    """particle-steps/s from a JSON object or list on stdout (the best of a list)."""
    start = min(k for k in (out.find("{"), out.find("[")) if k >= 0)
    data = json.loads(out[start:])
    rows = data if isinstance(data, list) else [data]
    return max(float(r["particle_steps_per_s"]) for r in rows)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--case", default="settle3d", choices=["settle3d", "dense3d", "bonded3d"])
    ap.add_argument("--peer", default=None, choices=["liggghts", "yade"],
                    help="default: yade for bonded3d, liggghts otherwise")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--wait-idle", type=float, default=120.0, metavar="S")
    args = ap.parse_args(argv)
    peer = args.peer or ("yade" if args.case == "bonded3d" else "liggghts")
    py = sys.executable
    ours = [py, "-m", "tribodem.cli", "bench", "dem", "--case", args.case, "--particles",
            "20000", "--steps", "2000", "--threads", str(args.threads), "--json"]
    theirs = [py, str(ROOT / "benchmarks" / "peers.py"), "--codes", peer, "--case", args.case,
              "--threads", str(args.threads)]
    print(f"| time | case | threads | tribodem | others | {peer} | others | ratio |")
    print("|---|---|---|---|---|---|---|---|")
    for _ in range(args.rounds):
        _wait_idle(args.wait_idle)
        out_a, oth_a = _others(ours)
        _wait_idle(args.wait_idle)
        out_b, oth_b = _others(theirs)
        a, b = _rate(out_a), _rate(out_b)
        print(f"| {time.strftime('%H:%M:%S')} | {args.case} | {args.threads} | {a:.3e} | "
              f"{oth_a:.1%} | {b:.3e} | {oth_b:.1%} | {a / b:.2f} |", flush=True)


if __name__ == "__main__":
    main()
