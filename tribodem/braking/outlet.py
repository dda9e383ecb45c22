"""Debris outlet: detached particles leave the interface after a residence length.

The periodic cell of Sha et al. (2022) is closed: every detached particle stays in it, the third
body grows until it separates the first bodies, and the wear rate falls towards zero
(docs/braking.md "Long slides"). In a brake, debris leaves the contact: it is carried
across a contact plateau and out at its trailing edge, into the gaps between plateaus or
the pad's grooves (the "ejection flow" of Berthier's tribological circuit; the seed
itself: "the other part leaves the wear layer of the surface with the brake disc
movement", "a higher relative motion speed causes the wear debris to leave the braking
interface faster").

Rule (one parameter, ``length`` m, the *residence length*): a debris component (a
detached component of the bond graph that does not span the cell, ``measure``) leaves
when the mean net x-displacement of its particles since they became debris reaches
``length`` -- it has been carried that far along the sliding direction relative to the
pad (the pad is held in x, so the lab frame is the pad's frame). Debris lodged in a pad pit
does not move and stays; debris carried by the disc leaves after ``length / v``. The
residence length is the contact length a particle crosses before it is out: the plateau
size of the pad face, 50-500 um in brake pads (Eriksson and Jacobson 2000), not a
quantity Sha et al. (2022) gives, so it is an explicit option (``[run] outlet_length_m``; 0 = the
closed cell of the seed).

A particle that leaves is *ejected*: its group becomes ``EJECTED``, its velocity and spin
are set to zero and fixed, and its component is moved rigidly (bonds unchanged) into a
store below the disc's anchored layer, packed shelf by shelf across the cell and
separated from every live particle by more than a contact distance, so it never
interacts again. The particle arrays keep their size (no index of a bond, a contact
history or a measurement changes); the ejected particles count as worn material
(``measure``). The check runs between engine calls, at most every quarter cell width of
disc travel, so that the minimum-image x-displacement is exact.
"""

from __future__ import annotations

import numpy as np

from tribodem.braking.measure import partition
from tribodem.braking.model import EJECTED, Interface
from tribodem.dem.state import FIX_ROTATION, FIX_TRANSLATION


class Outlet:
    """The outlet's state: per particle the net x-travel (m) since it became debris, the
    x at the last check, whether it was debris then; the store's shelf cursor."""

    def __init__(self, iface: Interface, length: float) -> None:
        if not length > 0:
            raise ValueError(f"outlet_length_m = {length!r}: must be > 0 m")
        n = iface.sim.p.n
        self.length = float(length)
        self.travel = np.zeros(n)
        self.last_x = iface.sim.p.pos[:, 0].copy()
        self.tracking = np.zeros(n, dtype=bool)
        p = iface.sim.p
        rmax = float(p.radius.max())
        self.gap = 0.5 * rmax  # between stored components and below the anchored layer
        y0 = float(p.pos[iface.anchor_disc, 1].min()) - 2.0 * rmax - self.gap
        # [x cursor, top of the current shelf, height of the current shelf] (m)
        self.shelf = np.array([0.0, y0, 0.0])

    def state(self) -> dict[str, np.ndarray]:
        """Arrays for the run's checkpoint."""
        return {"outlet_travel": self.travel, "outlet_last_x": self.last_x,
                "outlet_tracking": self.tracking, "outlet_shelf": self.shelf}

    def set_state(self, a: dict[str, np.ndarray]) -> None:
        """Restore what ``state`` returned."""
        self.travel = np.array(a["outlet_travel"], dtype=np.float64)
        self.last_x = np.array(a["outlet_last_x"], dtype=np.float64)
        self.tracking = np.array(a["outlet_tracking"], dtype=bool)
        self.shelf = np.array(a["outlet_shelf"], dtype=np.float64)

    def grow(self, iface: Interface) -> None:
        """Particles were appended (``braking.feed``): they are body, not tracked."""
        n, k = iface.sim.p.n, self.travel.size
        self.travel = np.concatenate([self.travel, np.zeros(n - k)])
        self.last_x = np.concatenate([self.last_x, iface.sim.p.pos[k:, 0]])
        self.tracking = np.concatenate([self.tracking, np.zeros(n - k, dtype=bool)])

    def check(self, iface: Interface) -> int:
        """Update the travel of the debris and eject the components that went
        ``length``; returns the number of particles ejected now."""
        p = iface.sim.p
        w = iface.width
        x = p.pos[:, 0]
        _, _, debris, _, lab = partition(iface)
        d = x - self.last_x
        d -= w * np.rint(d / w)
        keep = debris & self.tracking
        self.travel = np.where(keep, self.travel + d, 0.0)
        self.tracking = debris
        self.last_x = x.copy()
        if not debris.any():
            return 0
        comp = lab[debris]
        idx = np.flatnonzero(debris)
        cnt = np.bincount(comp)
        mean = np.bincount(comp, weights=self.travel[idx]) / np.maximum(cnt, 1)
        out = np.flatnonzero(np.abs(mean) >= self.length)
        ejected = 0
        for c in out:
            members = idx[comp == c]
            self._store(iface, members)
            ejected += members.size
        return ejected

    def _store(self, iface: Interface, members: np.ndarray) -> None:
        """Move one component rigidly into the store and freeze it."""
        p = iface.sim.p
        w = iface.width
        r = p.radius[members]
        xy = p.pos[members, :2].copy()
        dx = xy[:, 0] - xy[0, 0]
        xy[:, 0] = xy[0, 0] + dx - w * np.rint(dx / w)  # unwrapped round its first member
        lo = xy - r[:, None]
        hi = xy + r[:, None]
        bw, bh = float(hi[:, 0].max() - lo[:, 0].min()), float(hi[:, 1].max() - lo[:, 1].min())
        cur, top, height = self.shelf
        if cur > 0.0 and cur + bw > w - self.gap:  # next shelf, below
            cur, top, height = 0.0, top - height - self.gap, 0.0
        shift_x = cur - float(lo[:, 0].min())
        shift_y = top - float(hi[:, 1].max())
        p.pos[members, 0] = np.mod(xy[:, 0] + shift_x, w)
        p.pos[members, 1] = xy[:, 1] + shift_y
        p.vel[members] = 0.0
        p.omega[members] = 0.0
        p.fixed[members] |= np.uint8(FIX_TRANSLATION | FIX_ROTATION)
        p.group[members] = EJECTED  # the next check stops tracking them (not debris)
        self.shelf = np.array([cur + bw + self.gap, top, max(height, bh)])
