"""Measurements of the braking interface (Sha et al. (2022) sections 3.4 and 5), all frame-free.

Definitions (reference state = the loaded interface at the start of sliding):

- **matrix / debris**: the graph of intact bonds is split into connected components
  (scipy.sparse.csgraph); a component holding an anchored particle (disc bottom layer,
  pad top layer) is the body's *matrix*; every other particle is *detached*: *debris*,
  or part of a delaminated layer (below). Each particle is exactly one of the three.
  *Debris clusters* are the debris components
  (a lone particle is a cluster of one; ``debris_clusters_multi`` counts those of >= 2).
  Bonds never re-form, so detachment is irreversible.
- **delaminated layer**: a detached component that spans the periodic cell (its
  particles' x-extents leave no gap as wide as one particle diameter): a crack that ran
  parallel to the surface through the whole cell and freed a slab as wide as the cell.
  Such a slab cannot leave the interface; it carries the load between the bodies and is
  worn on from its free face. Its size is set by the cell width, not by the wear process
  (in a real pad a subsurface crack meets the pad's edge or arrests), so it is reported
  on its own (``delaminated_particles_*``, ``delaminated_depth_*_m``) and counted neither
  as debris nor as wear; once it breaks into pieces narrower than the cell they are
  debris again. Cells whose bodies never crack through are unaffected.
- **ejected**: particles that left the interface through the debris outlet
  (``outlet``, ``[run] outlet_length_m``; none in the closed cell of the seed): worn
  material, never debris again; ``ejected_depth_*_m`` is their solid area over ``phi W``.
- **worn** particles: debris particles displaced by more than one mean radius from
  their place in their body's frame (the disc's rigid sliding removed): material that
  left the surface, not a cracked grain still in its seat; and every ejected particle.
- **wear depth, mean** (per body): the solid area of the body's worn particles over
  the cell width and the packing fraction, ``h = sum(pi r^2) / (phi W)`` (m): the
  thickness of intact material removed, the area form of "vertical displacement of the
  detached material" (section 3.4). The seed's pad value is ``wear_depth_mean_m``.
- **remaining thickness** (per body): the solid area of the body's matrix and
  delaminated-layer particles outside its anchored layer over ``phi W`` (m): the mean
  thickness of body left between the anchored boundary layer and the sliding interface
  (a delaminated slab still stands between them and carries the load). A run stops
  when a body is worn through (``tribodem.braking.setup.WORN_THROUGH``).
- **wear depth, max** (per body): the deepest initial position of a worn particle's
  far edge below the body's initial mean surface (disc: ``s0 - (y0 - r)``; pad:
  ``(y0 + r) - s0``), clipped at 0; ``s0`` = mean over x-bins (2 r_max wide) of the
  outermost particle surface of the body.
- **wear range** (per body): deepest initial position (centre depth below ``s0`` of the
  two ends) of a broken bond; ``wear_range_ratio`` = disc / pad (seed: 1:3).
- **force chains**: every particle pair carrying force: active contacts plus intact
  bonds, summed per pair (PFC's contact + parallel bond); normal force + = compression;
  *strong* = |F| above the mean |F| (section 3.1, figures 5, 17); *tensile* F < 0.
- **transfer layer thickness**: debris solid area over ``phi W`` (m): the equivalent
  thickness of the third-body layer between the matrices.
- **debris vertical displacement**: max |y - y0| of debris particles (m), the quantity of
  the seed's figures 11-12 displacement maps.
- **broken bonds by place** (summary only, :func:`breaks_by_place`): per body and mode, in
  the surface layer (two mean particle diameters under the body's local surface at the
  start) or in the bulk; the seed describes the pad failing in its surface layer.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from tribodem.braking.model import DISC, EJECTED, PAD, Interface
from tribodem.dem.bonds import INTACT, SHEAR, TENSILE

#: the measured columns added after checkpoints were first written: the rows of an older
#: checkpoint hold no value of them (nan there, not zero)
REMAINING = ("remaining_thickness_disc_m", "remaining_thickness_pad_m")


@dataclass
class Reference:
    """The reference state of the measurements (start of sliding)."""

    pos: np.ndarray
    radius: np.ndarray
    group: np.ndarray
    surface: dict[int, float]
    phi: dict[int, float]
    width: float

    def depth(self, idx: np.ndarray, edge: bool) -> np.ndarray:
        """Initial depth (m) of particles ``idx`` below their body's mean surface: of the
        far edge (``edge``) or the centre."""
        y = self.pos[idx, 1]
        r = self.radius[idx] if edge else 0.0
        g = self.group[idx]
        return np.where(g == DISC, self.surface[DISC] - (y - r), (y + r) - self.surface[PAD])


def surface_profile(pos: np.ndarray, radius: np.ndarray, group: np.ndarray, body: int,
                    width: float) -> np.ndarray:
    """The body's outermost particle surface (m) in each of the cell's x-bins (2 r_max
    wide; the disc's highest, the pad's lowest particle edge; +-inf in a bin it does not
    reach)."""
    sel = group == body
    nb = max(1, int(width // (2.0 * float(radius.max()))))
    b = np.minimum((np.mod(pos[sel, 0], width) / width * nb).astype(int), nb - 1)
    if body == DISC:
        top = np.full(nb, -np.inf)
        np.maximum.at(top, b, pos[sel, 1] + radius[sel])
    else:
        top = np.full(nb, np.inf)
        np.minimum.at(top, b, pos[sel, 1] - radius[sel])
    return top


def mean_surface(pos: np.ndarray, radius: np.ndarray, group: np.ndarray, body: int,
                 width: float) -> float:
    """Mean over x-bins (2 r_max wide) of the body's outermost particle surface (m)."""
    top = surface_profile(pos, radius, group, body, width)
    return float(top[np.isfinite(top)].mean())


#: the surface layer of ``breaks_by_place``: bonds starting within this many mean particle
#: diameters of their body's local surface
SURFACE_LAYER_DIAMETERS = 2.0


def breaks_by_place(iface: Interface, ref: Reference,
                    layer_diameters: float = SURFACE_LAYER_DIAMETERS) -> dict[str, Any]:
    """Broken bonds by body, mode (tensile, shear) and place: the **surface layer** (the
    bond's centre started less than ``layer_diameters`` mean particle diameters below its
    body's local surface: the outermost particle edge of its 2 r_max wide x-bin at the
    start of sliding, so asperities and pit floors alike) or the **bulk** (deeper).
    Keys ``broken_bonds_{pad,disc}_{surface,bulk}_{tensile,shear}`` (counts) and
    ``broken_bonds_surface_layer_m`` (the layer's thickness, m)."""
    b = iface.bonds
    w = ref.width
    layer = layer_diameters * 2.0 * float(ref.radius.mean())
    out: dict[str, Any] = {"broken_bonds_surface_layer_m": layer}
    pi, pj = ref.pos[b.i], ref.pos[b.j]
    dx = pj[:, 0] - pi[:, 0]
    dx -= w * np.rint(dx / w)
    xc = np.mod(pi[:, 0] + 0.5 * dx, w)
    yc = 0.5 * (pi[:, 1] + pj[:, 1])
    for body, name in ((DISC, "disc"), (PAD, "pad")):
        top = surface_profile(ref.pos, ref.radius, ref.group, body, w)
        top = np.where(np.isfinite(top), top, ref.surface[body])
        nbin = top.size
        sel = (ref.group[b.i] == body) & (b.mode != INTACT)
        k = np.minimum((xc[sel] / w * nbin).astype(int), nbin - 1)
        depth = top[k] - yc[sel] if body == DISC else yc[sel] - top[k]
        surf = depth < layer
        for mode, code in (("tensile", TENSILE), ("shear", SHEAR)):
            m = b.mode[sel] == code
            out[f"broken_bonds_{name}_surface_{mode}"] = float(np.count_nonzero(m & surf))
            out[f"broken_bonds_{name}_bulk_{mode}"] = float(np.count_nonzero(m & ~surf))
    return out


def reference(iface: Interface) -> Reference:
    """Take the reference state now (call at the start of sliding)."""
    p = iface.sim.p
    w = iface.width
    return Reference(pos=p.pos.copy(), radius=p.radius.copy(), group=p.group.copy(),
                     surface={b: mean_surface(p.pos, p.radius, p.group, b, w)
                              for b in (DISC, PAD)},
                     phi=dict(iface.phi), width=w)


def classify(iface: Interface) -> tuple[np.ndarray, np.ndarray]:
    """(matrix mask, component label per particle) from the intact-bond graph."""
    n = iface.sim.p.n
    b = iface.bonds
    ok = b.intact
    from scipy.sparse import coo_matrix  # here: scipy.sparse takes 0.25 s to import
    from scipy.sparse.csgraph import connected_components

    g = coo_matrix((np.ones(int(ok.sum())), (b.i[ok], b.j[ok])), shape=(n, n))
    _, lab = connected_components(g, directed=False)
    anchored = np.zeros(lab.max() + 1, dtype=bool)
    anchored[lab[iface.anchors]] = True
    return anchored[lab], lab


def spanning(x: np.ndarray, radius: np.ndarray, lab: np.ndarray, width: float,
             candidates: np.ndarray) -> np.ndarray:
    """Mask over component labels: True where the component (one of ``candidates``)
    spans the periodic cell of width ``width`` (m): the union of its particles' x-extents
    ``[x - r, x + r]`` leaves no gap (round the cell) as wide as one of its mean
    particle diameters."""
    out = np.zeros(int(lab.max()) + 1, dtype=bool)
    for c in candidates:
        m = lab == c
        lo = np.mod(x[m] - radius[m], width)
        o = np.argsort(lo)
        lo = lo[o]
        hi = lo + 2.0 * radius[m][o]
        n = lo.size
        # two turns round the cell, so an interval that wraps past x = W covers the start
        lo2, hi2 = np.concatenate([lo, lo + width]), np.concatenate([hi, hi + width])
        reach = np.maximum.accumulate(hi2)  # right end of the union of intervals 0..k
        gaps = lo2[n:] - reach[n - 1:2 * n - 1]  # before each start of the second turn
        out[c] = gaps.max() < 2.0 * float(radius[m].mean())
    return out


def layers(iface: Interface, matrix: np.ndarray, lab: np.ndarray) -> np.ndarray:
    """Mask of the particles in a delaminated layer (module docstring): detached
    components spanning the periodic cell."""
    p = iface.sim.p
    w = iface.width
    sizes = np.bincount(lab[~matrix], minlength=int(lab.max()) + 1)
    # fewer particles than this cannot span the cell with gaps under one diameter
    cand = np.flatnonzero(sizes >= w / (4.0 * float(p.radius.max())))
    return spanning(p.pos[:, 0], p.radius, lab, w, cand)[lab] & ~matrix


def partition(iface: Interface) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                                         np.ndarray]:
    """Each particle's part now (module docstring): masks ``matrix``, ``layer``
    (delaminated), ``debris``, ``gone`` (ejected) and the component label per particle."""
    matrix, lab = classify(iface)
    gone = iface.sim.p.group == EJECTED
    layer = layers(iface, matrix | gone, lab) & ~gone
    return matrix, layer, ~matrix & ~layer & ~gone, gone, lab


def force_chains(iface: Interface) -> dict[str, np.ndarray]:
    """Pairs carrying force (contacts + intact bonds, summed per pair; ejected particles
    left out): i, j, normal force (N, + compression)."""
    sim = iface.sim
    n = sim.p.n
    c = sim.contacts()
    b = iface.bonds
    gone = sim.p.group == EJECTED
    ok = b.intact & ~gone[b.i]  # an ejected component keeps its bonds, out of the cell
    i = np.concatenate([c["i"], b.i[ok]]).astype(np.int64)
    j = np.concatenate([c["j"], b.j[ok]]).astype(np.int64)
    f = np.concatenate([c["normal_force"], b.fn[ok]])
    lo, hi = np.minimum(i, j), np.maximum(i, j)
    key, inv = np.unique(lo * n + hi, return_inverse=True)
    fs = np.bincount(inv, weights=f, minlength=key.size)
    keep = fs != 0.0
    return {"i": (key // n)[keep], "j": (key % n)[keep], "force": fs[keep]}


def measure(iface: Interface, ref: Reference, slid: float) -> dict[str, float]:
    """All scalar measurements now (see the module docstring); ``slid``: the disc's
    sliding distance since the reference (m). SI units."""
    p = iface.sim.p
    matrix, layer, debris, gone, lab = partition(iface)
    u = p.pos - ref.pos
    u[ref.group == DISC, 0] += slid
    u[:, 0] -= ref.width * np.rint(u[:, 0] / ref.width)
    worn = (debris & (np.linalg.norm(u, axis=1) > float(ref.radius.mean()))) | gone
    out: dict[str, float] = {}
    area = np.pi * ref.radius**2
    w = ref.width
    intact = (matrix | layer) & ~iface.anchors
    for body, name in ((DISC, "disc"), (PAD, "pad")):
        d = worn & (ref.group == body)
        out[f"worn_particles_{name}"] = float(d.sum())
        out[f"debris_particles_{name}"] = float((debris & (ref.group == body)).sum())
        ej = gone & (ref.group == body)
        out[f"ejected_particles_{name}"] = float(ej.sum())
        out[f"ejected_depth_{name}_m"] = float(area[ej].sum() / (ref.phi[body] * w))
        lay = layer & (ref.group == body)
        out[f"delaminated_particles_{name}"] = float(lay.sum())
        out[f"delaminated_depth_{name}_m"] = float(area[lay].sum() / (ref.phi[body] * w))
        out[f"wear_depth_mean_{name}_m"] = float(area[d].sum() / (ref.phi[body] * w))
        own = intact & (ref.group == body)
        out[f"remaining_thickness_{name}_m"] = float(area[own].sum() / (ref.phi[body] * w))
        dep = ref.depth(np.flatnonzero(d), edge=True)
        out[f"wear_depth_max_{name}_m"] = float(max(0.0, dep.max(initial=0.0)))
    b = iface.bonds
    broken = ~b.intact
    for body, name in ((DISC, "disc"), (PAD, "pad")):
        sel = broken & (ref.group[b.i] == body)
        dep = 0.5 * (ref.depth(b.i[sel], edge=False) + ref.depth(b.j[sel], edge=False))
        out[f"wear_range_{name}_m"] = float(max(0.0, dep.max(initial=0.0)))
    out["wear_range_ratio"] = (out["wear_range_disc_m"] / out["wear_range_pad_m"]
                               if out["wear_range_pad_m"] > 0 else float("nan"))
    out["wear_depth_mean_m"] = out["wear_depth_mean_pad_m"]
    out["wear_depth_max_m"] = out["wear_depth_max_pad_m"]
    out["broken_bonds"] = float(b.broken_count())
    out["broken_bonds_tensile"] = float(b.broken_count("tensile"))
    out["broken_bonds_shear"] = float(b.broken_count("shear"))
    out["debris_particles"] = float(debris.sum())
    out["matrix_particles"] = float(matrix.sum())
    dl = lab[debris]
    sizes = np.bincount(dl) if dl.size else np.zeros(0, dtype=int)
    out["debris_clusters"] = float(np.count_nonzero(sizes))
    out["debris_clusters_multi"] = float(np.count_nonzero(sizes >= 2))
    phi_m = 0.5 * (ref.phi[DISC] + ref.phi[PAD])
    out["transfer_layer_thickness_m"] = float(area[debris].sum() / (phi_m * w))
    out["debris_max_vertical_displacement_m"] = float(
        np.abs(p.pos[debris, 1] - ref.pos[debris, 1]).max(initial=0.0))
    ch = force_chains(iface)
    f = ch["force"]
    mag = np.abs(f)
    out["force_chains"] = float(f.size)
    out["strong_force_chains"] = float(np.count_nonzero(mag > mag.mean())) if f.size else 0.0
    out["weak_force_chains"] = out["force_chains"] - out["strong_force_chains"]
    out["tensile_force_chains"] = float(np.count_nonzero(f < 0))
    out["compressive_force_chains"] = float(np.count_nonzero(f > 0))
    return out
