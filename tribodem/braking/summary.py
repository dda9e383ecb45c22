"""A braking run's ``summary.json``: what was run, what was measured at the end, the rates,
the cell, the wall times and the assumptions behind the numbers, with the notes the run's
own outcome calls for.

Time mapping (stated in every summary): the simulated time is the braking time it
represents (``equivalent_braking_time_s = simulated_time_s``); the seed's 8 s of braking
(377 m at 47 m/s) are out of reach, so the summary reports the fraction simulated and,
separately labelled, a linear extrapolation of the mean wear depth to 8 s from the steady
wear rate (least-squares slope over the second half of the run). Every summary reports
``wear_rate_steady_m_per_m`` (null with ``wear_rate_steady_reason`` when the steady-state
rule did not pass: the slope over the last two thirds is then
``wear_rate_last_two_thirds_m_per_m`` only), the run-in distance and depth, and
``contact_fraction``
(share of looks, one every ``CONTACT_EVERY`` steps, at which a disc-pad contact carries
load).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from tribodem.braking.conditions import SEED_BRAKING_TIME_S, pressure_to_load, speed_to_rpm
from tribodem.braking.drive import CONTACT_EVERY
from tribodem.braking.loop import BrakingLoop
from tribodem.braking.measure import REMAINING, breaks_by_place
from tribodem.braking.model import DISC, EJECTED, PLATE_AREAL_MASS, Interface
from tribodem.braking.setup import RunSetup
from tribodem.braking.steady import (
    STEADY_CUTS,
    steady_reason,
    steady_state,
    wear_extrapolation,
    wear_vs_distance,
    worn_text,
    worn_through,
)
from tribodem.io.runs import RunStopped

#: ``contact_fraction`` from which the interface counts as closed (a pad under hydraulic
#: pressure is in contact >= 90 % of the time); below it the summary's assumptions say
#: that the rates average contact episodes
CLOSED_CONTACT = 0.9
#: the entries of the last measurement row the summary reports
ROW_FIELDS = (
    "wear_depth_mean_m", "wear_depth_max_m", "wear_depth_mean_disc_m",
    "wear_depth_max_disc_m", "wear_depth_mean_pad_m", "wear_depth_max_pad_m",
    "broken_bonds", "broken_bonds_tensile", "broken_bonds_shear", "debris_particles",
    "debris_particles_disc", "debris_particles_pad", "worn_particles_disc",
    "worn_particles_pad", "debris_clusters",
    "debris_clusters_multi", "matrix_particles", "force_chains",
    "strong_force_chains", "weak_force_chains", "tensile_force_chains",
    "compressive_force_chains", "transfer_layer_thickness_m", "wear_range_disc_m",
    "wear_range_pad_m", "wear_range_ratio", "debris_max_vertical_displacement_m",
    "delaminated_particles_pad", "delaminated_depth_pad_m",
    "delaminated_particles_disc", "delaminated_depth_disc_m",
    "ejected_particles_pad", "ejected_depth_pad_m", "ejected_particles_disc",
    "ejected_depth_disc_m")


def particles_inside(iface: Interface) -> int:
    """Particles in the domain now: finite, above the disc's anchored (y-fixed) bottom
    layer, below the pressure wall, not ejected by the outlet."""
    p = iface.sim.p
    rmax = float(p.radius.max())
    y_lo = float(p.pos[iface.anchor_disc, 1].min()) - rmax
    y_hi = float(iface.wall.point[1]) + rmax
    inside = (np.isfinite(p.pos).all(axis=1) & (p.pos[:, 1] >= y_lo)
              & (p.pos[:, 1] <= y_hi) & (p.group != EJECTED))
    return int(inside.sum())


def _run_fields(setup: RunSetup, slid: float, t_sim: float) -> dict[str, Any]:
    """The load (kN, Pa), the speed (r/min, m/s), the distance slid (m) and the simulated
    time (s) with its mapping to braking time."""
    return {
        "condition": setup.condition,
        "load_kN": pressure_to_load(setup.pressure_Pa),
        "pressure_Pa": setup.pressure_Pa,
        "speed_rpm": speed_to_rpm(setup.speed_m_s),
        "sliding_speed_m_s": setup.speed_m_s,
        "simulated_sliding_distance_m": slid,
        "simulated_time_s": t_sim,
        "equivalent_braking_time_s": t_sim,
        "seed_braking_time_s": SEED_BRAKING_TIME_S,
        "fraction_of_seed_braking": t_sim / SEED_BRAKING_TIME_S,
        "time_mapping": "identity: every simulated second is one second of braking at the "
                        "condition's speed (no time or mass scaling)",
    }


def contact_after_run_in(rows: list[dict[str, float]]) -> dict[str, Any]:
    """The interface's contact measured on the samples (``rows``: the time series): the
    time (s) of the first sample that carries load through the interface (the pad
    applied), and the share of the samples after the run-in (sliding distance past a
    third of the run's, the steady rule's window) at which it carries load
    (``interface_force_N`` > 0), with their count; None where there is no such sample."""
    dist = np.array([r["sliding_distance_m"] for r in rows])
    load = np.array([r["interface_force_N"] for r in rows])
    on = np.flatnonzero(load > 0.0)
    late = dist > dist[-1] / 3.0 if dist.size else dist.astype(bool)
    n = int(np.count_nonzero(late))
    return {
        "first_contact_time_s": float(rows[on[0]]["time_s"]) if on.size else None,
        "contact_fraction_after_run_in": (float(np.count_nonzero(load[late] > 0.0)) / n
                                          if n else None),
        "contact_fraction_after_run_in_samples": n,
    }


def _rate_fields(loop: BrakingLoop) -> dict[str, Any]:
    """The wear rates (steady per distance m/m, second half in time m/s, run-in), the
    contact fraction, the ramps (s) and the extrapolated depth at 8 s (m)."""
    setup, rows, drive = loop.setup, loop.rows, loop.drive
    tt = np.array([r["time_s"] for r in rows])
    hh = np.array([r["wear_depth_mean_m"] for r in rows])
    rate, h8 = wear_extrapolation(tt, hh, SEED_BRAKING_TIME_S)
    st = steady_state(*wear_vs_distance(rows), setup.steady_tolerance, STEADY_CUTS)
    looks = max(drive.contact[0], 1.0)
    return {
        "steady_wear_rate_m_s": rate,
        # a rate is called steady only when the rule passed; else null, and why
        "wear_rate_steady_m_per_m": st["rate"] if st["steady"] else None,
        "wear_rate_steady_reason": steady_reason(st, setup.steady_tolerance),
        "wear_rate_last_two_thirds_m_per_m": st["rate"],
        "wear_rate_middle_third_m_per_m": st["rate_mid"],
        "wear_rate_last_third_m_per_m": st["rate_last"],
        "steady_reached": st["steady"],
        "steady_rule": f"least-squares wear-depth rate per sliding distance over the last "
                       f"third within +-{100 * setup.steady_tolerance:g}% of the middle "
                       "third's (positive), on the run and on the run cut to "
                       f"{', '.join(f'{f:.0%}' for f in STEADY_CUTS[1:])} of its distance; "
                       "steady rate = slope over the last two thirds; run-in = the first "
                       "third",
        "run_in_distance_m": st["run_in_distance"],
        "run_in_depth_m": st["run_in_depth"],
        "sliding_distance_cap_m": loop.cap_steps * loop.sim.dt * setup.speed_m_s,
        "contact_fraction": drive.contact[1] / looks,
        "contact_fraction_definition": f"fraction of steps (one look every {CONTACT_EVERY}) "
                                       "at which disc and pad particles (matrix or debris) "
                                       "are in contact with a positive normal force, i.e. "
                                       "the interface carries load",
        "interface_load_ratio_mean": drive.contact[2] / looks,
        **contact_after_run_in(rows),
        "ramp_s": setup.ramp_s,
        "speed_ramp_s": setup.speed_ramp_s,
        "wear_depth_mean_extrapolated_8s_m": h8,
    }


def backing_fields(loop: BrakingLoop) -> dict[str, Any]:
    """What stands for the pad's backing (the friction material and steel back plate the
    cell omits): the plate's mass per area (kg/m^2) against the assumed real back plate's
    (``PLATE_AREAL_MASS``), the distance ``p T^2 / (2 m)`` (m) that the real one would
    travel under the full pressure p over the run's time T (the most it could follow the
    wear), and, with the absorbing backing, the dashpots' impedances ``rho c_p`` and
    ``rho c_s`` (Pa s/m: the omitted friction material's compliance to waves, which it
    carries away without reflection)."""
    setup, iface = loop.setup, loop.iface
    area = iface.width * iface.disc.thickness
    t_run = loop.sim.time - loop.t0
    back = iface.backing
    return {
        "backing_plate_areal_mass_kg_m2": iface.stats["plate_mass_kg"] / area,
        "backing_real_plate_areal_mass_kg_m2": PLATE_AREAL_MASS,
        "backing_real_plate_travel_m": setup.pressure_Pa * t_run ** 2 / (2 * PLATE_AREAL_MASS),
        "backing_impedance_normal_Pa_s_m": (
            back.c_n * back.idx.size / area if back is not None else None),
        "backing_impedance_shear_Pa_s_m": (
            back.c_t * back.idx.size / area if back is not None else None),
    }


def _cell_fields(loop: BrakingLoop) -> dict[str, Any]:
    """The cell: particles and bonds, the plate (force N, pressure Pa, mass kg, travel
    m), the steps and time step (s), the geometry (m), the micro-parameters, the thermal
    boundary."""
    setup, iface, sim, drive = loop.setup, loop.iface, loop.sim, loop.drive
    return {
        "particles_initial": loop.n0,
        "particles_final": particles_inside(iface),
        "bonds_initial": iface.bonds.n_bonds,
        "target_force_N": iface.target_force,
        "backing": setup.backing,
        "plate_areal_mass_kg_m2": setup.plate_areal_mass,
        "plate_mass_kg": iface.stats["plate_mass_kg"],
        "plate_travel_m": loop.wall_y0 - float(iface.wall.point[1]),
        **backing_fields(loop),
        "mean_wall_force_N": drive.mean,
        "mean_wall_pressure_Pa": drive.mean / (iface.width * iface.disc.thickness),
        "mean_wall_pressure_ratio": drive.mean / iface.target_force,
        "steps": loop.done,
        "dt_s": sim.dt,
        "dt_limited_by": sim.dt_limit_by,
        "cell_width_m": iface.width,
        "disc_height_m": setup.geometry.disc_height,
        "pad_height_m": setup.geometry.pad_height,
        "roughness_amplitude_m": setup.geometry.amplitude,
        "roughness_modes": [setup.geometry.first_mode, setup.geometry.modes],
        "packing_fraction": iface.phi[DISC],
        "build_stats": iface.stats,
        "micro_parameters": {"disc": iface.disc.micro_dict(), "pad": iface.pad.micro_dict(),
                             "set": setup.micro},
        "thermal_curve": str(setup.thermal_curve) if setup.thermal_curve else None,
        "thermal_time_map": setup.thermal_time_map if setup.thermal_curve else None,
    }


def run_summary(loop: BrakingLoop) -> dict[str, Any]:
    """The summary of a finished (or worn-through) loop, after :meth:`BrakingLoop.finish`:
    the status, what was run, the last row's measurements, the rates, the cell, the wall
    times (s) and the assumptions with the outcome's notes."""
    last = loop.rows[-1]
    worn = worn_through(last, loop.floor)
    wall = loop.wall_times()
    summary: dict[str, Any] = {
        "status": "worn_through" if worn else "finished",
        "worn_through": worn,
        **_run_fields(loop.setup, loop.slid(), loop.sim.time - loop.t0),
        **{k: last[k] for k in ROW_FIELDS},
        # nan when resumed from a finished checkpoint older than the column
        **{k: last.get(k, float("nan")) for k in REMAINING},
        "worn_through_floor_m": loop.floor,
        "feed": loop.feed.summary() if loop.feed is not None else None,
        "outlet_length_m": loop.setup.outlet_length_m,
        **_rate_fields(loop),
        **breaks_by_place(loop.iface, loop.ref),
        **_cell_fields(loop),
        "wall_time_build_s": wall["build"],
        "wall_time_sliding_s": wall["sliding"],
        "wall_time_s": wall["total"],
        "assumptions": assumptions(loop.setup),
    }
    summary["assumptions"] += outcome_notes(summary)
    return summary


def stopped_summary(loop: BrakingLoop, err: RunStopped) -> dict[str, Any]:
    """The summary of a loop stopped early by ``err`` (an instability, a sweep's stop):
    the status ``stopped``, the reason, the steps done and planned, the simulated time
    (s) of the last row and the last checkpoint (None without one)."""
    setup, ck = loop.setup, loop.checkpoint
    return {
        "status": "stopped", "stopped_reason": str(err), "condition": setup.condition,
        "pressure_Pa": setup.pressure_Pa, "sliding_speed_m_s": setup.speed_m_s,
        "steps": loop.done, "steps_planned": loop.total_steps,
        "simulated_time_s": loop.rows[-1]["time_s"],
        "last_checkpoint": str(ck) if ck is not None and ck.is_file() else None}


def worn_through_message(summary: dict[str, Any], setup: RunSetup, where: str) -> str:
    """The message of a run stopped by a body worn through (``summary["worn_through"]``);
    ``where``: the outputs' folder as said in it ('' without one)."""
    worn = summary["worn_through"]
    return (f"{worn_text(worn)} = {setup.worn_through_diameters:g} particle diameters): "
            "the run stopped there, its outputs "
            f"are written{where}; allowed: a "
            f"thicker body ([geometry] {worn['body']}_height_m), a shorter run, or "
            "[run] worn_through_diameters = 0 to slide on through the anchored layer")


def _contact_note(cf: float) -> list[str]:
    """The note on an interface open for long spells (``contact_fraction`` ``cf`` below
    ``CLOSED_CONTACT``)."""
    if cf >= CLOSED_CONTACT:
        return []
    return [
        f"interface in contact {100 * cf:.0f} % of the sliding time (closed: >= "
        f"{100 * CLOSED_CONTACT:.0f} %): the pad flies between asperity impacts (the "
        "cell is narrower than the pad's load-sharing length), so the wear rates average "
        "contact episodes, not a closed sliding contact; wider cells ([geometry] "
        "width_m) close it (docs/braking.md)"]


def outcome_notes(summary: dict[str, Any]) -> list[str]:
    """What the run's own outcome means for its rates: a body worn through, an interface
    open for long spells (``contact_fraction`` < ``CLOSED_CONTACT``), a slab delaminated,
    a steady-state rule that did not pass."""
    notes = []
    worn = summary.get("worn_through")
    if worn:
        notes.append(
            f"{worn_text(worn)} of intact body outside its anchored layer): the run "
            "stopped there; every value is up to that point, and the cell no longer models "
            "the surface zone of a thick body (docs/braking.md 'Bodies worn through')")
    notes += _contact_note(summary["contact_fraction"])
    for body in ("pad", "disc"):
        if summary.get(f"delaminated_particles_{body}", 0) > 0:
            notes.append(
                f"the {body} cracked through parallel to its surface: a slab as wide as the "
                f"cell ({summary[f'delaminated_particles_{body}']:.0f} particles, "
                f"{1e6 * summary[f'delaminated_depth_{body}_m']:.1f} um of intact material) "
                "is detached but spans the periodic cell, so it is reported as delaminated, "
                "not as debris or wear (its size is the cell's; docs/braking.md "
                "'Measurements')")
    if not summary["steady_reached"]:
        notes.append(
            "steady-state rule not passed within the distance slid: "
            "wear_rate_steady_m_per_m is null (wear_rate_steady_reason says why); "
            "wear_rate_last_two_thirds_m_per_m is the slope over the last two thirds of a "
            "rate still changing (compare wear_rate_middle_third_m_per_m and "
            "wear_rate_last_third_m_per_m)" + (
                "" if summary["outlet_length_m"] > 0 else
                "; in the closed periodic cell the rate falls towards zero over ~10-16 mm as "
                "the debris layer takes up the sliding (no debris leaves the cell): the "
                "depth of a short run is a run-in depth (docs/braking.md 'Long slides'); "
                "[run] outlet_length_m lets debris leave"))
    return notes


def _model_assumptions(setup: RunSetup) -> list[str]:
    """The assumptions of every run: 2D cell, table 4 mapping, time mapping, pressure
    plate, boundary conditions, surfaces, wear depth."""
    return [
        "2D disks of unit thickness (1 m); forces per metre; pressure = wall force / "
        "(cell width x 1 m)",
        "load and speed from table 4 via the implied pad area 0.03939 m^2 and friction "
        "radius 0.375 m",
        "time mapping: identity (simulated time = braking time represented); the seed's 8 s "
        "is not reached; wear_depth_mean_extrapolated_8s_m extrapolates the steady wear "
        "rate (slope over the second half of the run) linearly in time = in sliding "
        "distance at constant speed; it is an extrapolation, not a simulation",
        "pressure wall: a pressure plate (engine 'boundary' servo, Lu (2018) eq 3.6), no "
        "damping, of mass " + (
            f"{setup.plate_areal_mass} kg/m^2 x W x t (the omitted pad and back plate: 15 mm "
            "Cu-PM + 6 mm steel assumed, the seed gives no sizes)"
            if setup.plate_areal_mass else
            f"{setup.wall_mass_ratio} x the cell's pad mass") +
        "; its mean force tends to the target by momentum balance. It stands for the "
        "pad's back plate: a light plate follows the cell's wear, which the real back "
        "plate (backing_real_plate_areal_mass_kg_m2) could not within the run "
        "(backing_real_plate_travel_m, against the wear depth): the run would become "
        "displacement-controlled and open",
        "disc: anchored bottom layer fixed in y and driven at -v in x, the rest of the disc "
        "starts at -v; pad: top layer " + (
            "tied to the rest of the pad by non-reflecting (Lysmer) dashpots, rho c_p "
            "relative to the plate in y and rho c_s in x (the support): the omitted "
            "friction material's compliance, as a medium that carries the impacts' waves "
            "away (backing_impedance_normal_Pa_s_m, backing_impedance_shear_Pa_s_m)"
            if setup.backing == "absorbing" else "held in x (support wall), free face in y"),
        "rough surfaces: independent random profiles (sine modes of wavelengths W/k, k = "
        f"{setup.geometry.first_mode}..{setup.geometry.modes}, amplitudes ~ U(0.3, 1)/k, "
        "max |h| = the amplitude) cut from one compacted block; pad lowered vertically to "
        "first contact",
        "wear depth = detached solid area / (packing fraction x width), pad (the seed "
        "analyses the pad); detached = not connected by intact bonds to an anchored layer",
    ]


def assumptions(setup: RunSetup) -> list[str]:
    """Every assumption behind the run's numbers: the model's, then those of its options
    (micro-parameters, outlet, feed, thermal boundary)."""
    a = _model_assumptions(setup)
    if setup.micro == "calibrated":
        a.append("micro-parameters: E_c and kratio from tribodem calibrate (docs/braking.md), "
                 "table 3 strengths, damping, friction")
    else:
        a.append("micro-parameters: the seed's table 3 values, uncalibrated in tribodem "
                 "(E ~ 88/79 GPa instead of 201/178 GPa)")
    if setup.outlet_length_m > 0:
        a.append(f"debris outlet: a debris component leaves the cell (ejected, counted as "
                 f"worn) once carried {1e6 * setup.outlet_length_m:g} um along the sliding "
                 "relative to the pad (the residence length: the contact plateau it crosses; "
                 "not given by the seed, whose cell is closed); docs/braking.md 'Debris "
                 "outlet'")
    else:
        a.append("closed cell (the seed's): no debris leaves; the third body accumulates")
    if setup.feed:
        a.append("feed: the bodies are cut from a block compacted periodic in x and y; "
                 "whenever a body's remaining thickness has fallen by one slab (3 mean "
                 "particle diameters) a slab of the block's continuation is added behind "
                 "its anchored layer, which moves to the slab's outer face (the surface "
                 "zone of a thick pad and disc; summary 'feed'; docs/braking.md 'Feed')")
    if setup.thermal_curve is None:
        a.append("no temperature boundary (the seed's figure 9 curve is not given in the "
                 "text; over microseconds any 8 s curve changes by ~1e-6 of its range)")
    return a
