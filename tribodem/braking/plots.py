"""Figures of a braking run, like Sha et al. (2022) figures 11-13 and 16-18 (matplotlib, Agg)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from tribodem.braking.model import EJECTED, Interface
from tribodem.io.results import write_figure


def _plt():  # noqa: ANN202
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _disks(ax: Any, pos: np.ndarray, radius: np.ndarray, values: np.ndarray, cmap: str,
           label: str, fig: Any) -> None:
    from matplotlib.collections import EllipseCollection

    col = EllipseCollection(2 * radius * 1e6, 2 * radius * 1e6, np.zeros_like(radius),
                            units="xy", offsets=pos[:, :2] * 1e6, offset_transform=ax.transData,
                            cmap=cmap, array=values, linewidths=0)
    ax.add_collection(col)
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.set_xlabel("x (um)")
    ax.set_ylabel("y (um)")
    fig.colorbar(col, ax=ax, label=label, shrink=0.8)


def _plot_displacement(out: Path, frames: dict[str, dict[str, np.ndarray]], w: float
                       ) -> None:
    """displacement.png (figs 11, 16): magnitude (um) in the body frames of the early and
    end frames, detached particles marked; ``w``: the cell width (m)."""
    plt = _plt()
    keys = [k for k in ("early", "end") if k in frames]
    fig, axes = plt.subplots(1, len(keys), figsize=(6.5 * len(keys), 5.0), squeeze=False)
    for ax, k in zip(axes[0], keys, strict=True):
        fr = frames[k]
        live = fr["group"] != EJECTED  # the outlet's store is not part of the cell
        pos = fr["pos"][live].copy()
        pos[:, 0] = np.mod(pos[:, 0], w)
        mag = np.linalg.norm(fr["disp"][live], axis=1) * 1e6
        _disks(ax, pos, fr["radius"][live], mag, "viridis", "displacement (um)", fig)
        d = fr["detached"][live]
        ax.scatter(pos[d, 0] * 1e6, pos[d, 1] * 1e6, s=4, c="r", marker="x",
                   label="detached (debris)")
        ax.set_title(f"{k}: sliding {float(fr['slid']) * 1e6:.1f} um")
        ax.legend(loc="upper right", fontsize=7)
    fig.tight_layout()
    write_figure(out / "displacement.png", fig)


def _plot_velocity(out: Path, fr: dict[str, np.ndarray], w: float) -> None:
    """velocity.png (fig 13): the velocity vectors (m/s, lab frame) of frame ``fr``."""
    plt = _plt()
    live = fr["group"] != EJECTED
    pos = fr["pos"][live].copy()
    pos[:, 0] = np.mod(pos[:, 0], w)
    v = fr["vel"][live]
    fig, ax = plt.subplots(figsize=(8, 5.5))
    sp = np.linalg.norm(v[:, :2], axis=1)
    q = ax.quiver(pos[:, 0] * 1e6, pos[:, 1] * 1e6, v[:, 0], v[:, 1], sp, cmap="plasma",
                  scale_units="xy", angles="xy", scale=max(sp.max(), 1e-12) / (w * 1e6 / 20))
    fig.colorbar(q, ax=ax, label="speed (m/s)")
    ax.set_aspect("equal")
    ax.set_xlabel("x (um)")
    ax.set_ylabel("y (um)")
    ax.set_title("velocity vectors at the end (lab frame; disc at -v)")
    fig.tight_layout()
    write_figure(out / "velocity.png", fig)


def _plot_chains(out: Path, fr: dict[str, np.ndarray], w: float) -> None:
    """force_chains.png (fig 17) of frame ``fr``: strong compressive chains black, tensile
    red, width ~ |F|; weak ones grey."""
    from matplotlib.collections import LineCollection

    plt = _plt()
    fig, ax = plt.subplots(figsize=(8, 5.5))
    i, j, f = fr["chain_i"], fr["chain_j"], fr["chain_f"]
    a, b = fr["pos"][i, :2], fr["pos"][j, :2].copy()
    dx = b[:, 0] - a[:, 0]
    b[:, 0] = a[:, 0] + dx - w * np.rint(dx / w)
    shift = np.floor(a[:, 0] / w) * w
    a[:, 0] -= shift
    b[:, 0] -= shift
    segs = np.stack([a, b], axis=1) * 1e6
    mag = np.abs(f)
    strong = mag > mag.mean() if f.size else np.zeros(0, dtype=bool)
    lw = 0.3 + 3.0 * mag / max(mag.max(initial=0.0), 1e-300)
    colors = np.where(f < 0, "red", "black")
    ax.add_collection(LineCollection(segs[strong], colors=colors[strong], linewidths=lw[strong]))
    ax.add_collection(LineCollection(segs[~strong], colors="0.7", linewidths=0.3))
    ax.set_xlim(0, w * 1e6)
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_xlabel("x (um)")
    ax.set_ylabel("y (um)")
    ax.set_title(f"force chains at the end: strong compressive (black) / tensile (red), "
                 f"weak (grey); {int((f > 0).sum())} comp., {int((f < 0).sum())} tens.",
                 fontsize=9)
    fig.tight_layout()
    write_figure(out / "force_chains.png", fig)


#: wear_history.png's panels: (title, y label, [(row key, legend label, scale)]): one
#: quantity per axis, in its unit
HISTORY_PANELS = (
    ("wear depth", "depth (um)", [
        ("wear_depth_mean_pad_m", "pad, mean", 1e6), ("wear_depth_max_pad_m", "pad, max", 1e6),
        ("wear_depth_mean_disc_m", "disc, mean", 1e6),
        ("transfer_layer_thickness_m", "transfer layer thickness", 1e6)]),
    ("broken bonds", "bonds broken (count)", [
        ("broken_bonds", "all", 1.0), ("broken_bonds_tensile", "in tension", 1.0),
        ("broken_bonds_shear", "in shear", 1.0)]),
    ("debris", "debris (count)", [
        ("debris_particles", "particles", 1.0),
        ("debris_clusters", "clusters (connected pieces)", 1.0)]),
    ("force chains", "force chains (count)", [
        ("force_chains", "all", 1.0), ("strong_force_chains", "strong (|F| > mean)", 1.0),
        ("weak_force_chains", "weak", 1.0), ("compressive_force_chains", "compressive", 1.0),
        ("tensile_force_chains", "tensile", 1.0)]),
    ("pressure plate: pressure", "plate pressure (MPa)", [("wall_pressure_Pa", "plate", 1e-6)]),
    ("pressure plate: travel", "plate displacement (um)", [("wall_displacement_m", "plate",
                                                             1e6)]),
)


def _plot_history(out: Path, rows: list[dict[str, float]], summary: dict[str, Any]) -> None:
    """wear_history.png (figs 12, 18) against the simulated time (us), one quantity per
    axis with its unit (:data:`HISTORY_PANELS`): the wear depths (um), the broken bonds,
    the debris, the force chains (counts), the plate's pressure (MPa, with the target) and
    its displacement (um)."""
    plt = _plt()
    t = np.array([r["time_s"] for r in rows]) * 1e6
    fig, axes = plt.subplots(3, 2, figsize=(11, 10), sharex=True)
    for ax, (title, ylabel, curves) in zip(axes.flat, HISTORY_PANELS, strict=True):
        for key, lab, scale in curves:
            ax.plot(t, np.array([r[key] for r in rows]) * scale,
                    lw=0.8 if key.startswith("wall_") else 1.2, label=lab)
        if curves[0][0] == "wall_pressure_Pa":
            ax.axhline(summary["pressure_Pa"] / 1e6, color="k", ls="--", lw=0.8,
                       label="target")
        ax.set_title(title, fontsize=10)
        ax.set_ylabel(ylabel)
        if len(ax.get_lines()) > 1:
            ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("simulated time (us)")
    fig.suptitle(f"condition {summary['condition']}: {summary['pressure_Pa'] / 1e6:.3g} MPa, "
                 f"{summary['sliding_speed_m_s']:.4g} m/s")
    fig.tight_layout()
    write_figure(out / "wear_history.png", fig)


def plot_run(out: Path, rows: list[dict[str, float]], frames: dict[str, dict[str, np.ndarray]],
             iface: Interface, summary: dict[str, Any]) -> None:
    """Write displacement.png (fig 11/16), velocity.png (fig 13), force_chains.png (fig 17)
    and wear_history.png (figs 12, 18) into folder ``out``."""
    w = iface.width
    _plot_displacement(out, frames, w)
    _plot_velocity(out, frames["end"], w)
    _plot_chains(out, frames["end"], w)
    _plot_history(out, rows, summary)
