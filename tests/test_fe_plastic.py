"""The ``fe`` backend with elastic-plastic bodies and ``chained`` cycles (docs/fe.md,
"Plastic bodies and chained cycles"). Coarse meshes (h = a/2, bodies 15 a) and 16 ccx
increments per cycle (the default 32 is for robustness; this case converges with 16) so
that the ccx jobs stay short.

Case: EN24T cylinder R 4 mm on a flat, 200 kN/m (Hertz p0 = 2.1 x the 680 MPa yield),
mu 0.6, +-5 um (gross slip), bilinear hardening of seed table 5.1.
"""

from __future__ import annotations

import csv
import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import run_tribodem

from tribodem.contact import bilinear_hardening
from tribodem.contact.fe import jobs
from tribodem.contact.fe.deck import FEMaterial
from tribodem.materials.en24t import EN24T

needs_ccx = pytest.mark.skipif(shutil.which("ccx") is None,
                               reason="CalculiX (ccx) not installed")

CONFIG = """cycles = {cycles}
solver = "fe"
[contact]
geometry = "cylinder_on_flat"
radius = 4e-3
load_per_length = 2.0e5
amplitude = 5e-6
n_increments = 8
n = 64
[wear]
criterion = "{criterion}"
[fe]
material = "{material}"
mode = "{mode}"
chain_cycles = 1
plastic_increments = 16
h_over_a = 0.5
size_factor = 15
{cache}[output]
vtk = false
figures = false
"""


def _config(tmp: Path, name: str = "ep.toml", cycles: int = 2, criterion: str = "dfdi",
            material: str = "elastic-plastic", mode: str = "chained",
            cache: Path | None = None) -> Path:
    p = tmp / name
    line = "" if cache is None else f'cache = "{cache}"\n'
    p.write_text(CONFIG.format(cycles=cycles, criterion=criterion, material=material,
                               mode=mode, cache=line))
    return p


def _rows(path: Path) -> list[dict[str, str]]:
    with open(path) as fh:
        return list(csv.DictReader(fh))


def test_plastic_criteria_need_the_plastic_material_and_chained_cycles(tmp_path: Path) -> None:
    """DFDI with elastic fe bodies, or over 2 fresh cycles (virgin bodies every cycle: the
    first cycle's plastic strain again and again), is refused before any work (exit 2),
    naming the [fe] option that gives it."""
    r = run_tribodem("fretting", "run", "--config", str(_config(tmp_path, material="elastic")),
                     "--out", str(tmp_path / "a"), "--no-progress")
    assert r.returncode == 2, r.stderr
    assert "fe.material = 'elastic-plastic'" in r.stderr and "Traceback" not in r.stderr
    r = run_tribodem("fretting", "run", "--config", str(_config(tmp_path, mode="fresh")),
                     "--out", str(tmp_path / "b"), "--no-progress")
    assert r.returncode == 2, r.stderr
    assert "fe.mode = 'chained'" in r.stderr and "plastic_every_cycle" in r.stderr


@needs_ccx
def test_chained_plastic_cycles_accumulate_and_resume(tmp_path: Path) -> None:
    """Two chained cycles (chain_cycles = 1: the chain's job is used up after cycle 1 and
    run again with 2 cycles) through the installed command:

    * plasticity: every body yields (max PEEQ > 0) and the von Mises stress at the Gauss
      points never exceeds the flow stress of the hardening law at the largest PEEQ
      (Y + H p, H the bilinear plastic modulus), within 1 %, and reaches Y within 1 %;
    * the equivalent plastic strain and the DFDI of both bodies grow in cycle 2
      (the plastic state carries over: the chain is never restarted);
    * gross slip at +A and -A: |Q| / (mu P) between 0.6 and 1.02 (plastic cycles of this
      case measured 0.71-0.79 at h = a/4, docs/fe.md);
    * after each job's last cycle the pad is lifted off: both surfaces keep a residual
      dent and pile-up, each between 0 and 1 um (measured 0.16-0.23 um at h = a/4);
    * a run stopped after 1 cycle and resumed to 2 writes the uninterrupted run's ccx decks
      byte for byte (the chain's job is replayed: each of its jobs is served from the job
      cache the uninterrupted run filled, which keys them by the deck's bytes) and gives
      the same results.csv and criterion.csv.
    """
    cache = tmp_path / "ccx_cache"
    r = run_tribodem("fretting", "run", "--config", str(_config(tmp_path, cache=cache)),
                     "--out", str(tmp_path / "full"), "--no-progress")
    assert r.returncode == 0, r.stderr
    summary = json.loads((tmp_path / "full" / "summary.json").read_text())
    rep = summary["first_body_report"]
    assert rep["mode"] == "chained" and rep["chain_restarts"] == 0
    # which ccx ran is part of the result (two builds agree within tolerances, not bits)
    assert "SPOOLES" in rep["ccx"]["solvers"] and "Version" in rep["ccx"]["version"]
    assert [c["job_cycle"] for c in rep["cycles"]] == [1, 2]
    for c in rep["cycles"]:  # the attempt its job converged on (a softer contact wears less)
        assert jobs.attempt_settings(c["ccx_attempt"]) == (c["attempt_refine"],
                                                           c["contact_penalty_scale"]), c
    law = FEMaterial(yield_strength=EN24T.yield_strength)
    (y, _), (s1, p1) = law.plastic_table()
    h = (s1 - y) / p1
    # the law that ran, stated: table 5.1's line, on past the UTS (the default)
    assert rep["plastic_law"] == {"yield_strength_pa": y, "hardening_pa": h,
                                  "beyond_uts": "line", "plastic_table": [[y, 0.0], [s1, p1]]}
    assert h == pytest.approx(bilinear_hardening(EN24T.young, y, EN24T.uts, EN24T.uts_strain),
                              rel=1e-12)
    for c in rep["cycles"]:
        p_max = max(c["max_peeq_upper"], c["max_peeq_lower"])
        assert p_max > 0
        assert y * 0.99 <= c["max_von_mises_pa"] <= 1.01 * (y + h * p_max), c
        assert all(0.6 < q < 1.02 for q in c["q_over_mu_p_at_plus_minus_a"]), c
        # each job ends by lifting the pad off: a residual dent with pile-up beside it
        for body in ("upper", "lower"):
            assert 0 < c[f"pile_up_{body}_m"] < 1e-6 and 0 < c[f"dent_{body}_m"] < 1e-6, c
    for body in ("upper", "lower"):
        peeq = [c[f"max_peeq_{body}"] for c in rep["cycles"]]
        assert np.all(np.diff(peeq) > 0), (body, peeq)
    crit = _rows(tmp_path / "full" / "criterion.csv")
    for body in ("upper", "lower"):
        d = [float(row[f"max_dfdi_{body}"]) for row in crit]
        assert d[0] > 0 and np.all(np.diff(d) > 0), (body, d)

    part = tmp_path / "part"
    p_toml = _config(tmp_path, "p.toml", cycles=1, cache=cache)
    r = run_tribodem("fretting", "run", "--config", str(p_toml), "--out", str(part),
                     "--no-progress")
    assert r.returncode == 0, r.stderr
    r = run_tribodem("fretting", "run", "--config", str(p_toml), "--out", str(part),
                     "--resume", "--cycles", "2", "--no-progress")
    assert r.returncode == 0, r.stderr
    ran = [(j["cycle"], j["cached"]) for j in _rows(tmp_path / "full" / "fe" / "jobs.csv")]
    assert ran == [("1", "0"), ("2", "0")], ran
    served = [(j["cycle"], j["cached"]) for j in _rows(part / "fe" / "jobs.csv")]
    assert served == [("1", "1"), ("2", "1")], served
    for name in ("results.csv", "criterion.csv"):
        assert (part / name).read_text() == (tmp_path / "full" / name).read_text(), name
