"""``tribodem fretting debris-study``: Lu (2018) section 5.4 (figures 5.22-5.27) as one call,
:func:`debris_study`.

The study: run the fretting case (default: the energy case, crossed 8 mm cylinders, 100 N)
without debris to cycle ``cycle`` (160 in the seed), then, on that worn geometry at the
loading position (offset 0), load ``N`` debris particles (the seed's counts 22k, 81k, 102k;
its 0.6 um particles and three shapes in equal shares) between the first bodies and compare
the contact force distribution on the lower body with and without them.

Reading of the seed (stated in ``debris_study.json``): the particle counts are *imposed*
(the seed's counts came from its own generation, ejection and 0.77 correction; ours would be
~330k by cycle 160, docs/debris.md), placed at random inside the worn volume of both bodies
within the solver window (probability proportional to the local worn depth, as eq 3.10's
sites), then loaded by the DE phase of :func:`tribodem.fretting.debris.run_de_phase` to the
load the first bodies carried at their sites (eqs 3.11-3.15). "Contact force on the lower
first body" is read as the total (solid-solid + debris) pressure times the cell area; the
solid-solid part is reported beside it.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numba
import numpy as np
from numpy.typing import NDArray

from tribodem.dem.clumps import debris_template
from tribodem.dem.state import BYTES_PER_PARTICLE
from tribodem.fretting.case import build_loop, debris_settings, preflight
from tribodem.fretting.config import RESUME_MAY_CHANGE, FrettingConfig, resolve_config
from tribodem.fretting.debris import (
    SHAPES,
    DebrisField,
    DebrisSettings,
    debris_target,
    run_de_phase,
)
from tribodem.fretting.loop import FrettingLoop
from tribodem.fretting.output import CHECKPOINT, read_checkpoint, write_checkpoint
from tribodem.fretting.record import read_study, study_diffs
from tribodem.fretting.runner import Echo, run
from tribodem.io import runs
from tribodem.io.config import ConfigError, dump_toml, parse_int_list
from tribodem.io.record import ConfigSource, RunResult, as_out, may_change_text
from tribodem.io.results import write_csv, write_figure, write_json, write_npz, write_text

#: The seed's numbers (section 5.4, figures 5.24-5.27; text below figure 5.29).
SEED_CYCLE = 160
SEED_COUNTS: tuple[int, ...] = (22_000, 81_000, 102_000)
SEED_PEAK_CHANGE = {81_000: -0.12}  #: "reduction in the peak contact force ... of the
#: order of 12% for 81k particles"
SEED_TREND = ("the force at the centre of the contact zone increases and the force at its "
              "edge decreases as the particle count increases; without debris the peak "
              "forces are at the two edges of the contact zone, lower at its centre")

#: ``--quick``: the seed's counts / 20 on the quick preset (64^2, 10 cycles).
QUICK_STUDY_COUNTS: tuple[int, ...] = (1100, 4050, 5100)

#: Fraction of the (no-debris) contact area nearest to / farthest from the contact centre
#: that defines the "centre" and the "edge" of the contact zone.
ZONE_FRACTION = 0.25


@dataclass(frozen=True)
class Zones:
    """Centre and edge of the no-debris contact at the loading position (window masks)."""

    contact: NDArray[np.bool_]
    centre: NDArray[np.bool_]
    edge: NDArray[np.bool_]
    radius_m: float  #: area-equivalent contact radius sqrt(A / pi), m


def contact_zones(pressure: NDArray[np.float64], coords: NDArray[np.float64],
                  fraction: float = ZONE_FRACTION) -> Zones:
    """The quarter of the contact area nearest to its pressure centroid ("centre") and the
    quarter farthest from it ("edge")."""
    contact = pressure > 0.0
    if not contact.any():
        raise ValueError("no contact in the pressure field")
    xw, yw = np.meshgrid(coords, coords, indexing="ij")
    w = pressure[contact]
    xc, yc = float((xw[contact] * w).sum() / w.sum()), float((yw[contact] * w).sum() / w.sum())
    r = np.hypot(xw - xc, yw - yc)
    rc = r[contact]
    lo, hi = np.quantile(rc, fraction), np.quantile(rc, 1.0 - fraction)
    dx = float(coords[1] - coords[0])
    return Zones(contact=contact, centre=contact & (r <= lo), edge=contact & (r >= hi),
                 radius_m=math.sqrt(contact.sum() * dx * dx / math.pi))


def distribution_metrics(pressure: NDArray[np.float64], zones: Zones, dx: float
                         ) -> dict[str, float]:
    """Peak, centre and edge of one contact force distribution on the lower body (SI)."""
    cell = dx * dx
    centre = float(pressure[zones.centre].mean())
    edge = float(pressure[zones.edge].mean())
    return {"peak_pressure_Pa": float(pressure.max()),
            "peak_force_per_cell_N": float(pressure.max()) * cell,
            "centre_mean_pressure_Pa": centre, "edge_mean_pressure_Pa": edge,
            "centre_to_edge": centre / edge if edge > 0 else math.inf,
            "total_force_N": float(pressure.sum()) * cell}


def band_profile(field: NDArray[np.float64], axis: int, rows: int = 2) -> NDArray[np.float64]:
    """Mean of ``field`` over the ``2 rows + 1`` grid lines through the window centre, as a
    profile along ``axis`` (0: x, the stroke; 1: y)."""
    n = field.shape[0]
    mid = n // 2
    band = slice(mid - rows, mid + rows + 1)
    return field[:, band].mean(axis=1) if axis == 0 else field[band, :].mean(axis=0)


def worn_sites(loop: FrettingLoop) -> list[tuple[NDArray[np.float64], NDArray[np.float64],
                                                 NDArray[np.float64]]]:
    """Worn depth of both bodies inside the solver window at offset 0 (window frame, m):
    (depth [nx, ny], x [nx], y [ny]) per body."""
    g = loop.grid
    c = loop.solver.coords
    tol = 1e-9 * g.dx
    inside = (g.x_lower >= c[0] - tol) & (g.x_lower <= c[-1] + tol)
    return [(np.asarray(loop.wear_upper), g.x_upper, g.y),
            (np.asarray(loop.wear_lower)[inside], g.x_lower[inside], g.y)]


def place_debris(settings: DebrisSettings, count: int, sites: list[tuple[NDArray[np.float64],
                 NDArray[np.float64], NDArray[np.float64]]], cell_area: float,
                 cycle: int) -> DebrisField:
    """``count`` particles at random points of the worn volume (probability ~ worn depth),
    through eq 3.10 on the worn depth scaled to hold exactly ``count`` particles."""
    vol = sum(float(np.maximum(d, 0.0).sum()) for d, _, _ in sites) * cell_area
    if vol <= 0.0:
        raise ValueError("no worn volume in the window: run more cycles before the study")
    field = DebrisField(settings)
    # eq 3.10: N = correction x V / (pi d^3 / 6); aim half a particle above count, so the
    # floor of eq 3.10 is count whatever the rounding
    want = (count + 0.5) * settings.particle_volume / settings.volume_correction
    scale = want / vol
    field.generate(cycle, [(d * scale, x, y) for d, x, y in sites], cell_area)
    if field.n != count:
        raise RuntimeError(f"placed {field.n} debris particles, asked for {count}")
    return field


def run_count(loop: FrettingLoop, settings: DebrisSettings, count: int,
              p_without: NDArray[np.float64], gap: NDArray[np.float64],
              zones: Zones) -> tuple[dict[str, Any], dict[str, NDArray[np.float64]]]:
    """One DE phase with ``count`` particles on the worn geometry: (row, arrays)."""
    sol = loop.solver
    c = sol.coords
    dx = sol.dx
    xw, yw = np.meshgrid(c, c, indexing="ij")
    lower = np.asarray(sol.lower(xw, yw), dtype=float)
    field = place_debris(settings, count, worn_sites(loop), loop.grid.cell_area,
                         loop.cycles_done)
    target = debris_target(field, p_without, c, dx, sol.load)
    res = run_de_phase(field, lower, gap, c, target, cycle=loop.cycles_done)
    try:
        sol.set_debris_pressure(res.pressure)
        total = sol.loaded_solution(0.0, debris=True)[0]
        debris_p = np.asarray(sol.debris_pressure, dtype=float).copy()
        debris_load = float(sol.debris_load)
    finally:
        sol.set_debris_pressure(None)
    solid = total - debris_p
    m_total = distribution_metrics(total, zones, dx)
    m_solid = distribution_metrics(solid, zones, dx)
    row: dict[str, Any] = {
        "particles": count, "particles_in_window": res.particles,
        "active_particles": res.active_particles, "spheres": res.members,
        "loaded_particles": res.loaded_particles, "target_N": res.target_N,
        "debris_load_fraction": debris_load / sol.load,
        "servo_rel_error": res.rel_error, "converged": res.converged, "de_steps": res.steps,
        "de_wall_time_s": res.wall_time_s,
        **{f"total_{k}": v for k, v in m_total.items()},
        **{f"solid_{k}": v for k, v in m_solid.items()},
        "load_balance_error": abs(m_total["total_force_N"] - sol.load) / sol.load,
    }
    arrays = {"total_pressure": total, "debris_pressure": debris_p, "solid_pressure": solid,
              "positions": res.positions, "particle_force": res.particle_force,
              "shape": field.shape}
    return row, arrays


def compare(rows: list[dict[str, Any]], none: dict[str, Any]) -> list[dict[str, Any]]:
    """Each row's changes against the no-debris distribution (fractions)."""
    out = []
    for r in rows:
        ch = dict(r)
        for part in ("total", "solid"):
            for k in ("peak_pressure_Pa", "centre_mean_pressure_Pa", "edge_mean_pressure_Pa"):
                ch[f"{part}_{k.replace('_Pa', '')}_change"] = r[f"{part}_{k}"] / none[k] - 1.0
        ch["seed_peak_change"] = SEED_PEAK_CHANGE.get(int(r["particles"]))
        out.append(ch)
    return out


TABLE_COLUMNS = (
    "particles", "active_particles", "debris_load_fraction", "total_peak_pressure_Pa",
    "total_peak_pressure_change", "solid_peak_pressure_Pa", "solid_peak_pressure_change",
    "total_centre_mean_pressure_change", "total_edge_mean_pressure_change",
    "total_centre_to_edge", "seed_peak_change", "servo_rel_error", "de_wall_time_s")


def write_table(out: Path, none: dict[str, Any], rows: list[dict[str, Any]]) -> Path:
    """``debris_study.csv``: one row without debris (its own reference: changes 0), then
    one per count (rows of :func:`compare`)."""
    bare = {"particles": 0, "active_particles": 0, "debris_load_fraction": 0.0,
            "servo_rel_error": 0.0, "de_wall_time_s": 0.0,
            **{f"{part}_{k}": v for part in ("total", "solid") for k, v in none.items()}}
    return write_csv(out / "debris_study.csv", TABLE_COLUMNS,
                     ([("" if r[k] is None else r[k]) for k in TABLE_COLUMNS]
                      for r in compare([bare], none) + rows))


def write_plots(out: Path, coords: NDArray[np.float64], p_without: NDArray[np.float64],
                per_count: list[tuple[int, dict[str, NDArray[np.float64]]]],
                cycle: int) -> list[Path]:
    """``debris_study_profiles.png`` (figs 5.24-5.25: the force distribution on the lower
    body along the stroke and across it, without and with each count) and
    ``debris_study_particles.png`` (figs 5.26-5.27: the force on each particle)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    um = coords * 1e6
    dx = float(coords[1] - coords[0])
    cell = dx * dx * 1e3  # N -> mN per cell
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharey=True)
    for ax, axis, name in ((axes[0], 0, "x (stroke)"), (axes[1], 1, "y (across the stroke)")):
        ax.plot(um, band_profile(p_without, axis) * cell, "k-", lw=2, label="no debris")
        for k, (count, arr) in enumerate(per_count):
            col = f"C{k}"
            ax.plot(um, band_profile(arr["total_pressure"], axis) * cell, "-", color=col,
                    label=f"{count // 1000}k particles: total")
            ax.plot(um, band_profile(arr["solid_pressure"], axis) * cell, ":", color=col,
                    label=f"{count // 1000}k: solid-solid only")
        reach = np.flatnonzero(band_profile(p_without, axis) > 0)
        if reach.size:  # the contact and as much again on each side
            lo_, hi_ = um[reach[0]], um[reach[-1]]
            pad = 0.5 * (hi_ - lo_) + 2 * dx * 1e6
            ax.set_xlim(lo_ - pad, hi_ + pad)
        ax.set_xlabel(f"{name}, um")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel(f"contact force on the lower body per {dx * 1e6:.2f} um cell, mN")
    axes[0].legend(fontsize=7)
    fig.suptitle(f"Cycle {cycle}: contact force on the lower first body (band of 5 grid "
                 "lines through the centre)")
    paths = [write_figure(out / "debris_study_profiles.png", fig)]
    if per_count:
        fig, axes = plt.subplots(1, len(per_count), figsize=(4.2 * len(per_count), 4),
                                 squeeze=False)
        for ax, (count, arr) in zip(axes[0], per_count, strict=True):
            f = -arr["particle_force"][:, 2] * 1e3
            pos = arr["positions"] * 1e6
            order = np.argsort(f)
            sc = ax.scatter(pos[order, 0], pos[order, 1], c=f[order], s=1, cmap="viridis",
                            vmin=0.0)
            ax.set_aspect("equal")
            ax.set_title(f"{count:,} particles")
            ax.set_xlabel("x, um")
            fig.colorbar(sc, ax=ax, label="force on the lower body, mN")
        axes[0][0].set_ylabel("y, um")
        fig.suptitle(f"Cycle {cycle}: force of each debris particle on the lower body")
        paths.append(write_figure(out / "debris_study_particles.png", fig))
    return paths


def profiles_csv(out: Path, coords: NDArray[np.float64], p_without: NDArray[np.float64],
                 per_count: list[tuple[int, dict[str, NDArray[np.float64]]]]) -> Path:
    """``debris_study_profiles.csv``: the plotted pressure profiles along x and y (Pa)."""
    cols = ["coord_m", "x_no_debris_Pa", "y_no_debris_Pa"]
    data = [coords, band_profile(p_without, 0), band_profile(p_without, 1)]
    for count, arr in per_count:
        for part in ("total", "solid"):
            for axis, ax in ((0, "x"), (1, "y")):
                cols.append(f"{ax}_{count}_{part}_Pa")
                data.append(band_profile(arr[f"{part}_pressure"], axis))
    return write_csv(out / "debris_study_profiles.csv", cols, zip(*data, strict=True))


def save_count(out: Path, count: int, row: dict[str, Any],
               arrays: dict[str, NDArray[np.float64]], solver_state: dict[str, Any]) -> None:
    """One count's result, atomically: its arrays, then the first-body solver's state after
    it (the warm starts the next count's solves begin from: a resumed study restores it,
    so its next count is bitwise the uninterrupted study's), then the row that marks it
    done."""
    write_npz(out / f"count_{count:06d}.npz", **arrays)
    write_checkpoint(out / f"count_{count:06d}_state.npz", {"count": int(count)},
                     solver_state)
    write_json(out / f"count_{count:06d}.json", row)


def load_count(out: Path, count: int
               ) -> tuple[dict[str, Any], dict[str, NDArray], dict[str, Any]] | None:
    """A count finished by an earlier run of the study: (row, arrays, the solver's state
    after it), or None (also for a count of an older study without the solver's state: it
    is run again, so the counts after it start from the same state as uninterrupted)."""
    js, npz = out / f"count_{count:06d}.json", out / f"count_{count:06d}.npz"
    st = out / f"count_{count:06d}_state.npz"
    if not (js.is_file() and npz.is_file() and st.is_file()):
        return None
    try:
        state = read_checkpoint(st)[1]
    except ConfigError:  # cut short or foreign: the count is run again
        return None
    with np.load(npz) as f:
        arrays = {k: f[k] for k in f.files}
    return json.loads(js.read_text()), arrays, state


def assumptions(cycle: int) -> dict[str, str]:
    """Which reading of Lu (2018) section 5.4 ran (also in docs/debris.md)."""
    return {
        "cycle": f"the debris is loaded on the geometry worn by {cycle} cycles without debris "
                 "(the seed's figures 5.24-5.27 are at its 160th cycle of the coupled run)",
        "counts": "imposed (the seed's 22k, 81k, 102k), not generated by eq 3.10 over the "
                  "run (that would be ~330k by cycle 160 with no ejection, docs/debris.md)",
        "placement": "random points in the worn volume of both bodies inside the solver "
                     "window at the loading position, probability ~ local worn depth, laid as "
                     "the compressed single layer of seed figure 3.8",
        "load": "the DE phase loads the debris to the load the first bodies carried at the "
                "particles' sites (eqs 3.11-3.15, capped at 0.9 of the load); the first "
                "bodies are rigid in the DE phase, then the debris pressure is applied to "
                "the elastic first bodies and the solid contact carries the rest",
        "force distribution": "contact force on the lower first body = (solid-solid + "
                              "debris) pressure x cell area; 'solid' columns give the "
                              "solid-solid part alone",
        "centre / edge": f"centre = the {ZONE_FRACTION:.0%} of the no-debris contact area "
                         "nearest its pressure centroid, edge = the "
                         f"{ZONE_FRACTION:.0%} farthest from it; mean pressure over each",
        "profiles": "mean over the 5 grid lines through the window centre",
    }


def parse_counts(text: str, field: str = "--counts") -> tuple[int, ...]:
    """Comma-separated particle counts (each 1..10^7, distinct, in any order)."""
    return parse_int_list(text, field, lambda c: 1 <= c <= 10**7,
                          "comma-separated distinct particle counts, each 1..10000000 "
                          "(e.g. 22000,81000,102000)")


@runs.releases_folders
def debris_study(config: ConfigSource = None, out: str | os.PathLike[str] | None = None, *,
                 counts: Sequence[int] | str | None = None, cycle: int | None = None,
                 quick: bool = False, resume: bool = False, progress: bool = False,
                 threads: int | None = None, echo: Echo | None = None) -> RunResult:
    """Lu (2018) section 5.4 into folder ``out``: the case worn without debris to ``cycle``
    (``out/wear/``), then at the loading position the contact force on the lower body
    without and with each count of debris particles; writes ``debris_study.csv`` (one row
    without debris, then one per count), ``debris_study.json``, profiles and plots.

    ``config``: the case (a :class:`~tribodem.fretting.config.FrettingConfig`, a dict
    shaped like the TOML file, a TOML path or None: the energy case; with ``resume``, the
    study's own); ``counts``: particle counts (a sequence or a comma-separated string;
    default the seed's 22000, 81000, 102000, ``quick``: 1100, 4050, 5100; with ``resume``
    the study's own); ``cycle``: the study's cycle (default the config's ``cycles``);
    ``threads``: DEM threads (0 = all; None: as set); ``resume``: skip the finished stages
    and resume the wear run from its checkpoint.
    """
    n_threads = None if threads is None else runs.check_threads(threads, "--threads")
    folder = as_out(out)  # type: ignore[arg-type]  # None is refused there, named
    runs.check_out_dir(folder, "--out", resume=resume,
                       need=("study.toml",) if resume else ())
    # a resume takes the study's own config and counts unless they are given again
    record = read_study(folder) if resume else {}
    if counts is None:
        counts = (tuple(record.get("counts") or ()) if resume else
                  QUICK_STUDY_COUNTS if quick else SEED_COUNTS)
    wanted = parse_counts(counts if isinstance(counts, str) else
                          ",".join(str(c) for c in counts))
    base = record["config"] if resume and config is None else None
    cfg = resolve_config(config, quick=quick,
                         overrides={"cycles": cycle} if cycle is not None else None, base=base)
    if n_threads is not None:
        numba.set_num_threads(n_threads)
    summary = run_debris_study(cfg, folder, wanted, resume=resume, progress=progress,
                               echo=echo)
    return RunResult(folder, summary, "debris_study.csv", list(summary["files"]))


def run_debris_study(cfg: FrettingConfig, out: Path, counts: tuple[int, ...] = SEED_COUNTS,
                     resume: bool = False, progress: bool = False, echo: Echo | None = None
                     ) -> dict[str, Any]:
    """The whole study into ``out``; returns ``debris_study.json``'s content.

    ``cfg``: a validated :class:`~tribodem.fretting.config.FrettingConfig` (its ``cycles``
    is the study's cycle; its ``[debris]`` table gives the particle settings, its ``every``
    is ignored: the wear run has no debris). Stages, each kept: ``out/wear/`` (the fretting
    run, with its checkpoint), ``count_NNNNNN.{npz,json}`` per count and
    ``count_NNNNNN_state.npz``, the first-body solver's state after it (the warm starts of
    the next count's solves); ``resume`` skips finished stages, restoring the state the
    last of them left, and resumes the wear run from its checkpoint: the study resumed
    after any stage is bitwise the uninterrupted one.
    """
    say = echo or (lambda s: None)
    out = Path(out)
    wear_dir = out / "wear"
    ck = wear_dir / CHECKPOINT
    runs.check_out_dir(out, "--out", resume=resume, need=("study.toml",) if resume else ())
    cfg = cfg.model_copy(update={"debris": cfg.debris.model_copy(update={"every": None})})
    case = preflight(cfg)  # the case and every check of a run before any work
    settings = debris_settings(case)
    check_counts(settings, counts)
    meta = {"config": cfg.record(), "counts": [int(c) for c in counts]}
    if resume:
        check_study_resume(out, meta)
    else:
        for stale in [*out.glob("count_*.json"), *out.glob("count_*.npz")]:
            stale.unlink()
    out.mkdir(parents=True, exist_ok=True)
    write_text(out / "study.toml", dump_toml(meta))
    hint = "add --resume to the same command"
    runs.announce(out, ck, resume_hint=hint)
    done_wear = (wear_dir / "summary.json").is_file() and ck.is_file()
    if not (resume and done_wear):
        say(f"stage 1/{len(counts) + 1}: fretting run to cycle {cfg.cycles} without debris "
            f"-> {wear_dir}")
        run(cfg, wear_dir, echo=echo, resume=resume and ck.is_file(), progress=progress)
        runs.announce(out, ck, resume_hint=hint)  # the study's folder again, not wear/
    meta_ck, state = read_checkpoint(ck)
    loop = build_loop(cfg, case)
    loop.load_state_dict(state)
    loop.run(cfg.cycles)  # restored at its last cycle: nothing to run, the worn surfaces set
    sol = loop.solver
    p_without, gap = sol.loaded_solution(0.0)
    zones = contact_zones(p_without, sol.coords)
    none = distribution_metrics(p_without, zones, sol.dx)
    rows: list[dict[str, Any]] = []
    per_count: list[tuple[int, dict[str, NDArray[np.float64]]]] = []
    for k, count in enumerate(counts):
        row, arrays = count_stage(loop, settings, count, p_without, gap, zones, out,
                                  f"stage {k + 2}/{len(counts) + 1}", resume, say)
        rows.append(row)
        per_count.append((count, arrays))
        say(f"  {count:,} particles: debris carries {row['debris_load_fraction']:.1%} of the "
            f"load; peak total {row['total_peak_pressure_Pa'] / none['peak_pressure_Pa'] - 1:+.1%}"
            f", solid-solid {row['solid_peak_pressure_Pa'] / none['peak_pressure_Pa'] - 1:+.1%}"
            f" ({row['de_wall_time_s']:.0f} s)")
    table = compare(rows, none)
    files = write_outputs(cfg, out, sol.coords, none, p_without, table, per_count)
    summary = {
        "cycle": cfg.cycles, "counts": list(counts), "no_debris": none,
        "contact_radius_m": zones.radius_m, "rows": table,
        "seed": {"cycle": SEED_CYCLE, "counts": list(SEED_COUNTS),
                 "peak_change": {str(k): v for k, v in SEED_PEAK_CHANGE.items()},
                 "trend": SEED_TREND},
        "wear_run": str(wear_dir), "assumptions": assumptions(cfg.cycles),
        "debris_settings": asdict(settings),
        "files": files,
        "checkpoint_cycles": int(meta_ck.get("cycles_done", cfg.cycles)),
    }
    write_json(out / "debris_study.json", summary)
    return summary


def write_outputs(cfg: FrettingConfig, out: Path, coords: NDArray[np.float64],
                  none: dict[str, Any], p_without: NDArray[np.float64],
                  table: list[dict[str, Any]],
                  per_count: list[tuple[int, dict[str, NDArray[np.float64]]]]) -> list[str]:
    """``debris_study.csv``, the profiles (CSV) and, as ``[output]`` asks, the plots; the
    names of every file the study writes (``debris_study.json`` and ``study.toml`` too)."""
    files = [write_table(out, none, table).name,
             profiles_csv(out, coords, p_without, per_count).name]
    if cfg.output.figures:
        files += [p.name for p in write_plots(out, coords, p_without, per_count, cfg.cycles)]
    return [*files, "debris_study.json", "study.toml"]


def check_counts(settings: DebrisSettings, counts: Sequence[int]) -> None:
    """Refuse (``ConfigError`` naming ``--counts``) a count whose spheres would not fit in
    the memory this machine has."""
    spheres_each = sum(share * debris_template(shape, settings.diameter).radii.size
                       for share, shape in zip(settings.shares, SHAPES, strict=True))
    for count in counts:
        runs.check_memory(count, spheres_each * BYTES_PER_PARTICLE, "--counts")


def check_study_resume(out: Path, meta: dict[str, Any]) -> None:
    """Refuse (``ConfigError``) resuming the study in ``out`` with another config or other
    counts; the study's cycle is its debris phases' cycle, so ``cycles`` may not change."""
    may = tuple(k for k in RESUME_MAY_CHANGE if k != "cycles")
    diffs = study_diffs(out, meta, may_change=may)
    if diffs:
        raise ConfigError(f"--resume: the config or counts differ from the study in "
                          f"'{out}' ({out / 'study.toml'}): {'; '.join(diffs)}; allowed: the "
                          f"same config and --counts ({may_change_text(may)})")


def count_stage(loop: FrettingLoop, settings: DebrisSettings, count: int,
                p_without: NDArray[np.float64], gap: NDArray[np.float64], zones: Zones,
                out: Path, label: str, resume: bool, say: Echo
                ) -> tuple[dict[str, Any], dict[str, NDArray[np.float64]]]:
    """One count: kept from an earlier run of the study on ``resume``, else its DE phase
    run and saved (``RunStopped`` when it fails: the finished stages are kept)."""
    got = load_count(out, count) if resume else None
    if got is not None:
        row, arrays, state = got
        try:  # where the uninterrupted study's next count starts from
            loop.solver.load_state_dict(state)
        except (KeyError, TypeError, ValueError) as err:
            raise ConfigError(f"--resume: '{out / f'count_{count:06d}_state.npz'}' does "
                              f"not fit this study: {type(err).__name__}: {err}") from None
        return row, arrays
    say(f"{label}: DE phase with {count:,} debris particles")
    try:
        row, arrays = run_count(loop, settings, count, p_without, gap, zones)
    except (ValueError, RuntimeError) as err:
        raise runs.RunStopped(
            f"DE phase with {count:,} particles: {err} (the wear run and the "
            "finished counts are kept; --resume runs the missing counts again)") from None
    save_count(out, count, row, arrays, loop.solver.state_dict())
    return row, arrays
