"""``tribodem validate``: each first-body backend against closed-form contact mechanics."""

from __future__ import annotations

import json
import logging
import tempfile
from pathlib import Path
from typing import Annotated

import typer

from tribodem.io.config import ConfigError
from tribodem.io.helptext import reflowed

#: backends with closed-form checks
SOLVERS = ("elastic", "elastic-plastic", "fe")

log = logging.getLogger(__name__)


@reflowed
def validate(
    solver: Annotated[str, typer.Option("--solver", help=f"One of: {', '.join(SOLVERS)}.")]
    = "elastic",
    as_json: Annotated[bool, typer.Option("--json", help="A JSON list of checks.")] = False,
    keep: Annotated[Path | None, typer.Option(
        "--keep", help="fe: keep the CalculiX jobs in this folder.")] = None,
    three_d: Annotated[bool, typer.Option(
        "--3d/--no-3d", help="fe: also the 3D crossed-cylinder checks (minutes of ccx).")
    ] = True,
) -> None:
    """Closed-form checks of a first-body backend: Hertz (point, line), Cattaneo-Mindlin,
    gross slip (fe: also through the reversals of a full cycle), first yield
    (elastic-plastic: with sliding friction mu = 0, 0.25, 0.5). Errors are
    relative, absolute (m) where the name says (m).
    Exit 0 when every check passes, 3 otherwise."""
    from tribodem.io.runs import RunStopped

    if solver not in SOLVERS:
        raise ConfigError(f"--solver = {solver!r}: allowed: {', '.join(SOLVERS)}")
    if solver == "fe":
        from tribodem.contact.fe.ccx import INSTALL_COMMAND, resolve_ccx

        if resolve_ccx() is None:
            raise ConfigError("--solver = 'fe' needs CalculiX's ccx, which is not on PATH; "
                              f"install it with: {INSTALL_COMMAND}")
        from tribodem.contact.fe.validate import validate_fe
        from tribodem.io.runs import announce, check_out_dir

        if keep is not None:  # Ctrl-C names the folder of the kept jobs
            check_out_dir(keep, "--keep")  # a folder (or a new one), writable
            announce(keep, resume_hint="the checks start again from the beginning")
        with tempfile.TemporaryDirectory(prefix="tribodem_fe_") as tmp:
            log.info("validate: the plane-strain checks, one ccx job after another (about a "
                     "minute)...")
            checks = validate_fe(keep or tmp, threads=1)
            if three_d:
                from tribodem.contact.fe.crossed import crossed_checks

                log.info("validate: the 3D crossed-cylinder checks (minutes of ccx; --no-3d "
                         "leaves them out)...")
                checks += crossed_checks(Path(keep or tmp), threads=1)
    elif solver == "elastic-plastic":
        from tribodem.contact.validate import elastic_plastic_checks

        log.info("validate: first yield with friction (about a minute)...")
        checks = elastic_plastic_checks()
    else:
        from tribodem.contact.validate import halfspace_checks

        checks = halfspace_checks()
    if as_json:
        typer.echo(json.dumps(checks, indent=2))
    else:
        for c in checks:
            mark = "ok  " if c["pass"] else "FAIL"
            typer.echo(f"{mark} {c['name']}: {c['value']:.6g} vs {c['reference']:.6g} "
                       f"(error {c['error']:.3g}, tolerance {c['tolerance']:.3g})")
    failed = [c["name"] for c in checks if not c["pass"]]
    if failed:
        raise RunStopped(f"{len(failed)} check(s) failed: {', '.join(failed)}")


def ccx_version() -> str:
    """The CalculiX ``ccx`` the finite-element backends run (``resolve_ccx``: its path,
    version line, direct solvers and tribodem's patches), or how to install it."""
    from tribodem.contact.fe.ccx import INSTALL_COMMAND, ccx_build, resolve_ccx

    exe = resolve_ccx()
    if exe is None:
        return f"ccx: not found ({INSTALL_COMMAND})"
    b = ccx_build(exe)
    solvers = ", ".join(b["solvers"]) or "solvers unknown"
    patches = f"; patches: {', '.join(b['patches'])}" if b["patches"] else ""
    return f"ccx: {exe} ({b['version']}; {solvers}{patches})"
