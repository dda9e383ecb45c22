"""Result files of a fretting run: CSV, JSON, figures (seed figs 5.14-5.16, 6.15), VTK."""

from __future__ import annotations

import json
import pickle
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from tribodem.fretting.loop import (
    DEBRIS_COLUMNS,
    PLASTIC_COLUMNS,
    RESULT_COLUMNS,
    FrettingHistory,
)
from tribodem.io.config import ConfigError
from tribodem.io.results import atomic_write, write_csv, write_figure, write_json

#: File name of a fretting run's checkpoint in its output folder.
CHECKPOINT = "checkpoint.npz"
#: Layout version of :data:`CHECKPOINT` (refused on resume when different).
CHECKPOINT_FORMAT = 1


def write_rows(hist: FrettingHistory, out: Path) -> Path:
    """``out/results.csv``: one row per cycle recorded so far, and, when the criterion
    reports per-cycle diagnostics (e.g. the largest DFDI or Miner sum), ``out/criterion.csv``
    with one row per simulated cycle (both rewritten atomically)."""
    cols = RESULT_COLUMNS + (DEBRIS_COLUMNS if hist.debris is not None else ())
    if any(PLASTIC_COLUMNS[0] in r for r in hist.rows):  # the first body's plastic state
        cols = cols + PLASTIC_COLUMNS
    info = [(r["cycle"], r["criterion"]) for r in hist.rows
            if not r.get("jumped") and r.get("criterion")]
    if info:
        keys = sorted({k for _, d in info for k, v in d.items()
                       if isinstance(v, int | float)})
        write_csv(out / "criterion.csv", ["cycle", *keys],
                  ([c, *(d.get(k, "") for k in keys)] for c, d in info))
    return write_csv(out / "results.csv", cols,
                     ([r.get(c, "") for c in cols] for r in hist.rows))


def write_results(hist: FrettingHistory, out: Path, extra: dict[str, Any]) -> dict[str, Any]:
    """``out/results.csv`` (one row per cycle) and ``out/summary.json`` (totals + ``extra``,
    and ``wear_zero_reason``: :func:`wear_zero_reason`)."""
    write_rows(hist, out)
    summary = {**hist.summary(), **extra}
    summary["wear_zero_reason"] = wear_zero_reason(summary)
    write_json(out / "summary.json", summary)
    return summary


def _pair(info: dict[str, Any], key: str, fmt: str = ".4g") -> str | None:
    """``"upper X, lower Y"`` of ``info[key_upper]`` and ``info[key_lower]`` (None without)."""
    up, lo = info.get(f"{key}_upper"), info.get(f"{key}_lower")
    if up is None or lo is None:
        return None
    return f"upper {format(up, fmt)}, lower {format(lo, fmt)}"


def wear_zero_reason(summary: dict[str, Any]) -> str | None:
    """Why a run's worn volume is zero on both bodies (None when anything was worn), from
    its summary: no cycle done; a threshold criterion whose field (or damage sum) never
    reached its threshold, with the largest value reached at the last simulated cycle
    (``criterion_last_cycle``) and, for SWT, the projected cycles to first wear; a rate
    criterion without dissipated energy or slip."""
    if summary.get("wear_volume_upper_m3", 0.0) > 0 or summary.get("wear_volume_lower_m3",
                                                                    0.0) > 0:
        return None
    if not summary.get("cycles"):
        return "no cycle was completed (the run stopped before its first cycle's end)"
    crit = summary.get("criterion") or {}
    name, info = crit.get("name", "the criterion"), summary.get("criterion_last_cycle") or {}
    if name == "dfdi":
        got = _pair(info, "max_dfdi")
        return ("the DFDI damage sum never reached its threshold 1 at any material point"
                + (f" (largest after the last simulated cycle: {got})" if got else ""))
    if name == "swt":
        got = _pair(info, "miner_sum_max")
        first = _pair(info, "cycles_to_first_wear", ".4g")
        return ("Miner's SWT damage sum never reached its threshold 1 at any material point"
                + (f" (largest after the last simulated cycle: {got})" if got else "")
                + (f"; projected cycles to first wear: {first}" if first else ""))
    if crit.get("kind") == "threshold":
        unit = crit.get("unit", "")
        u = "" if unit in ("", "-") else f" {unit}"  # "-": dimensionless
        thr = crit.get("threshold")
        got = _pair(info, "max_value")
        return (f"the {name} criterion's field never reached its threshold"
                + (f" {thr:.4g}{u}" if thr is not None else "")
                + (f" (largest over the last simulated cycle: {got}{u})" if got else ""))
    if not summary.get("dissipated_energy_total_J"):
        return (f"the {name} criterion wears where the contact slips, and no energy was "
                "dissipated (the contact stuck: no slip)")
    return f"the {name} criterion gave no wear depth at any grid point"


def _profile_rows(hist: FrettingHistory, k: int = 5) -> list[int]:
    """Indices of the recorded profiles to show: ``k`` spread over the run, the last
    among them."""
    n = len(hist.profile_cycles)
    return sorted({int(round(i)) for i in np.linspace(0, n - 1, min(k, n))}) if n else []


def write_profiles(hist: FrettingHistory, out: Path) -> Path | None:
    """``out/profiles.csv``: the worn profiles along the stroke at the central section
    y = 0 (columns cycle, body, x_m, wear_depth_m; m), at the cycles ``profiles.png``
    plots (five spread over the run, the last among them). None before the first cycle."""
    if not hist.rows:
        return None
    g = hist.grid
    rows: list[list[Any]] = []
    for i in _profile_rows(hist):
        cycle = hist.profile_cycles[i]
        for body, x, profs in (("upper", g.x_upper, hist.profiles_upper),
                               ("lower", g.x_lower, hist.profiles_lower)):
            rows += [[cycle, body, float(xv), float(d)] for xv, d in zip(x, profs[i],
                                                                         strict=True)]
    return write_csv(out / "profiles.csv", ["cycle", "body", "x_m", "wear_depth_m"], rows)


def write_figures(hist: FrettingHistory, out: Path) -> list[Path]:
    """Profiles at the central section (figs 5.15/6.15), wear-scar maps (5.14), wear vs
    cycle (5.16). PNG, written atomically."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    g = hist.grid
    paths = []
    if not hist.rows:
        return paths
    # profiles: surface height -(recession + wear) along x at y = 0, um
    fig, axes = plt.subplots(2, 2, figsize=(10, 7), sharex="col")
    for col, body, x, base, profs in (
        (0, "lower", g.x_lower, hist.base_lower, hist.profiles_lower),
        (1, "upper", g.x_upper, hist.base_upper, hist.profiles_upper),
    ):
        top, bottom = axes[0, col], axes[1, col]
        top.plot(x * 1e3, -base * 1e6, "k--", label="unworn")
        for i in _profile_rows(hist):
            lab = f"cycle {hist.profile_cycles[i]}"
            top.plot(x * 1e3, -(base + profs[i]) * 1e6, label=lab)
            bottom.plot(x * 1e3, -profs[i] * 1e6, label=lab)
        top.set_ylabel("surface height (um)")
        top.set_title(f"{body} body, central section y = 0")
        top.legend(fontsize=7)
        bottom.set_xlabel("x (mm)")
        bottom.set_ylabel("- wear depth (um)")
    fig.tight_layout()
    paths.append(write_figure(out / "profiles.png", fig))
    # wear-scar maps
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, body, x, w in ((axes[0], "lower", g.x_lower, hist.wear_lower),
                           (axes[1], "upper", g.x_upper, hist.wear_upper)):
        half = 0.5 * g.dy  # a point stands for dy along y (one section: the window's side)
        ext = (x[0] * 1e3, x[-1] * 1e3, (g.y[0] - half) * 1e3, (g.y[-1] + half) * 1e3)
        im = ax.imshow(w.T * 1e6, origin="lower", extent=ext, cmap="viridis",
                       aspect="equal" if g.ny > 1 else "auto")
        fig.colorbar(im, ax=ax, label="wear depth (um)")
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm)")
        ax.set_title(f"{body} body, cycle {hist.rows[-1]['cycle']}")
    fig.tight_layout()
    paths.append(write_figure(out / "wear_scar.png", fig))
    # wear vs cycle
    c = np.array([r["cycle"] for r in hist.rows])
    jumped = np.array([r["jumped"] for r in hist.rows], dtype=bool)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for body, color in (("upper", "tab:blue"), ("lower", "tab:red")):
        d = np.array([r[f"wear_depth_{body}_m"] for r in hist.rows]) * 1e6
        v = np.array([r[f"wear_volume_{body}_m3"] for r in hist.rows]) * 1e9
        axes[0].plot(c, d, color=color, label=body)
        axes[1].plot(c, v, color=color, label=body)
        if jumped.any():
            axes[0].plot(c[jumped], d[jumped], ".", color=color, ms=3)
            axes[1].plot(c[jumped], v[jumped], ".", color=color, ms=3)
    axes[0].set_ylabel("max wear depth (um)")
    axes[1].set_ylabel("worn volume (mm^3)")
    for ax in axes:
        ax.set_xlabel("cycle")
        ax.legend(title="dots: jumped" if jumped.any() else None)
    fig.tight_layout()
    paths.append(write_figure(out / "wear_vs_cycle.png", fig))
    return paths


def write_vtk_surfaces(hist: FrettingHistory, out: Path) -> list[Path]:
    """Worn surfaces as VTK quad grids (points at z = -(recession + wear), m); a line
    contact solved on one cross-section is drawn as a strip of the window's side along y
    (its section at both edges)."""
    import meshio

    g = hist.grid
    paths = []
    y = g.y if g.ny > 1 else np.array([-0.5 * g.dy, 0.5 * g.dy])
    for body, x, w, base in (("upper", g.x_upper, hist.wear_upper, hist.base_upper),
                             ("lower", g.x_lower, hist.wear_lower, hist.base_lower)):
        if g.ny == 1:
            w = np.repeat(w, 2, axis=1)
        nx, ny = w.shape
        xx, yy = np.meshgrid(x, y, indexing="ij")
        # base recession is only stored at the central section: use the worn depth map
        # for z and give the unworn central profile as point data along x
        z = -w
        pts = np.stack([xx.ravel(), yy.ravel(), z.ravel()], axis=1)
        idx = np.arange(nx * ny).reshape(nx, ny)
        quads = np.stack([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(),
                          idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()], axis=1)
        mesh = meshio.Mesh(pts, [("quad", quads)],
                           point_data={"wear_depth_m": w.ravel(),
                                       "unworn_recession_central_m":
                                           np.repeat(base, ny)})
        path = out / f"surface_{body}.vtu"
        atomic_write(path, lambda p, m=mesh: meshio.write(p, m, file_format="vtu"))
        paths.append(path)
    return paths


def debris_layer_figure(ph: Any) -> Any:
    """``debris_layer.png``'s figure of DE phase ``ph`` (a :class:`DEPhaseResult`): the
    particles coloured by the force on each (mN) and by the distance moved in the loading
    step (nm), each with its colour bar below it (a layer is wider than long along the
    stroke); a constrained layout keeps the titles clear of the colour bars."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    moved = np.linalg.norm(ph.positions - ph.start_positions, axis=1)
    fmag = np.linalg.norm(ph.particle_force, axis=1)
    ext = np.ptp(ph.positions[:, :2], axis=0)  # the figure's height follows the layer's
    ratio = float(np.clip(ext[1] / ext[0], 0.2, 1.5)) if ext[0] > 0 else 1.0
    fig, axes = plt.subplots(1, 2, figsize=(11, 2.3 + 4.7 * ratio), layout="constrained")
    for ax, val, lab in ((axes[0], fmag * 1e3, "force on particle (mN)"),
                         (axes[1], moved * 1e9, "moved distance (nm)")):
        sc = ax.scatter(ph.positions[:, 0] * 1e3, ph.positions[:, 1] * 1e3, c=val, s=2,
                        cmap="viridis")
        fig.colorbar(sc, ax=ax, label=lab, location="bottom", shrink=0.8, aspect=40)
        ax.set_aspect("equal")
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm)")
    axes[0].set_title(f"debris layer, cycle {ph.cycle}: {ph.particles:,} particles\n"
                      "force on each (figs 5.23/5.26)", fontsize=10)
    axes[1].set_title("distance moved in the loading step\n(figs 5.20/5.21)", fontsize=10)
    return fig


def write_debris_outputs(hist: FrettingHistory, out: Path, figures: bool = True,
                         vtk: bool = True) -> list[Path]:
    """Debris of each DE phase: ``debris_CCCC.vtu`` (particles with force, moved distance,
    shape) and pictures like seed figs 5.19-5.27: the particle layer coloured by the force
    on each particle, the distance moved in the loading step, the servo record, and the
    contact pressure on the lower body at the central section without vs with debris."""
    from tribodem.io.stl import heightmap_to_triangles, write_stl
    from tribodem.io.vtk import write_points

    paths: list[Path] = []
    last = hist.de_phases[-1] if hist.de_phases else None
    if last is not None and last.coords is not None:
        for body, z in (("lower", last.lower_z), ("upper", last.upper_z)):
            tris = heightmap_to_triangles(last.coords, last.coords, z)
            paths.append(write_stl(out / f"de_surface_{body}_{last.cycle:04d}.stl", tris))
    for ph in hist.de_phases:
        moved = np.linalg.norm(ph.positions - ph.start_positions, axis=1)
        fmag = np.linalg.norm(ph.particle_force, axis=1)
        paths.append(write_csv(
            out / f"debris_servo_{ph.cycle:04d}.csv",
            ("step", "upper_force_N", "lower_force_N", "upper_z_m", "target_N"),
            ([int(h[0]), h[1], h[2], h[3], ph.target_N] for h in ph.history)))
        if vtk:
            paths.append(write_points(
                out / f"debris_{ph.cycle:04d}.vtu", ph.positions,
                {"radius_m": ph.radius, "force_on_lower_N": ph.particle_force,
                 "force_N": fmag, "moved_m": moved}))
    if not figures or not hist.de_phases:
        return paths
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ph = hist.de_phases[-1]
    fig = debris_layer_figure(ph)
    paths.append(write_figure(out / "debris_layer.png", fig))
    g = hist.grid
    j = g.n // 2
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    if ph.pressure_without is not None and ph.pressure_with is not None:
        axes[0].plot(g.x_upper * 1e3, ph.pressure_without[:, j] / 1e6, label="without debris")
        axes[0].plot(g.x_upper * 1e3, ph.pressure_with[:, j] / 1e6, label="with debris")
        axes[0].plot(g.x_upper * 1e3, ph.pressure[:, j] / 1e6, ":", label="debris share")
    axes[0].set_xlabel("x (mm)")
    axes[0].set_ylabel("contact pressure on lower body (MPa)")
    axes[0].set_title(f"central section, cycle {ph.cycle} (figs 5.22/5.24)")
    axes[0].legend(fontsize=8)
    for k, p in enumerate(hist.de_phases):
        axes[1].plot(p.history[:, 0], p.history[:, 1], label=f"cycle {p.cycle}")
        axes[1].axhline(p.target_N, color="k", lw=0.5, ls="--",
                        label="target" if k == 0 else None)
    axes[1].set_xlabel("DE step")
    axes[1].set_ylabel("servo force on the debris (N)")
    axes[1].legend(fontsize=7)
    fig.tight_layout()
    paths.append(write_figure(out / "debris_pressure.png", fig))
    return paths


# ----------------------------------------------------------------------- checkpoints
@dataclass(frozen=True)
class _ArrayRef:
    key: str


def _split(tree: Any, arrays: dict[str, np.ndarray]) -> Any:
    """Numeric numpy arrays of nested dicts -> ``arrays`` (replaced by references)."""
    if isinstance(tree, dict):
        return {k: _split(v, arrays) for k, v in tree.items()}
    if isinstance(tree, np.ndarray) and tree.dtype != object:
        key = f"a{len(arrays)}"
        arrays[key] = tree
        return _ArrayRef(key)
    return tree


def _join(tree: Any, arrays: Any) -> Any:
    if isinstance(tree, dict):
        return {k: _join(v, arrays) for k, v in tree.items()}
    if isinstance(tree, _ArrayRef):
        return np.array(arrays[tree.key])
    return tree


def write_checkpoint(path: Path, meta: dict[str, Any], state: dict[str, Any]) -> Path:
    """One ``.npz`` (written to a temporary file, then renamed over ``path``): ``meta``
    as JSON (format, resolved config, cycle reached), the numeric arrays of ``state``
    (exact bits) and the rest of ``state`` (rows, strategy, debris record, ...) pickled."""
    arrays: dict[str, np.ndarray] = {}
    rest = _split(state, arrays)
    blob = np.frombuffer(pickle.dumps(rest, protocol=pickle.HIGHEST_PROTOCOL), dtype=np.uint8)
    head = np.array(json.dumps({"format": CHECKPOINT_FORMAT, **meta}))

    def w(p: Path) -> None:
        with p.open("wb") as fh:
            np.savez(fh, meta=head, blob=blob, **arrays)
    return atomic_write(path, w)


def read_checkpoint(path: Path) -> tuple[dict[str, Any], dict[str, Any]]:
    """(meta, state) of :func:`write_checkpoint`; ``ConfigError`` when it cannot be read."""
    try:
        with np.load(path, allow_pickle=False) as z:
            meta = json.loads(str(z["meta"][()]))
            if not isinstance(meta, dict) or meta.get("format") != CHECKPOINT_FORMAT:
                got = meta.get("format") if isinstance(meta, dict) else None
                raise ValueError(f"checkpoint format {got!r}, this tribodem reads "
                                 f"{CHECKPOINT_FORMAT}")
            rest = pickle.loads(z["blob"].tobytes())  # noqa: S301 - the run's own file
            state = _join(rest, z)
    except Exception as err:  # noqa: BLE001 - truncated, corrupt or foreign file
        raise ConfigError(f"checkpoint '{path}' cannot be read: {type(err).__name__}: "
                          f"{err}") from None
    return meta, state
