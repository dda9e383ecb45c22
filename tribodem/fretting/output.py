"""Result files of a fretting run: CSV, JSON, figures (seed figs 5.14-5.16, 6.15), VTK."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from tribodem.fretting.loop import RESULT_COLUMNS, FrettingHistory
from tribodem.io.results import atomic_write, write_csv, write_figure, write_json


def write_results(hist: FrettingHistory, out: Path, extra: dict[str, Any]) -> dict[str, Any]:
    """``out/results.csv`` (one row per cycle) and ``out/summary.json`` (totals + ``extra``)."""
    write_csv(out / "results.csv", RESULT_COLUMNS,
              ([r[c] for c in RESULT_COLUMNS] for r in hist.rows))
    summary = {**hist.summary(), **extra}
    write_json(out / "summary.json", summary)
    return summary


def _profile_rows(n_rows: int, k: int = 5) -> list[int]:
    return sorted({int(round(i)) for i in np.linspace(0, n_rows - 1, min(k, n_rows))})


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
        for i in _profile_rows(len(profs)):
            lab = f"cycle {hist.rows[i]['cycle']}"
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
        ext = (x[0] * 1e3, x[-1] * 1e3, g.y[0] * 1e3, g.y[-1] * 1e3)
        im = ax.imshow(w.T * 1e6, origin="lower", extent=ext, aspect="equal", cmap="viridis")
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
    """Worn surfaces as VTK quad grids (points at z = -(recession + wear), m)."""
    import meshio

    g = hist.grid
    paths = []
    for body, x, w, base in (("upper", g.x_upper, hist.wear_upper, hist.base_upper),
                             ("lower", g.x_lower, hist.wear_lower, hist.base_lower)):
        nx, ny = w.shape
        xx, yy = np.meshgrid(x, g.y, indexing="ij")
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
