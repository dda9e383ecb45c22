"""Uniaxial compression test of a bonded specimen (Sha et al. (2022) section 3.1, figure 6, eq 12).

Two frictionless platens (velocity walls) move towards the centre at ``platen_speed``
(default the seed's 0.1 m/s each: strain rate 2 v / H = 2000 1/s for H = 0.1 mm, i.e.
~4e-5 strain per elastic-wave transit (c = sqrt(E/rho) ~ 5 km/s): quasi-static, so the
seed's speed is kept), local damping 0.1; the run stops when the axial stress has fallen
below ``stop_fraction`` (70%) of its peak, or at ``max_strain``.

Measurements (2D, thickness t): axial stress ``sigma_y = (F_top + F_bottom) / 2 / (W0 t)``
(compression +); axial strain from the mean y of the top and bottom boundary particles
(gauge, ``eps_y = -(dL)/L0``, compression +); lateral strain from the mean x of the left
and right boundary particles (``eps_x = dW / W0``, expansion +). Boundary particles: those
within one mean radius of the specimen's extreme. A gauge on particles rather than the
platen gap keeps the platen-contact compliance out of E.

Eq 12: ``E = d sigma_y / d eps_y``, ``nu = -d eps_x / d eps_y`` (with our sign convention
``nu = d eps_x / d eps_y``), both least-squares slopes over the pre-peak window where
``sigma_y`` is between ``fit_window`` = (10%, 50%) of the peak stress: the peak is the
calibration point that fixes the window (the seed's wording); the secant modulus to the
peak is reported too.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tribodem.dem import Material, PlaneWall
from tribodem.dem.contact import set_pair
from tribodem.io.results import write_figure
from tribodem.materials.library import MaterialSpec
from tribodem.materials.specimen import Specimen


@dataclass
class CompressionResult:
    """Stress-strain record and eq 12 moduli of one uniaxial compression test (SI)."""

    strain_y: np.ndarray
    strain_x: np.ndarray
    stress: np.ndarray
    young: float
    poisson: float
    peak_stress: float
    peak_strain: float
    secant_modulus: float
    fit_range: tuple[int, int]
    steps: int
    dt: float
    broken_bonds: int
    n_bonds: int
    stopped_by: str
    info: dict[str, float] = field(default_factory=dict)


def _edge_sets(pos: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, ...]:
    rm = float(r.mean())
    lo_x, hi_x = (pos[:, 0] - r).min(), (pos[:, 0] + r).max()
    lo_y, hi_y = (pos[:, 1] - r).min(), (pos[:, 1] + r).max()
    left = np.flatnonzero(pos[:, 0] - r < lo_x + rm)
    right = np.flatnonzero(pos[:, 0] + r > hi_x - rm)
    bottom = np.flatnonzero(pos[:, 1] - r < lo_y + rm)
    top = np.flatnonzero(pos[:, 1] + r > hi_y - rm)
    return left, right, bottom, top


def fit_moduli(strain_y: np.ndarray, strain_x: np.ndarray, stress: np.ndarray,
               fit_window: tuple[float, float] = (0.1, 0.5)
               ) -> tuple[float, float, tuple[int, int]]:
    """Eq 12 by least squares over the loading branch with ``stress`` in ``fit_window`` x
    peak (up to the first crossing of the upper bound). Returns (E Pa, nu, (first, last)
    index)."""
    peak = float(np.max(stress))
    # the loading branch up to the first crossing of the upper bound (a drop after an early
    # local break must not re-enter the window)
    above = np.flatnonzero(stress > fit_window[1] * peak)
    end = int(above[0]) if above.size else stress.size
    sel = np.flatnonzero(stress[:end] >= fit_window[0] * peak)
    if not (peak > 0 and fit_window[0] < fit_window[1]) or sel.size < 3:
        raise RuntimeError(f"compression: only {sel.size} points in the fit window "
                           f"{fit_window} of the peak {peak:.4g} Pa; record more often")
    a, b = sel[0], sel[-1] + 1
    young = float(np.polyfit(strain_y[a:b], stress[a:b], 1)[0])
    nu = float(np.polyfit(strain_y[a:b], strain_x[a:b], 1)[0])
    return young, nu, (int(a), int(b - 1))


def run_compression(specimen: Specimen, platen_speed: float = 0.1,
                    local_damping: float = 0.1, stop_fraction: float = 0.7,
                    max_strain: float = 0.05, fit_window: tuple[float, float] = (0.1, 0.5),
                    record_every: int = 10, dt_safety: float = 0.3,
                    max_steps: int = 2_000_000) -> CompressionResult:
    """Compress ``specimen`` between two platens until the stress falls below
    ``stop_fraction`` x peak (or ``max_strain``); moduli by eq 12 (``fit_moduli``).

    ``platen_speed`` (m/s, each platen), ``local_damping`` (PFC alpha).
    """
    checks = [("platen_speed", platen_speed, platen_speed > 0, "> 0 m/s"),
              ("local_damping", local_damping, 0 <= local_damping < 1, "in [0, 1)"),
              ("stop_fraction", stop_fraction, 0 < stop_fraction < 1, "in (0, 1)"),
              ("max_strain", max_strain, 0 < max_strain < 0.5, "in (0, 0.5)"),
              ("record_every", record_every, record_every >= 1, ">= 1 step")]
    for name, v, ok, allowed in checks:
        if not ok:
            raise ValueError(f"compression: {name} = {v!r}: must be {allowed}")
    spec: MaterialSpec = specimen.spec
    p0 = specimen.particles
    pos, r = p0.pos, p0.radius
    y_lo, y_hi = float((pos[:, 1] - r).min()), float((pos[:, 1] + r).max())
    width = float((pos[:, 0] + r).max() - (pos[:, 0] - r).min())
    platen = Material(name="platen", young=spec.young, poisson=spec.poisson,
                      density=spec.density, friction=0.0,
                      effective_modulus=spec.effective_modulus, kratio=spec.kratio,
                      beta_n=spec.beta_n, law="linear")
    walls = [PlaneWall([0, y_lo, 0], [0, 1, 0], material=1, mode="velocity",
                       velocity=[0, platen_speed, 0], name="bottom"),
             PlaneWall([0, y_hi, 0], [0, -1, 0], material=1, mode="velocity",
                       velocity=[0, -platen_speed, 0], name="top")]
    sim, bonds = specimen.build(walls=walls, extra_materials=[platen],
                                local_damping=local_damping, dt_safety=dt_safety)
    set_pair(sim.pairtab, 0, 1, spec.contact_material(), platen, friction=0.0)
    left, right, bottom, top = _edge_sets(pos, r)
    t = p0.thickness

    def gauge() -> tuple[float, float]:
        x, y = sim.p.pos[:, 0], sim.p.pos[:, 1]
        return float(x[right].mean() - x[left].mean()), float(y[top].mean() - y[bottom].mean())

    w0, l0 = gauge()
    ey, ex, sy = [0.0], [0.0], [0.0]
    peak, stopped_by = 0.0, "max_steps"
    while sim.step_count < max_steps:
        sim.step(record_every)
        w, length = gauge()
        s = 0.5 * (sim.walls[0].normal_force + sim.walls[1].normal_force) / (width * t)
        ey.append((l0 - length) / l0)
        ex.append((w - w0) / w0)
        sy.append(s)
        peak = max(peak, s)
        if peak > 0 and s < stop_fraction * peak and bonds.broken_count() > 0:
            stopped_by = "post-peak stress"
            break
        if ey[-1] >= max_strain:
            stopped_by = "max_strain"
            break
    strain_y, strain_x, stress = np.array(ey), np.array(ex), np.array(sy)
    young, nu, rng = fit_moduli(strain_y, strain_x, stress, fit_window)
    k = int(np.argmax(stress))
    return CompressionResult(
        strain_y=strain_y, strain_x=strain_x, stress=stress, young=young, poisson=nu,
        peak_stress=float(stress[k]), peak_strain=float(strain_y[k]),
        secant_modulus=float(stress[k] / strain_y[k]) if strain_y[k] > 0 else float("nan"),
        fit_range=rng, steps=sim.step_count, dt=sim.dt, broken_bonds=bonds.broken_count(),
        n_bonds=bonds.n_bonds, stopped_by=stopped_by,
        info={"platen_speed_m_s": platen_speed, "strain_rate_1_s":
              2.0 * platen_speed / (y_hi - y_lo), "local_damping": local_damping,
              "width_m": width, "height_m": y_hi - y_lo, "particles": float(sim.p.n)})


def plot_stress_strain(res: CompressionResult, path: str | Path, title: str = "") -> Path:
    """Axial stress and lateral strain vs axial strain, fit window marked (PNG, Agg)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    e = 100 * res.strain_y
    ax.plot(e, res.stress / 1e6, color="tab:blue", lw=1.2, label="axial stress")
    a, b = res.fit_range
    ax.plot(e[a:b + 1], res.stress[a:b + 1] / 1e6, color="tab:red", lw=3, alpha=0.6,
            label=f"eq 12 window: E = {res.young / 1e9:.1f} GPa")
    ax.axhline(res.peak_stress / 1e6, color="grey", lw=0.6, ls=":")
    ax.set_xlabel("axial strain (%)")
    ax.set_ylabel("axial stress (MPa)")
    ax2 = ax.twinx()
    ax2.plot(e, 100 * res.strain_x, color="tab:green", lw=1,
             label=f"lateral strain: nu = {res.poisson:.3f}")
    ax2.set_ylabel("lateral strain (%)")
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    ax.legend(h1 + h2, l1 + l2, loc="lower right", fontsize=8)
    ax.set_title(title or "uniaxial compression (Sha et al. (2022) fig 6, eq 12)")
    fig.tight_layout()

    return write_figure(path, fig)
