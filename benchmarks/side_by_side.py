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
import sys
import time
from pathlib import Path

from peers import _run_measured, machine_busy  # benchmarks/ is this script's sys.path[0]

ROOT = Path(__file__).resolve().parents[1]


def _others(cmd: list[str]) -> tuple[str, float]:
    """Run ``cmd``; its stdout and the share of the machine's CPUs that other processes used
    meanwhile (0..1; ``peers._run_measured``)."""
    proc, others = _run_measured(cmd, capture_output=True, text=True, cwd=ROOT, check=True)
    return proc.stdout, others


def _wait_idle(limit_s: float) -> None:
    """Wait until the machine's CPUs are < 15 % busy over 0.5 s (``limit_s`` at most)."""
    end = time.monotonic() + limit_s
    while time.monotonic() < end and machine_busy(0.5) >= 0.15:
        pass


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
