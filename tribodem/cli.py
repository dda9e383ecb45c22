"""The ``tribodem`` command (typer).

Sub-commands live next to the rooms they drive; this file only wires them. Every
user-facing error (bad config, bad input, numerical instability) becomes a one-line
message and a non-zero exit code, never a traceback:
exit 2 = bad input (refused before any work), exit 3 = run stopped (instability).
"""

from __future__ import annotations

import errno
import os
import re
import sys

import typer
from typer import TyperException

from tribodem import __version__
from tribodem.io.config import ConfigError

app = typer.Typer(
    name="tribodem",
    help="Wear at contact interfaces with particles (DEM, fretting FE-DE, cycle-jumping).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)


def _version(value: bool) -> None:
    if value:
        from tribodem.contact.cli import ccx_version

        typer.echo(f"tribodem {__version__}")
        typer.echo(ccx_version())
        raise typer.Exit()


@app.callback()
def _root(
    version: bool = typer.Option(False, "--version", callback=_version, is_eager=True,
                                 help="Print the version and exit."),
    verbose: int = typer.Option(0, "--verbose", "-v", count=True,
                                help="More messages on stderr (-vv: the libraries' too)."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="Only warnings and errors."),
) -> None:
    """tribodem: wear at contact interfaces with particles."""
    from tribodem.io.logs import configure

    configure(-1 if quiet else verbose)


#: Sub-commands: name -> (module, attribute, a typer group or a single command).
COMMANDS: dict[str, tuple[str, str, bool]] = {
    "calibrate": ("tribodem.materials.cli", "calibrate", False),
    "dem": ("tribodem.dem.cli", "dem_app", True),
    "bench": ("tribodem.dem.cli", "bench_app", True),
    "jump": ("tribodem.cyclejump.cli", "jump_app", True),
    "fretting": ("tribodem.fretting.cli", "fretting_app", True),
    "braking": ("tribodem.braking.cli", "braking_app", True),
    "validate": ("tribodem.contact.cli", "validate", False),
}


_registered: set[str] = set()


def full_app() -> typer.Typer:
    """The app with every sub-command registered (for in-process use, e.g. tests)."""
    _register()
    return app


def _register(argv: list[str] | None = None) -> None:
    """Add the sub-commands. Given the command line, only the one it names is imported (each
    room's imports cost up to a second); otherwise (help, a typo) all of them."""
    import importlib

    first = next((a for a in (argv or []) if not a.startswith("-")), None)
    names = [first] if first in COMMANDS else list(COMMANDS)
    for name in names:
        if name in _registered:
            continue
        _registered.add(name)
        module, attr, group = COMMANDS[name]
        obj = getattr(importlib.import_module(module), attr)
        if group:
            app.add_typer(obj, name=name)
        else:
            app.command(name)(obj)


def main() -> None:
    """Entry point: run the app, mapping every outcome to a message and an exit code.

    0 done; 2 usage or validation error (typer's own short message, or field, value and what
    is allowed); 3 the run stopped early (instability, contact outgrew the window): outputs
    kept, also after a fault of the file system (a full disk, a folder made read-only); 130
Ctrl-C, 143 SIGTERM, after saying where the outputs and the last checkpoint are. None of
    these prints a traceback.
    """
    from tribodem.io import runs, signals

    def interrupted() -> None:
        typer.echo(runs.interrupted_message(), err=True)
        sys.exit(signals.exit_code())

    try:
        _refuse_empty_values(sys.argv[1:])
        _register(sys.argv[1:])
        # without standalone mode typer *returns* the code of an Exit it caught, and turns
        # Ctrl-C into Exit(130): map both here
        rv = app(standalone_mode=False)
        if rv == 130:
            interrupted()
        if isinstance(rv, int) and not isinstance(rv, bool) and rv:
            sys.exit(rv)
    except ConfigError as err:
        typer.echo(f"error: {err}", err=True)
        sys.exit(2)
    except runs.RunStopped as err:
        typer.echo(f"run stopped: {err}", err=True)
        where = runs.where()
        if where:
            typer.echo(where, err=True)
        sys.exit(3)
    except (KeyboardInterrupt, typer.Abort):
        interrupted()
    except typer.Exit as e:
        sys.exit(e.exit_code)
    except TyperException as err:  # typer/click usage errors: its own short message
        show = getattr(err, "show", None)
        if callable(show):
            show()
        else:
            typer.echo(f"error: {err}", err=True)
        sys.exit(getattr(err, "exit_code", 2) or 2)
    except OSError as err:
        if err.errno not in FILE_SYSTEM_FAULTS:
            raise
        # a fault of the file system: before any work nothing was touched (exit 2); during
        # a run the last complete outputs and checkpoint are kept (exit 3)
        what = f"{err.strerror or err}" + (f": '{_intended(err.filename)}'"
                                            if err.filename else "")
        if not runs.started():
            typer.echo(f"error: cannot write the outputs: {what}", err=True)
            sys.exit(2)
        typer.echo(f"run stopped: a file could not be written: {what}", err=True)
        where = runs.where()
        if where:
            typer.echo(where, err=True)
        sys.exit(3)
    except Exception as err:
        # Ctrl-C inside compiled or C code (numba loading a kernel, for one) can surface as
        # another exception whose cause is the KeyboardInterrupt: still a Ctrl-C
        if _interrupt_in_chain(err):
            interrupted()
        raise


def _refuse_empty_values(argv: list[str]) -> None:
    """Refuse an option given the empty string (``--out ''`` would silently mean the
    current folder once typer has made it a path): ``ConfigError`` naming the option."""
    for i, arg in enumerate(argv):
        if not arg.startswith("--"):
            continue
        name, eq, value = arg.partition("=")
        if eq and not value.strip():
            raise ConfigError(f"{name} = '': allowed: a value (not empty)")
        if not eq and i + 1 < len(argv) and not argv[i + 1].strip():
            raise ConfigError(f"{name} = '': allowed: a value (not empty)")


#: errors of the file system that end a run cleanly (the disk, permissions, names, the mount)
FILE_SYSTEM_FAULTS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EACCES, errno.EPERM,
                                errno.ENAMETOOLONG, errno.EROFS, errno.EIO, errno.ENOTDIR,
                                errno.EISDIR, errno.EEXIST, errno.ENOENT})


#: the temporary an atomic write makes beside its file (tribodem.io.results.atomic_write):
#: ``.NAME.XXXXXXXX.tmp`` + NAME's suffix
_TEMPORARY = re.compile(r"^\.(?P<name>.+)\.[A-Za-z0-9_]{8}\.tmp(\.[^/]*)?$")


def _intended(filename: object) -> str:
    """The file a fault of the file system was about: for the temporary of an atomic write,
    the file it was to become (the name the user knows); else ``filename`` as it is."""
    text = os.fsdecode(filename) if isinstance(filename, str | bytes) else str(filename)
    head, _, tail = text.rpartition("/")
    m = _TEMPORARY.match(tail)
    return f"{head}/{m['name']}" if m and head else m["name"] if m else text


def _interrupt_in_chain(err: BaseException) -> bool:
    """Whether a KeyboardInterrupt is in ``err``'s chain of causes and contexts."""
    seen: set[int] = set()
    e: BaseException | None = err
    while e is not None and id(e) not in seen:
        if isinstance(e, KeyboardInterrupt):
            return True
        seen.add(id(e))
        e = e.__cause__ or e.__context__
    return False


if __name__ == "__main__":
    main()
