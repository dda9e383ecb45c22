"""Figures of a braking run, like seed 000 figures 11-13 and 16-18 (matplotlib, Agg)."""

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


def _plot_history(out: Path, rows: list[dict[str, float]], summary: dict[str, Any]) -> None:
    """wear_history.png (figs 12, 18): depths (um), bonds and debris, force chains, the
    plate's pressure (MPa) and displacement (um) against the simulated time (us)."""
    plt = _plt()
    t = np.array([r["time_s"] for r in rows]) * 1e6
    fig, axes = plt.subplots(2, 2, figsize=(10, 7))
    ax = axes[0, 0]
    for key, lab in (("wear_depth_mean_pad_m", "pad mean"), ("wear_depth_max_pad_m", "pad max"),
                     ("wear_depth_mean_disc_m", "disc mean"),
                     ("transfer_layer_thickness_m", "transfer layer")):
        ax.plot(t, np.array([r[key] for r in rows]) * 1e6, label=lab)
    ax.set_ylabel("depth (um)")
    ax.legend(fontsize=7)
    ax = axes[0, 1]
    for key in ("broken_bonds", "broken_bonds_tensile", "broken_bonds_shear",
                "debris_particles", "debris_clusters"):
        ax.plot(t, [r[key] for r in rows], label=key)
    ax.legend(fontsize=7)
    ax = axes[1, 0]
    for key in ("force_chains", "strong_force_chains", "weak_force_chains",
                "tensile_force_chains", "compressive_force_chains"):
        ax.plot(t, [r[key] for r in rows], label=key)
    ax.legend(fontsize=7)
    ax.set_xlabel("simulated time (us)")
    ax = axes[1, 1]
    ax.plot(t, np.array([r["wall_pressure_Pa"] for r in rows]) / 1e6, lw=0.7,
            label="wall pressure (MPa)")
    ax.axhline(summary["pressure_Pa"] / 1e6, color="k", ls="--", label="target")
    ax.plot(t, np.array([r["wall_displacement_m"] for r in rows]) * 1e6, label="wall dy (um)")
    ax.legend(fontsize=7)
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
