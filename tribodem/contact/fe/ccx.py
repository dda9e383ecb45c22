"""Run CalculiX ``ccx`` as a subprocess with a wall-clock limit and clear failures.

* The job runs in its folder (deck, log ``<job>.log``, ``.sta``, ``.dat``, ``.frd`` kept).
* ``threads`` sets ``OMP_NUM_THREADS``, ``CCX_NPROC_EQUATION_SOLVER`` and
  ``MKL_NUM_THREADS`` (PARDISO builds).
* glibc's malloc keeps freed memory in the process (``MALLOC_TUNABLES``, unless the caller
  set ``GLIBC_TUNABLES``): ccx allocates and frees its matrices every Newton iteration, and
  with glibc's defaults each round trip went back to the kernel as fresh zeroed pages (7.1
  million page faults, 11 % of the CPU time of the seed's 3D elastic-plastic loading); with
  the tunables 0.8 million and 8-12 % less CPU, the same .dat byte for byte (docs/fe3d.md).
* A run longer than ``timeout`` seconds is killed (its whole process group) and raises
  :class:`CcxTimeoutError` (a bad contact setup can make ccx iterate for ever); ccx is also
  killed on Ctrl-C, and on Linux when the Python process dies (``PR_SET_PDEATHSIG``).
* A non-zero exit code, an ``*ERROR`` line in the log, or a missing "Job finished" raises
  :class:`CcxError` (:class:`CcxConvergenceError` when ccx reports divergence or too many
  cutbacks) carrying the ccx message, the deck path and the last ``.sta`` line.
* No ``ccx`` executable raises :class:`CcxNotFoundError` naming the install command.
* Which ccx (:func:`resolve_ccx`): the one named by the caller, else ``$TRIBODEM_CCX``, else
  ``ccx_pardiso`` (the PARDISO build of ``tools/build_ccx_pardiso``, on PATH or beside this
  Python), else ``ccx`` on PATH (Debian's calculix-ccx: SPOOLES only). The decks are the
  same for every build: ccx uses PARDISO as its default solver when it is built in.
"""

from __future__ import annotations

import functools
import os
import shutil
import signal
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

#: the one command that installs the solver (Debian/Ubuntu package of CalculiX 2.20)
INSTALL_COMMAND = "apt-get install -y calculix-ccx"
#: environment variable naming the ccx to run (a name on PATH or a path)
CCX_ENV = "TRIBODEM_CCX"
#: the executable ``tools/build_ccx_pardiso`` installs (ccx 2.20 with MKL's PARDISO)
PARDISO_NAME = "ccx_pardiso"

_CONVERGENCE_WORDS = ("diverge", "cutback", "too many iterations", "increment size smaller",
                      "no convergence", "not converge")


class CcxNotFoundError(FileNotFoundError):
    """The ccx executable is not on PATH."""


class FESolverStopped(RuntimeError):
    """The finite-element solve cannot go on (ccx failed, the mesh cannot be morphed); a
    fretting run stops early with this message and keeps its outputs (exit 3)."""


class CcxError(FESolverStopped):
    """ccx stopped with an error; ``message`` is ccx's own text, ``deck`` the input file."""

    def __init__(self, what: str, message: str, deck: Path, sta: str = "") -> None:
        self.message = message
        self.deck = deck
        self.sta = sta
        text = f"{what} (deck {deck}): {message}"
        if sta:
            text += f"\nlast .sta line: {sta}"
        super().__init__(text)


class CcxConvergenceError(CcxError):
    """ccx did not converge (diverging iterations, too many cutbacks)."""


class CcxTimeoutError(CcxError):
    """ccx ran longer than the wall-clock limit and was killed."""


@dataclass
class CcxRun:
    """A finished ccx job."""

    job: Path  #: ``<folder>/<name>`` without suffix
    seconds: float  #: wall-clock time of the ccx process, s
    log: str  #: ccx's standard output and error
    cached: bool = False  #: the results were copied from a job cache (no ccx process run)

    @property
    def dat(self) -> Path:
        return self.job.with_suffix(".dat")

    @property
    def frd(self) -> Path:
        return self.job.with_suffix(".frd")


def resolve_ccx(executable: str | None = None) -> str | None:
    """Path of the ccx to run, or None when there is none: ``executable`` (a name on PATH or
    a path) if given; else ``$TRIBODEM_CCX``; else ``ccx_pardiso`` on PATH or in this
    Python's ``bin`` folder (``tools/build_ccx_pardiso``); else ``ccx`` on PATH."""
    if executable is None:
        executable = os.environ.get(CCX_ENV) or None
    if executable is not None:
        return shutil.which(executable)
    beside_python = str(Path(sys.prefix) / "bin")
    return (shutil.which(PARDISO_NAME) or shutil.which(PARDISO_NAME, path=beside_python)
            or shutil.which("ccx"))


def find_ccx(executable: str | None = None) -> str:
    """Absolute path of the ccx :func:`resolve_ccx` picks, else :class:`CcxNotFoundError`
    naming the install command."""
    path = resolve_ccx(executable)
    if path is None:
        what = executable or os.environ.get(CCX_ENV) or "ccx"
        raise CcxNotFoundError(
            f"CalculiX solver '{what}' not found on PATH; install it with: "
            f"{INSTALL_COMMAND}")
    return path


def _markers_in(path: str, markers: dict[str, bytes]) -> list[str]:
    """The names of ``markers`` whose bytes occur in the file at ``path`` (none if unreadable)."""
    try:
        data = Path(path).read_bytes()
    except OSError:
        return []
    return [name for name, marker in markers.items() if marker in data]


#: the direct solvers a ccx can be built with, each found by its factorisation message
CCX_SOLVERS = {name: f"using the unsymmetric {name.lower()} solver".encode()
               for name in ("PARDISO", "SPOOLES")}


def ccx_solvers(path: str) -> list[str]:
    """The direct solvers built into the ccx at ``path`` (``PARDISO``, ``SPOOLES``), read
    from the messages in the binary; the first is the one ccx uses by default."""
    return _markers_in(path, CCX_SOLVERS)


#: tribodem's ccx patches (``tools/*.patch``, applied by ``tools/build_ccx_pardiso``; docs/fe3d.md
#: "Two ccx patches"), each found by a message only the patched binary carries
CCX_PATCHES = {
    "pardiso_analysis_kept": b"in pardiso_main: PARDISO error",
    "contact_divergence": b"the residual rose in two iterations running",
}


def ccx_patches(path: str) -> list[str]:
    """tribodem's patches (:data:`CCX_PATCHES`) built into the ccx at ``path``."""
    return _markers_in(path, CCX_PATCHES)


@functools.lru_cache(maxsize=8)
def _ccx_build(path: str, size: int, mtime_ns: int) -> tuple[str, tuple[str, ...],
                                                             tuple[str, ...]]:
    del size, mtime_ns  # the cache key: a rebuilt binary is read again
    try:
        out = subprocess.run([path, "-v"], capture_output=True, text=True, timeout=10).stdout
        line = next((x.strip() for x in out.splitlines() if "Version" in x), "version unknown")
    except (OSError, subprocess.TimeoutExpired):
        line = "version unknown"
    found = _markers_in(path, CCX_SOLVERS | CCX_PATCHES)  # one read of the binary
    return (line, tuple(n for n in found if n in CCX_SOLVERS),
            tuple(n for n in found if n in CCX_PATCHES))


def ccx_build(path: str) -> dict[str, Any]:
    """Which ccx ran, for summaries and ``--version``: ``executable`` (path), ``version``
    (its version line), ``solvers`` (:func:`ccx_solvers`, the default first) and
    ``patches`` (:func:`ccx_patches`). Results of two builds agree within the solver's
    tolerances, not in every digit (docs/fe3d.md)."""
    try:
        st = Path(path).stat()
    except OSError:
        return {"executable": path, "version": "not found", "solvers": [], "patches": []}
    line, solvers, patches = _ccx_build(path, st.st_size, st.st_mtime_ns)
    return {"executable": path, "version": line, "solvers": list(solvers),
            "patches": list(patches)}


def _last_sta_line(job: Path) -> str:
    sta = job.with_suffix(".sta")
    if not sta.exists():
        return ""
    lines = [ln.strip() for ln in sta.read_text(errors="replace").splitlines() if ln.strip()]
    return lines[-1] if lines else ""


def _error_text(log: str) -> str:
    """The ``*ERROR`` paragraph(s) of a ccx log (up to 6 lines each)."""
    lines = log.splitlines()
    out: list[str] = []
    for i, ln in enumerate(lines):
        if "*ERROR" in ln:
            para = [ln.strip()]
            for nxt in lines[i + 1:i + 6]:
                if not nxt.strip() or "*ERROR" in nxt:
                    break
                para.append(nxt.strip())
            text = " ".join(para)
            if text not in out:
                out.append(text)
    return " | ".join(out)


def _die_with_parent() -> None:
    """In the child before exec (Linux): SIGKILL when the Python parent dies, so a killed
    driver does not leave ccx running in its own session."""
    try:
        import ctypes

        ctypes.CDLL(None).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


#: glibc malloc tunables for ccx (see the module docstring): blocks up to 32 MiB (glibc's
#: largest mmap threshold) from the heap, never trimmed back, grown 256 MiB at a time
MALLOC_TUNABLES = ("glibc.malloc.mmap_threshold=33554432:"
                   "glibc.malloc.trim_threshold=4294967296:glibc.malloc.top_pad=268435456")


def _kill(proc: subprocess.Popen[bytes]) -> None:
    """Kill ccx's process group (it runs in its own session) and reap it."""
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    proc.wait()


def run_ccx(deck: str | Path, threads: int = 1, timeout: float = 600.0,
            executable: str | None = None) -> CcxRun:
    """Run ``ccx -i <job>`` in the deck's folder; see the module docstring for failures."""
    deck = Path(deck).resolve()
    if deck.suffix != ".inp" or not deck.exists():
        raise FileNotFoundError(f"deck {deck} does not exist or is not a .inp file")
    exe = find_ccx(executable)
    job = deck.with_suffix("")
    env = dict(os.environ, OMP_NUM_THREADS=str(int(threads)),
               CCX_NPROC_EQUATION_SOLVER=str(int(threads)), MKL_NUM_THREADS=str(int(threads)))
    env.setdefault("GLIBC_TUNABLES", MALLOC_TUNABLES)
    log_path = job.with_suffix(".log")
    t0 = time.perf_counter()
    with open(log_path, "w") as log_file:
        proc = subprocess.Popen([exe, "-i", job.name], cwd=deck.parent, env=env,
                                stdout=log_file, stderr=subprocess.STDOUT,
                                start_new_session=True,
                                preexec_fn=_die_with_parent if sys.platform == "linux" else None)
        try:
            rc = proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            _kill(proc)
            raise CcxTimeoutError(f"ccx exceeded the {timeout:g} s wall-clock limit and was "
                                  "killed", "no result", deck, _last_sta_line(job)) from None
        except BaseException:  # Ctrl-C and the like: do not leave ccx running
            _kill(proc)
            raise
    seconds = time.perf_counter() - t0
    log = log_path.read_text(errors="replace")
    err = _error_text(log)
    if rc != 0 or err or "Job finished" not in log:
        tail = " | ".join(ln.strip() for ln in log.splitlines() if ln.strip())[-300:]
        message = err or f"exit code {rc}, no 'Job finished' in {log_path}; log ends: {tail}"
        cls = CcxConvergenceError if any(w in message.lower() for w in _CONVERGENCE_WORDS) \
            else CcxError
        raise cls(f"ccx failed (exit code {rc})", message, deck, _last_sta_line(job))
    return CcxRun(job=job, seconds=seconds, log=log)
