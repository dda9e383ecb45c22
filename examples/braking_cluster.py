"""The braking trend study on a batch cluster: dask-jobqueue starts one-core Dask workers
as SLURM jobs and ``tribodem.braking.sweep`` sends the sweep's members to them
(docs/howto/cluster.md, "The braking study on a batch cluster").

    python examples/braking_cluster.py --out /shared/braking --packings 8 --jobs 40
    python examples/braking_cluster.py --dry-run --measured /shared/braking --packings 8

Needs the ``cluster`` extra (``pip install 'tribodem[cluster]'``: dask.distributed and
dask-jobqueue) on the login node and the compute nodes, and an ``--out`` folder on a file
system they all share. Each job is one worker of one core (numba, OpenMP and BLAS on one
thread): a member is one single-threaded run. The sweep is the same command as
``tribodem braking sweep``: re-run it after a stop, a lost job or a wall-time limit and it
skips the finished members and resumes the others from their checkpoints.

``--dry-run`` starts no job: it prints the job script dask-jobqueue would submit and the
projected wall time of the sweep per cluster size (``tribodem.braking.projected_wall_s``)
from a measured member cost: the mean ``wall_time_s`` of the finished members under
``--measured`` (a sweep's folder, e.g. a few members run locally first), else
``--member-s``. PBSCluster, SGECluster and LSFCluster take the same arguments as
SLURMCluster.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

from dask_jobqueue import SLURMCluster

import tribodem.braking

#: the cluster sizes (workers) of the projection table
SIZES = (1, 2, 5, 10, 20, 40, 80, 160)


def measured_member_s(folder: Path) -> tuple[float, int]:
    """(mean ``wall_time_s``, count) of the finished members of the sweep in ``folder``
    (their ``summary.json``: ``condition_k/summary.json`` or
    ``condition_k/seed_s/summary.json``); ``ValueError`` when none has finished."""
    times = []
    for f in sorted(folder.glob("condition_*/**/summary.json")):
        s = json.loads(f.read_text())
        if s.get("status") == "finished" and s.get("wall_time_s") is not None:
            times.append(float(s["wall_time_s"]))
    if not times:
        raise ValueError(f"{folder}: no finished member (condition_*/**/summary.json)")
    return sum(times) / len(times), len(times)


def projection(members: int, member_s: float, sizes: tuple[int, ...] = SIZES,
               startup_s: float = 60.0) -> list[tuple[int, float]]:
    """(workers, projected wall time s) for each cluster size in ``sizes``
    (``tribodem.braking.projected_wall_s``: ceil(members / workers) rounds of one member,
    plus the cluster's start)."""
    return [(w, tribodem.braking.projected_wall_s(members, member_s, w, startup_s))
            for w in sizes]


def make_cluster(a: argparse.Namespace) -> SLURMCluster:
    """One-core, one-worker SLURM jobs that stay up for ``--walltime`` (each takes
    members until then; a member cut by the limit resumes on another job)."""
    extra = [f"--partition={a.queue}"] if a.queue else []
    return SLURMCluster(cores=1, processes=1, memory=a.memory, walltime=a.walltime,
                        job_extra_directives=extra,
                        job_script_prologue=["export OMP_NUM_THREADS=1 NUMBA_NUM_THREADS=1 "
                                             "OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1"])


def main() -> None:
    """Parse the options; the dry run's job script and projection, or the sweep."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path, default=Path("braking_sweep"),
                    help="the sweep's folder, shared by every node")
    ap.add_argument("--config", default=None, help="a braking config (default: the "
                    "trend-study cell)")
    ap.add_argument("--packings", type=int, default=8)
    ap.add_argument("--conditions", default="1,2,3,4,5")
    ap.add_argument("--jobs", type=int, default=40, help="workers (one-core jobs)")
    ap.add_argument("--memory", default="2GB", help="per job")
    ap.add_argument("--walltime", default="04:00:00", help="per job")
    ap.add_argument("--queue", default=None, help="SLURM partition")
    ap.add_argument("--dry-run", action="store_true",
                    help="print the job script and the projection; submit nothing")
    ap.add_argument("--measured", type=Path, default=None,
                    help="a sweep folder whose finished members give the member cost")
    ap.add_argument("--member-s", type=float, default=None,
                    help="the member cost (s of one core) without --measured")
    a = ap.parse_args()
    conditions = [int(c) for c in a.conditions.split(",")]
    members = a.packings * len(conditions)
    cluster = make_cluster(a)
    try:
        if a.dry_run:
            print(cluster.job_script())
            if a.measured is not None:
                member_s, n = measured_member_s(a.measured)
                source = f"mean of {n} finished members in {a.measured}"
            elif a.member_s is not None:
                member_s, source = a.member_s, "--member-s"
            else:
                raise SystemExit("--dry-run needs --measured DIR or --member-s SECONDS")
            print(f"{members} members ({a.packings} packings x {len(conditions)} "
                  f"conditions), {member_s:.0f} s a member ({source}):")
            print("| workers | projected wall time |\n|---|---|")
            for w, t in projection(members, member_s):
                print(f"| {w} | {t / 3600:.2f} h ({math.ceil(members / w)} rounds) |")
            return
        cluster.scale(jobs=a.jobs)
        res = tribodem.braking.sweep(a.out, config=a.config, packings=a.packings,
                                     conditions=conditions,
                                     scheduler=cluster.scheduler_address, progress=True,
                                     echo=print)
        for row in res.summary["wear_changes"]:
            print(f"{row['change']}: ours {row['ours']}, seed {row['seed']}")
    finally:
        cluster.close()


if __name__ == "__main__":
    main()
