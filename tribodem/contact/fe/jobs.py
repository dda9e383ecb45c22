"""What the ccx-per-cycle first-body backends (``fe``: 2D, ``fe3d``: 3D) share.

A job's record and the run folder's ``jobs.csv`` / JSON of them, one ccx job run with
retries at smaller increments, the jobs' mean time profile, serving a cycle's stored
increments in order, and the stop when a criterion asks for stresses deeper than ccx prints.
"""

from __future__ import annotations

import csv
import hashlib
import json
import math
import shutil
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from tribodem.contact.base import ElasticBody, IncrementResult, Unsupported
from tribodem.contact.elastoplastic import PlasticStep
from tribodem.contact.fe.ccx import (
    CcxConvergenceError,
    CcxRun,
    FESolverStopped,
    ccx_build,
    resolve_ccx,
    run_ccx,
)
from tribodem.contact.fe.deck import ContactSettings
from tribodem.io.results import write_csv, write_text


@dataclass
class JobRecord:
    """One ccx job of a backend: where, what it cost (s) and what it gave."""

    cycle: int  #: the fretting cycle it serves (1-based)
    folder: Path
    deck: Path
    elements: int
    refine: int  #: increment refinement of the successful attempt (1: none)
    seconds_mesh: float  #: meshing, morphing and deck writing, s
    seconds_ccx: float  #: ccx wall clock (all attempts), s
    seconds_read: float  #: reading the .dat and recovering the tractions, s
    seconds_map: float = 0.0  #: mapping the fields to the window, s
    cycles: int = 1  #: cycles after the loading in the job (chained mode: > 1)
    worn_volume_upper: float = 0.0  #: worn volume of the morphed upper body, m^3
    worn_volume_lower: float = 0.0  #: worn volume of the morphed lower body, m^3
    cached: bool = False  #: ccx's results came from the job cache (not run again)
    penalty_scale: float = 1.0  #: contact penalty scale of the successful attempt


#: a column that an older ``jobs.csv`` lacks, and what its rows meant by leaving it out
JOB_DEFAULTS = {"penalty_scale": "1"}
JOB_COLUMNS = ("cycle", "cycles", "elements", "refine", "penalty_scale", "seconds_mesh",
               "seconds_ccx", "seconds_read", "seconds_map", "worn_volume_upper_m3",
               "worn_volume_lower_m3", "cached", "deck")


def prior_job_rows(path: Path) -> list[list[str]]:
    """The rows of an interrupted run's ``jobs.csv`` in ``JOB_COLUMNS`` order (a file
    written before a column existed gets ``JOB_DEFAULTS``); ``[]`` when there is no such
    file or its header has a column this version does not know."""
    if not path.exists():
        return []
    with open(path, newline="") as fh:
        reader = csv.DictReader(fh)
        fields = set(reader.fieldnames or ())
        rows = list(reader)
    if not fields or not fields <= set(JOB_COLUMNS):
        return []
    return [[row.get(c) or JOB_DEFAULTS.get(c, "") for c in JOB_COLUMNS] for row in rows]


#: materials of the ccx backends: elastic, or bilinear elastic-plastic (``*PLASTIC``)
MATERIALS = ("elastic", "elastic-plastic")


#: the ccx outputs a job cache keeps (and copies back on a hit)
CACHED_SUFFIXES = (".dat", ".frd", ".sta", ".cvg", ".log")


def _cache_key(deck_hash: Any, executable: str | None) -> str:
    """The deck's bytes (``deck_hash``, their sha256) and the ccx executable (path, size,
    mtime): equal keys, equal results (ccx is deterministic for a given deck and build)."""
    h = deck_hash.copy()
    exe = resolve_ccx(executable)
    if exe:
        st = Path(exe).stat()
        h.update(f"{exe}|{st.st_size}|{st.st_mtime_ns}".encode())
    return h.hexdigest()[:32]


def _from_cache(deck: Path, cache: Path, key: str) -> CcxRun | None:
    entry = cache / key
    if not (entry / "job.dat").exists():
        return None
    job = deck.with_suffix("")
    for suffix in CACHED_SUFFIXES:
        if (entry / f"job{suffix}").exists():
            shutil.copyfile(entry / f"job{suffix}", job.with_suffix(suffix))
    return CcxRun(job=job, seconds=0.0, log=job.with_suffix(".log").read_text(errors="replace"),
                  cached=True)


def _to_cache(run: CcxRun, cache: Path, key: str) -> None:
    """Copy a finished job's outputs into ``cache/key`` (a temporary folder renamed into
    place: a reader never sees half an entry; a concurrent writer's entry is kept)."""
    cache.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{key}-", dir=cache))
    for suffix in CACHED_SUFFIXES:
        src = run.job.with_suffix(suffix)
        if src.exists():
            shutil.copyfile(src, tmp / f"job{suffix}")
    try:
        tmp.rename(cache / key)
    except OSError:  # another process stored it first
        shutil.rmtree(tmp, ignore_errors=True)


#: beside a deck that did not converge: its key (``_failure_key``) on the first line, then
#: ccx's message. ``run_job`` does not run a deck with that key again (a resumed run goes
#: on from the next attempt); delete the file to run it again (ccx with PARDISO on several
#: threads sums in another order each run, so a failed deck may pass another time).
FAILED_SUFFIX = ".failed"


def _failure_key(deck_hash: Any, executable: str | None) -> str:
    """The deck's bytes (``deck_hash``) and the ccx build by what it is (version line,
    solvers, patches: :func:`~tribodem.contact.fe.ccx.ccx_build`), not by its file as
    ``_cache_key``: a record carried to another machine (``tools/carry_run``), whose
    ``tools/build_ccx_pardiso`` made the same build anew, still skips the attempt that
    failed."""
    h = deck_hash.copy()
    exe = resolve_ccx(executable)
    if exe:
        b = ccx_build(exe)
        h.update(f"{b['version']}|{','.join(b['solvers'])}|{','.join(b['patches'])}".encode())
    return h.hexdigest()[:32]


def _known_failure(deck: Path, key: str) -> str | None:
    """ccx's message for ``deck`` if a deck with ``key`` failed to converge here before."""
    rec = deck.with_suffix(FAILED_SUFFIX)
    if not rec.is_file():
        return None
    first, _, message = rec.read_text().partition("\n")
    return message if first == key else None


def checked_increments(name: str, value: float) -> int:
    """``value`` as ccx increments per cycle: an integer >= 4 (``ValueError`` naming
    ``name`` otherwise)."""
    if int(value) != value or value < 4:
        raise ValueError(f"{name} = {value!r} is not allowed: an integer >= 4")
    return int(value)


def attempt_settings(attempt: int) -> tuple[int, float]:
    """(increment refinement, contact penalty scale) of ``run_job``'s attempt ``attempt`` (0:
    the job as configured): the retries halve the increments and the contact's penalty
    stiffnesses (normal and stick slope together) in turn: (1, 1), (2, 1), (2, 1/2), (4,
    1/2), (4, 1/4). The softer contact is for the stick / slip state of a node on a worn
    rim that flips every Newton iteration whatever the increment (docs/fe3d.md)."""
    return 2 ** ((attempt + 1) // 2), 0.5 ** (attempt // 2)


def attempt_index(refine: int, scale: float) -> int:
    """The attempt of :func:`attempt_settings` that runs at increment refinement ``refine``
    and contact penalty scale ``scale`` (``ValueError`` for a pair no attempt has)."""
    for attempt in range(2 * int(math.log2(max(int(refine), 1))) + 2):
        if attempt_settings(attempt) == (int(refine), float(scale)):
            return attempt
    raise ValueError(f"no attempt runs at refine {refine!r}, penalty scale {scale!r}")


#: where a job's attempts start (``[fe] retry_from``): ``first``, the job as configured
#: (every job); ``last``, the attempt on which the previous job converged (the attempts
#: before it are not run: a worn geometry that needed a finer or softer attempt in one cycle
#: mostly needs it in the next, and each failed attempt costs up to a whole job)
RETRY_FROM = ("first", "last")

#: the friction coefficient while seating and loading (``[fe] loading_friction``): ``low``,
#: ContactSettings.mu_loading (1e-3: the frictionless normal problem, which for elastically
#: similar bodies does not depend on friction, as validated); ``full``, the interface's mu
#: from the first touch, as on a rig; ``auto``, ``full`` for elastic-plastic bodies (not
#: similar once they yield; worn plastic fe3d geometries got through only with it) and
#: ``low`` for elastic ones (the worn h = a quick preset stopped with ``full``): docs/fe3d.md
#: "Friction while loading", measured
LOADING_FRICTION = ("auto", "low", "full")


def run_job(write: Callable[[int, str, float], Path], retries: int, threads: int,
            timeout: float, executable: str | None, cache: Path | None = None,
            start: int = 0) -> tuple[CcxRun, int, float, float, float]:
    """Write and run one ccx job, retrying a non-converging one (``retries`` more attempts,
    :func:`attempt_settings`; the last failure is raised). ``start``: the first attempt
    run (0: the job as configured; at most ``retries``; see :data:`RETRY_FROM`).

    ``write(refine, name, penalty_scale)`` writes the deck ``name`` (``job``,
    ``job_refine2``, ``job_refine2_soft2``, ...) at that refinement and contact penalty scale
    and returns its path. ``cache``: a folder of finished jobs keyed by the deck's bytes and
    the ccx build; a deck found there is not run again, its outputs are copied into the job
    folder (``CcxRun.cached``). A deck that did not converge leaves a ``FAILED_SUFFIX``
    record beside it, and the same deck is not run again (the next attempt follows): a run
    resumed after a stopped cycle, with more ``retries``, goes on where it stopped. Returns
    (the run, its refinement, its penalty scale, seconds writing decks, seconds in ccx over
    all attempts)."""
    t_deck = t_ccx = 0.0
    for attempt in range(min(max(int(start), 0), retries), retries + 1):
        refine, scale = attempt_settings(attempt)
        name = "job" if attempt == 0 else f"job_refine{refine}"
        if scale != 1.0:
            name += f"_soft{round(1.0 / scale)}"
        t1 = time.perf_counter()
        deck = write(refine, name, scale)
        t_deck += time.perf_counter() - t1
        deck_hash = hashlib.sha256(deck.read_bytes())  # read and hashed once for both keys
        key = _cache_key(deck_hash, executable)
        if cache is not None:
            hit = _from_cache(deck, cache, key)
            if hit is not None:
                return hit, refine, scale, t_deck, t_ccx
        fkey = _failure_key(deck_hash, executable)
        known = _known_failure(deck, fkey)
        if known is not None:  # this very deck failed here before: the next attempt
            if attempt == retries:
                raise CcxConvergenceError(
                    "ccx did not converge on this same deck before (not run again; delete "
                    f"{deck.with_suffix(FAILED_SUFFIX)} to retry it)", known, deck)
            continue
        t2 = time.perf_counter()
        try:
            run = run_ccx(deck, threads=threads, timeout=timeout, executable=executable)
        except CcxConvergenceError as err:
            t_ccx += time.perf_counter() - t2
            write_text(deck.with_suffix(FAILED_SUFFIX), f"{fkey}\n{err}")
            if attempt == retries:
                raise
            continue
        t_ccx += time.perf_counter() - t2
        if cache is not None:
            _to_cache(run, cache, key)
        return run, refine, scale, t_deck, t_ccx
    raise AssertionError("unreachable")  # pragma: no cover


def check_stress_depth(depth: float, printed: float, backend: str) -> None:
    """Stop the run (:class:`FESolverStopped`, exit 3) when a stress grid ``depth`` (m) goes
    deeper than the columns ``backend`` has ccx print (``printed``, m), saying what to set."""
    if depth > printed * (1 + 1e-9):
        raise FESolverStopped(
            f"the stress grid asked for reaches {depth:.4g} m below the surface, deeper "
            f"than the {backend} solver prints the column stresses ({printed:.4g} m); "
            "set wear.stress_depth (it sets both the criterion's grid and the depth ccx "
            "prints)")


class CcxJobs:
    """Mixin of the ccx-per-cycle backends: the work folder, running a job's attempts, the
    jobs' records and profile, and serving a cycle's increments. The backend
    (:class:`~tribodem.contact.fe.base.CcxBackend`) sets ``name``, ``workdir``, ``jobs``,
    ``_cycle``, ``_k``, ``_served``, ``offsets``, ``amplitude``, ``n_increments`` and the
    attributes declared below."""

    name: ClassVar[str]
    workdir: Path | None
    jobs: list[JobRecord]
    offsets: NDArray[np.float64]
    amplitude: float
    n_increments: int
    _cycle: int
    _k: int | None
    _served: list[IncrementResult]
    _prior_jobs: list[list[str]] | None = None

    upper_material: ElasticBody
    lower_material: ElasticBody
    coords: NDArray[np.float64]
    dx: float
    n: int
    _pending: list[PlasticStep]
    settings: ContactSettings  #: the interface law as configured
    mesh: Any  #: the (morphed) mesh of the last job (``h_fine``, m)
    retries: int
    threads: int
    timeout: float
    executable: str  #: the ccx executable (:func:`~tribodem.contact.fe.ccx.find_ccx`)
    cache: Path | None
    #: where a job's attempts start (:data:`RETRY_FROM`)
    retry_from: str = "first"
    #: the seating and loading friction that runs, "low" or "full" (:data:`LOADING_FRICTION`)
    loading_friction: str = "low"
    plastic: bool
    friction: float
    #: the attempt on which the last job converged (:func:`attempt_index`; kept in the
    #: backend's state, so a resumed run starts where the uninterrupted one would)
    _last_attempt: int = 0

    def _first_attempt(self) -> int:
        """The attempt the next job starts at (:data:`RETRY_FROM`)."""
        return min(self._last_attempt, self.retries) if self.retry_from == "last" else 0

    @property
    def _penalty_scale(self) -> float:
        """The contact penalty scale of the last job's converged attempt."""
        return attempt_settings(self._last_attempt)[1]

    def _run_attempts(self, write: Callable[[int, str, float], Path]
                      ) -> tuple[CcxRun, int, float, float, float]:
        """:func:`run_job` with this backend's ccx settings, from :meth:`_first_attempt`;
        keeps the attempt that converged (``_last_attempt``)."""
        out = run_job(write, self.retries, self.threads, self.timeout, self.executable,
                      self.cache, start=self._first_attempt())
        self._last_attempt = attempt_index(out[1], out[2])
        return out

    def _attempt_report(self) -> dict[str, Any]:
        """The last job's converged attempt, for its cycles' reports (summary.json): its
        index, increment refinement and contact penalty scale (:func:`attempt_settings`; a
        softened contact changes the fields, docs/fe.md ``retry_from``)."""
        refine, scale = attempt_settings(self._last_attempt)
        return {"ccx_attempt": self._last_attempt, "attempt_refine": refine,
                "contact_penalty_scale": scale, "loading_mu": self.settings.mu_loading}

    def _restore_last_attempt(self, state: dict[str, Any], refine_unit: int = 1) -> None:
        """``_last_attempt`` from a saved state, else (a state saved before it was kept)
        from the last row of the run's ``jobs.csv`` (its refine divided by
        ``refine_unit``, the job's own refinement of the cycle), else 0."""
        if "last_attempt" in state:
            self._last_attempt = int(state["last_attempt"])
            return
        rows = prior_job_rows(self.workdir / "jobs.csv") if self.workdir is not None else []
        self._last_attempt = 0
        if rows:
            row = dict(zip(JOB_COLUMNS, rows[-1], strict=True))
            try:
                self._last_attempt = attempt_index(int(row["refine"]) // refine_unit,
                                                   float(row["penalty_scale"]))
            except ValueError:
                pass

    def _scaled_settings(self, scale: float) -> ContactSettings:
        """``settings`` with the penalty stiffnesses (normal, and the stick slope with it)
        scaled by ``scale`` (a retry's softer contact)."""
        s = self.settings
        return s if scale == 1.0 else replace(s, penalty_factor=s.penalty_factor * scale)

    def _stick_slope(self) -> float:
        """The last job's stick slope k_t, Pa/m: stick factor x penalty factor x E_min / h
        of the contact its converged attempt ran with (a slip increment up to mu p / k_t is
        the interface spring's, i.e. stick)."""
        return self._scaled_settings(self._penalty_scale).stick_slope(
            self.upper_material.young, self.lower_material.young, self.mesh.h_fine)

    def _plastic_grid_x(self, body: str) -> NDArray[np.float64]:
        """x of the plastic-step grid: the window (upper, its own frame) or the window plus
        the stroke (lower, lab frame) at the window spacing, m."""
        if body == "upper":
            return self.coords
        pad = math.ceil(self.amplitude / self.dx) + 1
        return ((np.arange(-pad, self.n + pad) - self.n // 2) * self.dx).astype(np.float64,
                                                                                 copy=False)

    def plastic_steps(self) -> list[PlasticStep]:
        """The plastic steps solved since the last call (then forgotten): the loading (a
        job's first cycle) and every output increment of the cycles served, one step per
        body (:attr:`PlasticStep.body`: the upper body's grid in its window frame, the lower
        body's in the lab frame over the window plus the stroke)."""
        if not self.plastic:
            raise Unsupported(f"the {self.name} solver gives plastic strain with material = "
                              "'elastic-plastic'")
        out, self._pending = self._pending, []
        return out

    def _folder(self) -> Path:
        """This cycle's job folder (a temporary work folder if none was given)."""
        if self.workdir is None:
            self.workdir = Path(tempfile.mkdtemp(prefix=f"tribodem-{self.name}-"))
        return self.workdir / f"cycle_{self._cycle + 1:04d}"

    _loaded: bool
    _fresh_for_cycle: bool = False

    def column_wear(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Worn depth (m) at each node column of the (upper, lower) body."""
        raise NotImplementedError

    def _start_cycle(self) -> None:
        """Make the next cycle's increments (a job, or the next cycle of one) and serve it."""
        raise NotImplementedError

    def _load(self) -> IncrementResult:
        """The first loading's increment, running the loading's job if it is not run."""
        raise NotImplementedError

    def _key(self) -> tuple[bytes, ...]:
        """The geometry a job was run on: the column wear of both bodies."""
        wu, wl = self.column_wear()
        return wu.tobytes(), wl.tobytes()

    def begin_cycle(self) -> None:
        """Make this cycle's increments: a ccx job on the current surfaces, unless the job
        already run serves it (the loading's job, or the next cycle of a chain)."""
        self._start_cycle()

    def solve_increment(self, offset: float) -> IncrementResult:
        """Serve the stored increment ending at ``offset`` (m): ``0.0`` after ``reset`` is
        the normal loading; then the cycle's offsets in order (:func:`cycle_offsets` of
        ``amplitude``, ``n_increments``); anything else is a ``ValueError``."""
        offset = float(offset)
        if self._k is None:
            if offset == 0.0 and not self._loaded:
                inc = self._load()
                self._fresh_for_cycle = True  # the first cycle may reuse the loading's job
                self._loaded = True
                return inc
            self._start_cycle()
        inc = self._next_increment(offset)
        self._loaded = True
        return inc

    def _next_increment(self, offset: float) -> IncrementResult:
        """The stored increment ending at ``offset`` (m), the next of the cycle in order;
        anything else is a ``ValueError``."""
        assert self._k is not None
        expected = float(self.offsets[self._k])
        if abs(offset - expected) > 1e-9 * self.amplitude:
            raise ValueError(
                f"offset = {offset!r} m is not increment {self._k + 1} of the {self.name} "
                f"job's cycle (expected {expected!r} m: amplitude {self.amplitude:g} m, "
                f"n_increments {self.n_increments}); the {self.name} backend serves the cycle "
                "0 -> +A -> 0 -> -A -> 0 in order")
        inc = self._served[self._k]
        self._k += 1
        if self._k == len(self.offsets):
            self._k = None
        return inc

    def _write_profile(self) -> None:
        """``workdir/jobs.csv``: one row per job (a resumed run's after the rows written
        before it stopped), rewritten atomically whenever a job is run or its fields are mapped."""
        assert self.workdir is not None
        path = self.workdir / "jobs.csv"
        if self._prior_jobs is None:
            self._prior_jobs = prior_job_rows(path)
        rows: list[list[Any]] = [
            [rec.cycle, rec.cycles, rec.elements, rec.refine, f"{rec.penalty_scale:g}",
             f"{rec.seconds_mesh:.4f}",
             f"{rec.seconds_ccx:.3f}", f"{rec.seconds_read:.4f}", f"{rec.seconds_map:.4f}",
             f"{rec.worn_volume_upper:.9e}", f"{rec.worn_volume_lower:.9e}",
             int(rec.cached), str(rec.deck)]
            for rec in self.jobs]
        write_csv(path, JOB_COLUMNS, self._prior_jobs + rows)

    def profile(self) -> dict[str, float]:
        """Seconds spent per job, averaged over the jobs run: meshing (with morphing and the
        deck), ccx, reading, mapping to the window; and the number of jobs."""
        if not self.jobs:
            return {"jobs": 0}
        keys = ("seconds_mesh", "seconds_ccx", "seconds_read", "seconds_map")
        return {"jobs": len(self.jobs),
                **{k: float(np.mean([getattr(j, k) for j in self.jobs])) for k in keys}}

    def write_json(self, path: str | Path) -> Path:
        """The jobs' records as JSON (for a run folder)."""
        path = Path(path)
        path.write_text(json.dumps([{**vars(j), "folder": str(j.folder), "deck": str(j.deck)}
                                    for j in self.jobs], indent=1))
        return path
