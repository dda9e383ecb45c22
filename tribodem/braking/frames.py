"""What a braking run keeps of its particles for looking at: the figure frames (start, early,
end: positions, velocities, displacements, force chains) and the VTK snapshots with their
ParaView ``.pvd`` indexes."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tribodem.braking.measure import Reference, classify, force_chains
from tribodem.braking.model import DISC, Interface
from tribodem.io.vtk import has_lines, write_lines, write_points, write_pvd


def body_displacement(iface: Interface, ref: Reference, slid: float) -> np.ndarray:
    """Displacement (m, (n, 3)) in each body's frame: the disc's rigid sliding ``slid``
    (m, in -x) removed; x by minimum image."""
    p = iface.sim.p
    u = p.pos - ref.pos
    u[p.group == DISC, 0] += slid
    w = ref.width
    u[:, 0] -= w * np.rint(u[:, 0] / w)
    return u


def figure_frame(iface: Interface, ref: Reference, slid: float) -> dict[str, np.ndarray]:
    """The particles now, for the run's figures: positions (m), radii (m), velocities
    (m/s), displacements in the bodies' frames (m), bodies, detached flags, the force
    chains (pairs and normal forces, N) and the distance slid ``slid`` (m)."""
    p = iface.sim.p
    matrix, _ = classify(iface)
    ch = force_chains(iface)
    return {"pos": p.pos.copy(), "radius": p.radius.copy(), "vel": p.vel.copy(),
            "disp": body_displacement(iface, ref, slid), "group": p.group.copy(),
            "detached": ~matrix, "chain_i": ch["i"], "chain_j": ch["j"],
            "chain_f": ch["force"], "slid": np.array(slid)}


def write_snapshot(out: Path, iface: Interface, ref: Reference, slid: float, k: int,
                   t: float, entries: list[tuple[float, str]],
                   chain_entries: list[tuple[float, str]]) -> None:
    """VTK snapshot ``k`` at simulated time ``t`` (s) in folder ``out``: the particles
    (``particles_KKKK.vtu``) and the force chains (``chains_KKKK.vtu``: line cells between
    the particles' centres, with their normal force; none at a snapshot without any chain,
    such as the first one, before the plate loads the interface: a ``.vtu`` without cells
    could not be read back by meshio); each is added to its index (``entries``,
    ``chain_entries``) and the ``.pvd`` files rewritten."""
    p = iface.sim.p
    matrix, lab = classify(iface)
    name = f"particles_{k:04d}.vtu"
    write_points(out / name, p.pos, {
        "radius": p.radius, "velocity": p.vel, "displacement": body_displacement(iface, ref,
                                                                                 slid),
        "body": p.group, "detached": (~matrix).astype(np.int32), "component": lab})
    entries.append((t, name))
    write_pvd(out / "particles.pvd", entries)
    ch = force_chains(iface)
    f = ch["force"]
    lines = np.stack([ch["i"], ch["j"]], axis=1)
    if not has_lines(lines):
        return
    cname = f"chains_{k:04d}.vtu"
    write_lines(out / cname, p.pos, lines, {
        "normal_force": f, "strong": (np.abs(f) > np.abs(f).mean()).astype(np.int32)})
    chain_entries.append((t, cname))
    write_pvd(out / "chains.pvd", chain_entries)
