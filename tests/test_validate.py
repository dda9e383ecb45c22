"""``tribodem validate``: the half-space backend against closed-form contact mechanics, and
the FE backend refused without CalculiX (its own checks run in tests/test_fe.py)."""

from __future__ import annotations

import json
import os

from conftest import run_tribodem


def test_halfspace_passes_every_closed_form_check() -> None:
    r = run_tribodem("validate", "--solver", "elastic", "--json")
    assert r.returncode == 0, r.stderr
    checks = json.loads(r.stdout)
    names = {c["name"] for c in checks}
    for key in ("hertz point p0 (Pa)", "hertz line a (m)", "gross slip Q / (mu P)",
                "first yield load (N)"):
        assert key in names
    assert sum("mindlin Q" in n for n in names) == 3
    assert sum("stick radius" in n for n in names) == 3
    for c in checks:
        assert set(c) == {"name", "value", "reference", "error", "tolerance", "pass"}
        assert c["pass"] and c["error"] <= c["tolerance"], c


def test_fe_without_ccx_exits_2_with_the_install_command() -> None:
    env = {**os.environ, "PATH": "/nonexistent", "TRIBODEM_CCX": "ccx"}
    r = run_tribodem("validate", "--solver", "fe", env=env)
    assert r.returncode == 2 and "apt-get install -y calculix-ccx" in r.stderr
    assert "Traceback" not in r.stderr
