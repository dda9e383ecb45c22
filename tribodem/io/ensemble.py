"""Ensembles on Dask: every member of a sweep is one independent task in its own folder.

Used by ``tribodem braking sweep`` (:mod:`tribodem.braking.ensemble`) and ``tribodem
fretting sweep`` (:mod:`tribodem.fretting.sweep`); each of them says what a member is and
what its task does, this module runs the tasks (and, for short tasks without folders such
as ``tribodem calibrate``'s specimens, maps a function over items: :func:`task_map`):

- by default on a ``LocalCluster`` of worker *processes* with one thread each (``--workers``,
  default all local cores), every worker with numba, OpenMP and BLAS limited to one thread
  (:data:`WORKER_ENV` in its environment; the tasks also call ``numba.set_num_threads(1)``),
  so N members run at once on N cores without oversubscription;
- with ``--scheduler tcp://HOST:PORT`` (or a scheduler JSON file) on an existing cluster
  (``dask scheduler`` / ``dask worker``, dask-jobqueue, Kubernetes). The output folder must
  then be on a file system every worker shares with the client.

**A member's task must be idempotent and retry-safe**: it looks at its folder when it
starts, on whichever worker, and returns the finished summary found there, resumes from
its checkpoint or starts over; every file it writes is written atomically
(``tribodem.io.results``), so a worker killed at any moment leaves either the old or the
new version of each file. The scheduler reschedules the task of a lost worker
(``distributed.scheduler.allowed-failures``, default 3 losses per task) and the new attempt
resumes from the last checkpoint.

The client side (:func:`run_members`) submits the members, shows members done / running /
failed, reports a failed member without stopping the others, and on Ctrl-C (or any error)
kills the local workers, sets the sweep's stop event (tasks on a remote cluster that poll it
with :func:`stop_check` stop at their next checkpoint), cancels the futures, closes the
client and the local cluster, and re-raises.

Dask (``dask`` and ``distributed``) is the optional extra ``cluster`` (``pip install
'tribodem[cluster]'``): without it a command that needs a cluster is refused before any work
(:func:`require_dask`, exit 2, naming the install command).
"""

from __future__ import annotations

import logging
import os
import time
import uuid
from collections.abc import Callable, Hashable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tribodem.io.config import ConfigError

#: environment of every local worker process: one thread per numeric library
WORKER_ENV = {"NUMBA_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
              "OPENBLAS_NUM_THREADS": "1"}
#: seconds between two looks at the sweep's stop event inside a running member
STOP_POLL_S = 2.0
#: how to install what the commands on a cluster need (Dask: the extra ``cluster``)
CLUSTER_INSTALL = "pip install 'tribodem[cluster]'"


def require_dask(command: str = "this command", alternative: str = "") -> None:
    """``ConfigError`` (exit 2, before any work) when Dask (``dask`` and ``distributed``,
    the extra ``cluster``) is not installed: it names ``command``, the install command and
    ``alternative`` (e.g. running in this process)."""
    try:
        import dask  # noqa: F401
        import distributed  # noqa: F401
    except ImportError as err:
        raise ConfigError(
            f"{command} runs on a Dask cluster, but {err.name or 'dask'} is not installed; "
            f"install it with: {CLUSTER_INSTALL}" + (f" (or {alternative})" if alternative
                                                     else "")) from None


@dataclass
class Member:
    """One member of a sweep: an independent, idempotent task writing its own folder.

    ``key``: the caller's key of its result and failure (a row's name, a (condition,
    packing) pair); ``label``: how messages name it; ``task_name``: a short prefix of its
    Dask key (no spaces); ``task``: a picklable module-level function called on a worker
    as ``task(data, str(folder), stop_event_name)``, returning the member's summary (a
    dict); ``data``: the member's config (a dict shaped like the TOML); ``folder``: where
    the task writes (``summary.json`` there when it finished); ``info``: what the room
    keeps beside it (a table row's cells, the condition number).
    """

    key: Hashable
    label: str
    task_name: str
    task: Callable[..., dict[str, Any]]
    data: dict[str, Any]
    folder: Path
    info: dict[str, Any] = field(default_factory=dict)

    @property
    def args(self) -> tuple[Any, ...]:
        """The task's arguments before the stop event's name: the config and the folder."""
        return self.data, str(self.folder.resolve())


def stop_check(event_name: str | None) -> Callable[[], bool] | None:
    """A cheap ``should_stop()`` for a task: looks at the sweep's ``distributed.Event`` at
    most every ``STOP_POLL_S`` seconds (None outside a worker or without an event)."""
    if event_name is None:
        return None
    try:
        from distributed import Event, get_worker

        get_worker()
        ev = Event(event_name)
    except Exception:  # noqa: BLE001 - not on a worker: nothing to poll
        return None
    last = [time.monotonic()]

    def should_stop() -> bool:
        now = time.monotonic()
        if now - last[0] < STOP_POLL_S:
            return False
        last[0] = now
        try:
            return bool(ev.is_set())
        except Exception:  # noqa: BLE001 - scheduler unreachable: keep going
            return False

    return should_stop


def local_cores() -> int:
    """Cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def check_scheduler(scheduler: str) -> dict[str, str]:
    """The ``Client`` keyword for ``--scheduler`` (an address or a scheduler file), or
    ``ConfigError`` naming the option, the value and what is allowed."""
    if "://" in scheduler:
        proto, _, rest = scheduler.partition("://")
        host, _, port = rest.rpartition(":")
        if proto in ("tcp", "tls", "ucx", "inproc") and host and port.isdigit():
            return {"address": scheduler}
    elif Path(scheduler).is_file():
        return {"scheduler_file": scheduler}
    raise ConfigError(f"--scheduler = '{scheduler}': allowed: a scheduler address "
                      "tcp://HOST:PORT (or tls://HOST:PORT) or an existing scheduler JSON "
                      "file")


def check_cluster_options(command: str, workers: int, scheduler: str | None,
                          in_process: bool = False, alternative: str = "") -> None:
    """``--workers`` (a local cluster's size) and ``--scheduler`` (an existing cluster)
    exclude each other; the scheduler must look like one (:func:`check_scheduler`); Dask
    must be installed (:func:`require_dask`, naming ``alternative``) unless the work runs
    ``in_process``.
    ``ConfigError`` naming ``command``, the option and the value otherwise."""
    if scheduler is not None and workers:
        raise ConfigError(f"{command}: --workers = {workers}: sets the local cluster's size, "
                          "so it cannot go with --scheduler (the cluster there has its own "
                          "workers); allowed: one of the two")
    if scheduler is not None:
        check_scheduler(scheduler)
    if not in_process:
        require_dask(command, alternative)


def open_client(scheduler: str | None, workers: int) -> tuple[Any, Any]:
    """(client, local cluster or None): a ``LocalCluster`` of ``workers`` processes (0 =
    all local cores) with one thread each, or a client of the cluster at ``scheduler``
    (``tcp://HOST:PORT``, ``tls://...`` or a scheduler JSON file); ``ConfigError`` naming
    ``--scheduler`` when it cannot be reached within 15 s (or Dask is not installed)."""
    require_dask()
    import dask
    from distributed import Client, LocalCluster

    logging.getLogger("distributed").setLevel(logging.CRITICAL)
    if scheduler is not None:
        kw = check_scheduler(scheduler)
        try:
            return Client(timeout="15s", set_as_default=False, **kw), None
        except (OSError, TimeoutError, ValueError) as err:
            raise ConfigError(f"--scheduler = '{scheduler}': cannot connect ({err}); "
                              "allowed: the address of a running dask scheduler") from None
    n = workers or local_cores()
    with dask.config.set({"distributed.scheduler.worker-saturation": 1.0,
                          "distributed.worker.daemon": True}):
        # no dashboard; the scheduler's HTTP server (health routes) on a free port: its
        # default 8787 warns on stderr when another cluster holds it
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               dashboard_address="127.0.0.1:0",
                               scheduler_kwargs={"dashboard": False},
                               silence_logs=logging.CRITICAL, env=dict(WORKER_ENV))
    try:
        client = Client(cluster, set_as_default=False)
    except BaseException:
        cluster.close()
        raise
    return client, cluster


def close(client: Any, cluster: Any) -> None:
    """Close the client and (if ours) the local cluster, quietly."""
    for obj in (client, cluster):
        if obj is None:
            continue
        try:
            obj.close(timeout=10)
        except Exception:  # noqa: BLE001 - already gone
            pass


def _kill(pids: list[int]) -> None:
    """SIGKILL the local worker processes (their nannies are closed with the cluster)."""
    import signal

    for pid in pids:
        try:
            os.kill(pid, signal.SIGKILL)
        except OSError:
            pass


def _running(client: Any, keys: set[str]) -> int:
    """Our tasks being processed on a worker, at most one per worker thread."""
    try:
        busy = sum(1 for ks in client.processing().values() for k in ks if k in keys)
        return min(busy, sum(client.nthreads().values()))
    except Exception:  # noqa: BLE001 - a display only
        return 0


@contextmanager
def _session(scheduler: str | None, workers: int, futures: Callable[[], list[Any]],
             on_stop: Callable[[Any], None] | None = None) -> Iterator[tuple[Any, bool]]:
    """(client, whether the cluster is our local one) for the body of a ``with``; the
    client and the local cluster are closed after it. On Ctrl-C or any error in the body:
    our local workers killed at once (every file a task writes is atomic), ``on_stop``
    (client) called, the tasks ``futures()`` cancelled, client and cluster closed, the
    error re-raised."""
    client, cluster = open_client(scheduler, workers)
    pids: list[int] = []
    try:
        if cluster is not None:  # our own workers: killed at once on a stop
            pids = list(client.run(os.getpid).values())
        yield client, cluster is not None
    except BaseException:
        _kill(pids)
        for stop in (on_stop, lambda c: c.cancel(futures(), force=True)):
            if stop is None:
                continue
            try:
                stop(client)
            except Exception:  # noqa: BLE001 - best effort
                pass
        close(client, cluster)
        raise
    close(client, cluster)


def run_members(todo: Sequence[Member], total: int, done_before: int, *,
                scheduler: str | None, workers: int, progress: bool,
                echo: Callable[[str], None], desc: str = "sweep"
                ) -> tuple[dict[Hashable, dict[str, Any]], dict[Hashable, str], str]:
    """Run the tasks of ``todo`` on Dask; returns (summaries by key, failure message by key,
    a line describing the cluster). ``total`` and ``done_before``: the sweep's members and
    those finished before (the progress bar ``desc`` counts them). A failed member (an
    exception in its task, a task lost with its workers too often, a folder the client
    cannot see) is reported through ``echo`` and left out; the others go on. Ctrl-C or any
    error: stop event set, futures cancelled, client and local cluster closed, re-raised."""
    require_dask()
    from distributed import Event

    from tribodem.io import runs

    results: dict[Hashable, dict[str, Any]] = {}
    failed: dict[Hashable, str] = {}
    tag = uuid.uuid4().hex[:8]
    stop_name = f"tribodem-sweep-{tag}-stop"
    futs: dict[Any, Member] = {}
    # on a stop the sweep's event is set: tasks on a remote cluster stop at their next look
    with _session(scheduler, workers, lambda: list(futs),
                  lambda c: Event(stop_name, client=c).set()) as (client, local):
        nthreads = client.nthreads()
        where = (f"local cluster of {len(nthreads)} worker process(es) x 1 thread"
                 if local else
                 f"cluster at {client.scheduler.address} ({len(nthreads)} worker(s), "
                 f"{sum(nthreads.values())} thread(s) now)")
        for i, m in enumerate(todo):
            f = client.submit(m.task, *m.args, stop_name, key=f"{m.task_name}-{i}-{tag}",
                              pure=False, retries=0)
            futs[f] = m
        pending = set(futs)
        with runs.progress(total, "member", desc, enabled=progress,
                           initial=done_before) as bar:
            last = 0.0
            while pending:
                finished = {f for f in pending if f.done()}
                pending -= finished
                if not finished:
                    time.sleep(0.25)
                for f in finished:
                    m = futs[f]
                    try:
                        s = f.result()
                        if not (m.folder / "summary.json").is_file():
                            raise RuntimeError(
                                f"its summary.json is not visible from the client in "
                                f"'{m.folder}': --out must be on a file system shared by "
                                "the client and every worker")
                        results[m.key] = s
                    except Exception as err:  # noqa: BLE001 - reported, the rest go on
                        failed[m.key] = f"{type(err).__name__}: {err}"
                        echo(f"  {m.label}: failed: {failed[m.key]}")
                    bar.update(1)
                now = time.monotonic()
                if finished or now - last > 1.0:
                    last = now
                    keys = {f.key for f in pending}
                    bar.set_postfix_str(f"done {len(results) + done_before}, running "
                                        f"{_running(client, keys)}, failed {len(failed)}")
    return results, failed, where


#: ``map_(fn, items, on_done)``: ``[fn(x) for x in items]`` in order, ``on_done()`` after
#: each item finishes (in the order they finish)
Mapper = Callable[[Callable[[Any], Any], Sequence[Any], Callable[[], None] | None], list[Any]]


def serial_map(fn: Callable[[Any], Any], items: Sequence[Any],
               on_done: Callable[[], None] | None = None) -> list[Any]:
    """A :data:`Mapper` in this process, one item after another."""
    out = []
    for x in items:
        out.append(fn(x))
        if on_done is not None:
            on_done()
    return out


def one_thread_on_worker() -> None:
    """Inside a Dask worker: numba limited to one thread (a remote worker's environment is
    not ours, so :data:`WORKER_ENV` may not hold there); elsewhere nothing."""
    try:
        from distributed import get_worker

        get_worker()
    except (ImportError, ValueError):
        return
    import numba

    numba.set_num_threads(1)


@contextmanager
def task_map(scheduler: str | None, workers: int) -> Iterator[Mapper]:
    """A :data:`Mapper` on Dask: a ``LocalCluster`` of ``workers`` one-thread processes (0 =
    all local cores) or the cluster at ``scheduler`` (:func:`open_client`). For tasks
    whose results are small enough to return (no member folders, nothing to resume): the
    first failed task raises its error. On Ctrl-C or any error the local workers are
    killed, the tasks cancelled and the client closed before the error goes on."""
    from distributed import as_completed

    submitted: list[Any] = []
    with _session(scheduler, workers, lambda: submitted) as (client, _):

        def map_(fn: Callable[[Any], Any], items: Sequence[Any],
                 on_done: Callable[[], None] | None = None) -> list[Any]:
            futs = [client.submit(fn, x, pure=False) for x in items]
            submitted.extend(futs)
            for f in as_completed(futs, loop=client.loop):
                f.result()  # a failure raises here, at once
                if on_done is not None:
                    on_done()
            return [f.result() for f in futs]

        yield map_
