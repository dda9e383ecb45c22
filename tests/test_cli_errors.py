"""Every command refuses bad input the same way, through the installed ``tribodem`` command.

Each row: the arguments (``{tmp}`` is a fresh folder, ``{file}`` an existing plain file,
``{cfg:NAME}`` a TOML file from ``CONFIGS``), the exit code, and the words the message must
contain (the field or option named). Every refusal: exit 2, no traceback, and no output
folder made for a new ``--out``.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import run_tribodem

CONFIGS = {
    "dem_neg": "[case]\nparticles = -5\n",
    "dem_kind": "[case]\nkind = 'brake'\n",
    "dem_typo": "[run]\nstepz = 3\n",
    "dem_threads": "[run]\nthreads = 999\n",
    "dem_every": "[output]\nscalars_every = 0\n",
    "bad_toml": "[case\nparticles = 3\n",
    "fr_load": "[contact]\nload = -1.0\n",
    "fr_n": "[contact]\nn = 63\n",
    "fr_inc": "[contact]\nn_increments = 10\n",
    "fr_window": "[contact]\nwindow = 1e-5\n",
    "fr_jump": "[jump]\nstrategy = 'constant'\n[jump.params]\nbogus = 3\n",
    "fr_nu": "[contact]\npoisson = 0.7\n",
    "fr_unknown": "[wear]\ncriterium = 'energy'\n",
    "fr_slope": "solver = 'fe3d'\n[fe]\nmax_wear_slope = 0.0\n",
    "fr_cycinc_2d": ("solver = 'fe'\n[contact]\ngeometry = 'cylinder_on_flat'\n"
                     "load_per_length = 1e5\n[fe]\ncycle_increments = 64\n"),
    "fr_cycinc": "solver = 'fe3d'\n[fe]\ncycle_increments = 2\n",
    "fr_retry_from": "solver = 'fe3d'\n[fe]\nretry_from = 'middle'\n",
    "fr_retries": "solver = 'fe3d'\n[fe]\nretries = 7\n",
    "fr_hold": "solver = 'elastic-plastic'\n[plastic]\nbeyond_uts = 'hold'\n",
    "fr_past_uts": "[plastic]\nbeyond_uts = 'cap'\n",
    "fr_loading_mu": "solver = 'fe3d'\n[fe]\nloading_friction = 'half'\n",
    "fr_slope_2d": ("solver = 'fe'\n[contact]\ngeometry = 'cylinder_on_flat'\n"
                    "load_per_length = 1e5\nwindow = 1e-3\n[fe]\nmax_wear_slope = 0.2\n"),
    "br_index": "[condition]\nindex = 9\n",
    "br_duration": "[condition]\nindex = 5\n[run]\nduration_s = -1.0\n",
    "br_width": "[condition]\nindex = 5\n[geometry]\nwidth_m = 0.0\n",
    "br_typo": "[condition]\nindex = 5\n[run]\nbogus = 1\n",
    "br_both": "[condition]\nload_kN = 13.0\npressure_Pa = 1e6\nrpm = 800.0\n",
    "br_curve": "[condition]\nindex = 5\n[thermal]\ncurve = 'no_such_curve.csv'\n",
    "br_threads": "[condition]\nindex = 5\n[run]\nthreads = 200\n",
}

NEW = "{tmp}/new"  # an output folder that must not be created by a refused command

CASES: list[tuple[str, list[str], list[str]]] = [
    # typer/click usage errors: typer's short message, exit 2
    ("bare", [], ["Usage"]),
    ("unknown-command", ["nosuch"], ["No such command"]),
    ("dem-missing-out", ["dem", "run"], ["--out"]),
    ("dem-unknown-option", ["dem", "run", "--out", NEW, "--bogus"], ["--bogus"]),
    ("fretting-cycles-abc", ["fretting", "run", "--out", NEW, "--cycles", "abc"], ["--cycles"]),
    ("braking-condition-float", ["braking", "run", "--out", NEW, "--condition", "1.5"],
     ["--condition"]),
    ("bench-particles-neg", ["bench", "dem", "--particles", "-1"], ["--particles"]),
    ("bench-particles-1e9", ["bench", "dem", "--particles", "1000000000"], ["--particles"]),
    ("bench-steps-0", ["bench", "dem", "--steps", "0"], ["--steps"]),
    ("sweep-workers-neg", ["braking", "sweep", "--out", NEW, "--workers", "-1"], ["--workers"]),
    ("sweep-packings-0", ["braking", "sweep", "--out", NEW, "--packings", "0"], ["--packings"]),
    ("sweep-seeds-0", ["braking", "sweep", "--out", NEW, "--seeds", "0"], ["--seeds"]),
    ("calibrate-seed-neg", ["calibrate", "--material", "q345b", "--out", NEW, "--seed", "-1"],
     ["--seed"]),
    # tribodem's validation: field, value, what is allowed
    ("bench-threads-999", ["bench", "dem", "--threads", "999"], ["--threads", "999"]),
    ("bench-threads-neg", ["bench", "dem", "--threads", "-3"], ["--threads", "-3"]),
    ("bench-threads-0", ["bench", "dem", "--threads", "0"], ["--threads", "allowed"]),
    ("bench-memory", ["bench", "dem", "--particles", "90000000"], ["--particles", "GiB"]),
    ("bench-case", ["bench", "dem", "--case", "foo"], ["--case", "settle3d"]),
    ("dem-particles-neg", ["dem", "run", "--config", "{cfg:dem_neg}", "--out", NEW],
     ["case.particles", "-5"]),
    ("dem-kind", ["dem", "run", "--config", "{cfg:dem_kind}", "--out", NEW],
     ["case.kind", "settle3d"]),
    ("dem-typo", ["dem", "run", "--config", "{cfg:dem_typo}", "--out", NEW], ["run.stepz"]),
    ("dem-threads", ["dem", "run", "--config", "{cfg:dem_threads}", "--out", NEW],
     ["run.threads", "999"]),
    ("dem-every-0", ["dem", "run", "--config", "{cfg:dem_every}", "--out", NEW],
     ["output.scalars_every"]),
    ("dem-bad-toml", ["dem", "run", "--config", "{cfg:bad_toml}", "--out", NEW],
     ["--config", "TOML"]),
    ("dem-config-missing", ["dem", "run", "--config", "{tmp}/none.toml", "--out", NEW],
     ["--config", "does not exist"]),
    ("dem-config-folder", ["dem", "run", "--config", "{tmp}", "--out", NEW],
     ["--config", "folder"]),
    ("dem-out-file", ["dem", "run", "--quick", "--out", "{file}"], ["--out", "file"]),
    ("dem-out-under-file", ["dem", "run", "--quick", "--out", "{file}/sub"], ["--out"]),
    ("dem-resume-empty", ["dem", "run", "--quick", "--out", "{tmp}", "--resume"],
     ["--out", "checkpoint"]),
    ("jump-strategy", ["jump", "replay", "--strategy", "foo", "--input", "{file}"],
     ["--strategy", "adaptive"]),
    ("jump-input-missing", ["jump", "replay", "--strategy", "adaptive", "--input",
                            "{tmp}/none.csv"], ["--input", "does not exist"]),
    ("jump-input-folder", ["jump", "replay", "--strategy", "adaptive", "--input", "{tmp}"],
     ["--input", "folder"]),
    ("jump-param-form", ["jump", "replay", "--strategy", "constant", "--input", "{file}",
                         "--param", "jump_length"], ["--param", "key=value"]),
    ("jump-param-unknown", ["jump", "replay", "--strategy", "constant", "--input", "{file}",
                            "--param", "bogus=1"], ["bogus", "jump_length"]),
    ("jump-plot-folder", ["jump", "replay", "--strategy", "adaptive", "--input", "{file}",
                          "--plot", "{tmp}"], ["--plot", "folder"]),
    ("calibrate-material", ["calibrate", "--material", "steel", "--out", NEW],
     ["--material", "q345b"]),
    ("calibrate-out-file", ["calibrate", "--material", "q345b", "--quick", "--out", "{file}"],
     ["--out"]),
    ("fretting-criterion", ["fretting", "run", "--out", NEW, "--criterion", "foo"],
     ["criterion", "energy"]),
    ("fretting-jump", ["fretting", "run", "--out", NEW, "--jump", "foo"], ["jump", "adaptive"]),
    ("fretting-solver", ["fretting", "run", "--out", NEW, "--solver", "foo"],
     ["solver", "elastic"]),
    ("fretting-cycles-0", ["fretting", "run", "--out", NEW, "--cycles", "0"], ["cycles", "0"]),
    ("fretting-debris-0", ["fretting", "run", "--out", NEW, "--debris-every", "0"],
     ["debris.every"]),
    ("fretting-debris-both", ["fretting", "run", "--out", NEW, "--debris-every", "2",
                              "--no-debris"], ["--debris-every", "--no-debris"]),
    ("fretting-dfdi-elastic", ["fretting", "run", "--out", NEW, "--criterion", "dfdi",
                               "--solver", "elastic"], ["dfdi", "elastic"]),
    ("fretting-load", ["fretting", "run", "--config", "{cfg:fr_load}", "--out", NEW],
     ["contact.load", "-1"]),
    ("fretting-n-odd", ["fretting", "run", "--config", "{cfg:fr_n}", "--out", NEW],
     ["contact.n", "63"]),
    ("fretting-increments", ["fretting", "run", "--config", "{cfg:fr_inc}", "--out", NEW],
     ["contact.n_increments", "10"]),
    ("fretting-window", ["fretting", "run", "--config", "{cfg:fr_window}", "--out", NEW],
     ["contact.window", "1e-05"]),
    ("fretting-jump-param", ["fretting", "run", "--config", "{cfg:fr_jump}", "--out", NEW],
     ["bogus", "jump_length"]),
    ("fretting-poisson", ["fretting", "run", "--config", "{cfg:fr_nu}", "--out", NEW],
     ["contact.poisson", "0.7"]),
    ("fretting-typo", ["fretting", "run", "--config", "{cfg:fr_unknown}", "--out", NEW],
     ["wear.criterium"]),
    ("fretting-slope-0", ["fretting", "run", "--config", "{cfg:fr_slope}", "--out", NEW],
     ["fe.max_wear_slope", "0.0", "a number > 0", "'off'"]),
    ("fretting-slope-fe2d", ["fretting", "run", "--config", "{cfg:fr_slope_2d}", "--out",
                             NEW], ["fe.max_wear_slope", "0.2", "'fe3d' has it"]),
    ("fretting-cycle-increments-fe2d", ["fretting", "run", "--config", "{cfg:fr_cycinc_2d}",
                                        "--out", NEW], ["fe.cycle_increments", "64",
                                                        "'fe3d' has it"]),
    ("fretting-cycle-increments-2", ["fretting", "run", "--config", "{cfg:fr_cycinc}", "--out",
                                     NEW], ["fe.cycle_increments", "2", "ge 4"]),
    ("fretting-retry-from", ["fretting", "run", "--config", "{cfg:fr_retry_from}", "--out",
                             NEW], ["fe.retry_from", "middle", "'first'", "'last'"]),
    ("fretting-retries-7", ["fretting", "run", "--config", "{cfg:fr_retries}", "--out", NEW],
     ["fe.retries", "7", "6"]),
    ("fretting-hold-tamaas", ["fretting", "run", "--config", "{cfg:fr_hold}", "--out", NEW],
     ["plastic.beyond_uts", "'hold'", "elastic-plastic", "'line'", "'fe3d'"]),
    ("fretting-beyond-uts", ["fretting", "run", "--config", "{cfg:fr_past_uts}", "--out", NEW],
     ["plastic.beyond_uts", "cap", "line", "hold"]),
    ("fretting-loading-friction", ["fretting", "run", "--config", "{cfg:fr_loading_mu}",
                                   "--out", NEW], ["fe.loading_friction", "half", "low", "full"]),
    ("fretting-out-file", ["fretting", "run", "--quick", "--out", "{file}"], ["--out"]),
    ("fretting-resume-empty", ["fretting", "run", "--quick", "--out", "{tmp}", "--resume"],
     ["--out"]),
    ("study-counts-abc", ["fretting", "debris-study", "--out", NEW, "--counts", "abc"],
     ["--counts", "abc"]),
    ("study-counts-0", ["fretting", "debris-study", "--out", NEW, "--counts", "0,5"],
     ["--counts", "0,5"]),
    ("study-counts-memory", ["fretting", "debris-study", "--out", NEW, "--counts", "10000000"],
     ["--counts", "10000000", "GiB"]),
    ("study-cycle-0", ["fretting", "debris-study", "--out", NEW, "--cycle", "0"],
     ["cycles", "0"]),
    ("study-threads", ["fretting", "debris-study", "--out", NEW, "--threads", "99"],
     ["--threads", "99"]),
    ("study-resume-empty", ["fretting", "debris-study", "--out", "{tmp}", "--resume"],
     ["--out", "study.toml"]),
    ("braking-condition-7", ["braking", "run", "--out", NEW, "--condition", "7"],
     ["--condition", "7"]),
    ("braking-nothing", ["braking", "run", "--out", NEW], ["--condition", "--config"]),
    ("braking-index", ["braking", "run", "--config", "{cfg:br_index}", "--out", NEW],
     ["condition.index", "9"]),
    ("braking-duration", ["braking", "run", "--config", "{cfg:br_duration}", "--out", NEW],
     ["run.duration_s", "-1"]),
    ("braking-width", ["braking", "run", "--config", "{cfg:br_width}", "--out", NEW],
     ["geometry.width_m", "0"]),
    ("braking-typo", ["braking", "run", "--config", "{cfg:br_typo}", "--out", NEW],
     ["run.bogus"]),
    ("braking-both-loads", ["braking", "run", "--config", "{cfg:br_both}", "--out", NEW],
     ["load_kN", "pressure_Pa"]),
    ("braking-curve", ["braking", "run", "--config", "{cfg:br_curve}", "--out", NEW],
     ["thermal.curve", "no_such_curve.csv"]),
    ("braking-threads", ["braking", "run", "--config", "{cfg:br_threads}", "--out", NEW],
     ["run.threads", "200"]),
    ("braking-out-file", ["braking", "run", "--condition", "5", "--quick", "--out", "{file}"],
     ["--out"]),
    ("braking-resume-empty", ["braking", "run", "--condition", "5", "--quick", "--out",
                              "{tmp}", "--resume"], ["--out"]),
    ("sweep-out-file", ["braking", "sweep", "--quick", "--out", "{file}"], ["--out"]),
]


def _expand(args: list[str], tmp: Path) -> list[str]:
    plain = tmp / "plain.txt"
    plain.write_text("cycle,increment\n1,1.0\n2,1.0\n")
    out = []
    for a in args:
        if a.startswith("{cfg:"):
            name = a[5:-1]
            p = tmp / f"{name}.toml"
            p.write_text(CONFIGS[name])
            out.append(str(p))
        else:
            out.append(a.replace("{tmp}", str(tmp)).replace("{file}", str(plain)))
    return out


def test_table_has_at_least_40_cases() -> None:
    assert len(CASES) >= 40 and len({c[0] for c in CASES}) == len(CASES)


@pytest.mark.parametrize(("name", "args", "words"), CASES, ids=[c[0] for c in CASES])
def test_bad_input_exits_2_naming_the_field(tmp_path: Path, name: str, args: list[str],
                                            words: list[str]) -> None:
    r = run_tribodem(*_expand(args, tmp_path), timeout=120)
    text = r.stdout + r.stderr
    assert r.returncode == 2, f"{name}: exit {r.returncode}\n{text}"
    assert "Traceback" not in text, text
    for w in words:
        assert w in text, f"{name}: {w!r} not in the message:\n{text}"
    assert not (tmp_path / "new").exists(), f"{name}: the refused run made its output folder"


def test_the_commands_modules_leave_scipys_heavy_subpackages_unimported() -> None:
    """A refusal (or ``--help``) costs the command's imports: every command's module loads
    without scipy's signal, optimize, interpolate, spatial, sparse or stats (0.2-0.6 s each
    to import; the functions that use them import them: 1.4 -> 0.6 s for a refused
    ``fretting run``), checked in a fresh interpreter."""
    import subprocess
    import sys

    heavy = ("signal", "optimize", "interpolate", "spatial", "sparse", "stats")
    code = ("import sys, tribodem.cli as c; c._register(); "
            f"print(' '.join(m for m in {heavy!r} if 'scipy.' + m in sys.modules))")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == [], r.stdout
