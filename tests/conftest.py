"""Shared fixtures: small builders for DEM test scenes."""

from __future__ import annotations

import numpy as np
import pytest

from tribodem.dem import Box, Material, ParticleState, Simulation

STEEL = dict(young=2.1e11, poisson=0.3, density=7850.0)

#: Worker-seconds of the longest test files, measured with CI's ccx (Debian's, SPOOLES) on a
#: 2-core VM, numba's cache warm; only their order matters.
#: ``pytest -n auto --dist loadfile`` hands whole files to the workers, by default those with
#: the most tests first, which put the three-test 4-min fe3d file last and left one worker
#: alone with it for the last minutes. Longest first (files not listed after them, in
#: collection order) gives a short makespan (Graham's LPT rule).
FILE_SECONDS = {
    "test_fe_backend3d_runs.py": 147, "test_fe_backend3d.py": 118, "test_cli_errors.py": 89,
    "test_braking.py": 67, "test_fe.py": 65, "test_outputs.py": 60, "test_faults.py": 55,
    "test_fe_backend.py": 45,
    "test_fretting_resume.py": 43, "test_fretting_geometry.py": 38,
    "test_braking_dask.py": 36, "test_braking_resume.py": 33, "test_cli_resume.py": 28,
    "test_fretting_line.py": 25, "test_fretting_jump.py": 25, "test_fretting_sweep.py": 24,
    "test_fe_plastic.py": 24, "test_materials.py": 22, "test_config_properties.py": 20,
    "test_fe_crossed.py": 18, "test_contact_halfspace.py": 17, "test_cyclejump.py": 17,
    "test_fretting_debris_study.py": 17, "test_library_braking.py": 16,
    "test_fretting_study.py": 15, "test_cli.py": 15, "test_library_fretting.py": 15,
    "test_fretting_sampling.py": 15, "test_fretting.py": 13,
}


def pytest_configure(config: pytest.Config) -> None:
    """Keep the collection's file order for pytest-xdist (``--no-loadscope-reorder``)."""
    if hasattr(config.option, "loadscopereorder"):
        config.option.loadscopereorder = False


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """The longest files first (:data:`FILE_SECONDS`); a stable sort keeps each file's tests
    together and in their order."""
    items.sort(key=lambda item: -FILE_SECONDS.get(item.path.name, 0))


def two_spheres(v0: float, cor: float, r: float = 0.005, friction: float = 0.0) -> Simulation:
    """Two equal steel spheres approaching head-on along x at relative speed v0."""
    mat = Material(name="steel", cor=cor, friction=friction, **STEEL)
    p = ParticleState(dim=3, pos=[[0, 0, 0], [2 * r + 1e-9, 0, 0]], radius=r,
                      density=STEEL["density"], vel=[[v0 / 2, 0, 0], [-v0 / 2, 0, 0]])
    return Simulation(p, [mat], Box([-1, -1, -1], [1, 1, 1]))


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(1234)


def tribodem_exe() -> str:
    """The installed ``tribodem`` console script (beside this interpreter, else on PATH)."""
    import shutil
    import sys
    from pathlib import Path

    exe = Path(sys.executable).with_name("tribodem")
    if exe.is_file():
        return str(exe)
    found = shutil.which("tribodem")
    if found is None:
        pytest.fail("the tribodem command is not installed (pip install -e .)")
    return found


def run_tribodem(*args: str, timeout: float = 600, **kw):  # noqa: ANN201
    """Run the installed ``tribodem`` command as a real subprocess (text output captured)."""
    import subprocess

    return subprocess.run([tribodem_exe(), *args], capture_output=True, text=True,
                          timeout=timeout, **kw)


#: summary.json entries that are wall-clock times (never bitwise between two runs)
TIMING = {"wall_time_s", "wall_time_total_s"}


def without_timings(d: object) -> object:
    """A JSON tree (summary.json) without its wall-clock timings (:data:`TIMING`)."""
    if isinstance(d, dict):
        return {k: without_timings(v) for k, v in d.items() if k not in TIMING}
    if isinstance(d, list):
        return [without_timings(v) for v in d]
    return d


def default_sigint() -> None:
    """``preexec_fn`` for a child that must take Ctrl-C: a shell without job control starts
    background commands with SIGINT ignored, and Python keeps an inherited SIG_IGN."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_DFL)


#: The tiny braking cell of the braking CLI tests (same as ``test_braking.SMALL``): a TOML
#: [geometry] table, 100 x 36 + 36 um, 4 um roughness in 2 modes, packing seed 3.
TINY_CELL = """[geometry]
width_m = 100e-6
disc_height_m = 36e-6
pad_height_m = 36e-6
roughness_amplitude_m = 4e-6
roughness_modes = 2
seed = 3
"""
#: the [run] line the tests on ``TINY_CELL`` add: its bodies are ~3 grains thick outside
#: their anchored layers and one impact can take one, so the worn-through guard (which
#: would stop the run, exit 3) is off in these mechanics tests; test_braking tests it
TINY_RUN = "worn_through_diameters = 0.0\n"


def before_config_v2(cfg) -> dict:  # noqa: ANN001 - a FrettingConfig
    """``cfg`` as tribodem recorded it before config_version 2: every field of then, [fe]
    h_over_a and size_factor at the then defaults 0.25 / 40.0, no marker (and none of the
    fields added since: [plastic] beyond_uts, [fe] loading_friction)."""
    old = cfg.model_dump(mode="json")
    del old["config_version"], old["plastic"]["beyond_uts"], old["fe"]["loading_friction"]
    old["fe"] |= {"h_over_a": 0.25, "size_factor": 40.0}
    return old
