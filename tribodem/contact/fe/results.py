"""Readers of ccx results: the ``.dat`` text file and nodal blocks of the ``.frd`` file.

* ``.dat`` (``*NODE PRINT`` / ``*EL PRINT`` of :mod:`tribodem.contact.fe.deck`), one block
  per output time (ccx total time: seating (0, 1], normal load (1, 2], tangential cycle
  (2, 6]): total reaction force of the flat's bottom (= the contact force on the pad:
  ``P = fy``, ``Q = fx``), displacements of REF and of both contact faces, integration-point
  stresses (and PEEQ).
* Contact tractions: ccx 2.20's ``*CONTACT PRINT`` of surface-to-surface contact lists
  integration points without node or position, and its nodal ``CPRESS`` in the ``.frd`` was
  5 % low under load and wrong once sliding (measured), so the contact force on each surface
  node of the pad is recovered as the sum of the nodal forces f = int B^T sigma dA of its
  elements (exact for the small-strain solution up to the 7 printed digits), divided by the
  node's tributary length. Relative tangential displacement: the pad node's x displacement
  minus the flat's at the same undeformed x (linear interpolation).
* ``.frd``: any nodal block (``DISP``, ``STRESS``, ``PE``, ...) for post-processing.

Stresses in Pa, displacements in m, forces in N per metre of thickness (plane strain).
Plane-strain elements are expanded by ccx into one layer of bricks: integration points
``k`` and ``k + 4`` of a ``CPE4`` lie at the same in-plane point and are averaged.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from tribodem.contact.fe.mesh import Mesh

_HEADER = re.compile(r"^\s*(?P<what>[a-z][a-z .]*?)\s*\((?P<cols>[^)]*)\)\s*for\s+"
                     r"(?:set\s+(?P<set>\S+)|all contact elements)\s+and time\s+"
                     r"(?P<time>\S+)")


@dataclass
class DatBlock:
    """One ``.dat`` block: kind (``total force``, ``displacements``, ``stresses``, ...),
    set name, total time and the numeric rows (integer ids as floats)."""

    kind: str
    set_name: str
    time: float
    rows: NDArray[np.float64]


def read_dat(path: str | Path) -> list[DatBlock]:
    """All blocks of a ccx ``.dat`` file in file order."""
    return _dat_blocks(Path(path).read_text().splitlines())


_HEADER_TIME = re.compile(r"^[ \t]*[a-z][^\n]*\)\s*for\s+(?:set\s+\S+|all contact elements)\s+"
                          r"and time\s+(\S+)", re.MULTILINE)


def read_dat_last(path: str | Path) -> tuple[float | None, list[DatBlock]]:
    """(the last output time, its blocks) of a ccx ``.dat`` file: the headers are found in
    the text and only the blocks from the first one of that time on are parsed (a job's
    ``.dat`` holds tens of output times). (None, []) for a file without blocks."""
    text = Path(path).read_text()
    heads = [(m.start(), float(m.group(1))) for m in _HEADER_TIME.finditer(text)]
    if not heads:
        return None, []
    last = max(t for _, t in heads)
    start = next(pos for pos, t in heads if t == last)
    blocks = [b for b in _dat_blocks(text[start:].splitlines()) if b.time == last]
    return last, blocks


def _dat_blocks(lines: list[str]) -> list[DatBlock]:
    """The blocks of the lines of a ``.dat`` file (see :func:`read_dat`)."""
    blocks: list[DatBlock] = []
    cur: DatBlock | None = None
    buf: list[list[float]] = []

    def close() -> None:
        if cur is not None:
            cur.rows = np.asarray(buf, dtype=float).reshape(len(buf), -1) if buf else \
                np.zeros((0, 0))
            blocks.append(cur)

    for line in lines:
        m = _HEADER.match(line)
        if m:
            close()
            cur = DatBlock(m["what"].strip(), m["set"] or "", float(m["time"]), np.zeros(0))
            buf = []
            continue
        parts = line.split()
        if cur is not None and parts:
            try:
                buf.append([float(p) for p in parts])
            except ValueError:
                close()
                cur, buf = None, []
    close()
    return blocks


@dataclass
class FrdBlock:
    """One nodal result block of an ``.frd`` file."""

    name: str  #: e.g. ``DISP``, ``STRESS``, ``CONTACT``, ``PE``
    time: float  #: total time
    step: int  #: step number
    components: list[str]
    nodes: NDArray[np.int64]  #: node ids [n]
    values: NDArray[np.float64]  #: [n, n_components]


def _frd_floats(line: str, n: int) -> list[float]:
    n = min(n, (len(line.rstrip()) - 13) // 12)
    return [float(line[13 + 12 * k: 25 + 12 * k]) for k in range(n)]


def read_frd(path: str | Path, names: tuple[str, ...] | None = None) -> list[FrdBlock]:
    """Nodal result blocks of an ASCII ``.frd`` file (``names`` filters them)."""
    out: list[FrdBlock] = []
    lines = Path(path).read_text().splitlines()
    i, time, step = 0, 0.0, 0
    while i < len(lines):
        ln = lines[i]
        if ln.startswith("  100C"):
            time = float(ln[12:24])
            step = int(ln[59:64]) if len(ln) >= 64 and ln[59:64].strip() else step
            name = lines[i + 1][5:13].strip()
            ncomp = int(lines[i + 1][13:18])
            comps, i = [], i + 2
            while lines[i].startswith(" -5"):
                comps.append(lines[i][5:13].strip())
                i += 1
            want = names is None or name in names
            ids: list[int] = []
            vals: list[list[float]] = []
            while not lines[i].startswith(" -3"):
                if want and lines[i].startswith(" -1"):
                    ids.append(int(lines[i][3:13]))
                    vals.append(_frd_floats(lines[i], min(ncomp, 6)))
                i += 1
            if want:
                out.append(FrdBlock(name, time, step, comps[:len(vals[0]) if vals else 0],
                                    np.asarray(ids, dtype=np.int64),
                                    np.asarray(vals, dtype=float)))
        i += 1
    return out


@dataclass
class ContactState:
    """Contact tractions along the pad's surface at one increment, nodes sorted by x."""

    time: float  #: ccx total time
    x: NDArray[np.float64]  #: undeformed x of the pad's surface nodes, m
    pressure: NDArray[np.float64]  #: contact pressure on the pad, Pa (nodal force / length)
    shear: NDArray[np.float64]  #: shear traction on the pad along x, Pa
    #: accumulated relative tangential displacement of the pad's node with respect to the
    #: flat's material point initially under it, m (its change between increments is the slip)
    slip: NDArray[np.float64]


@dataclass
class FEResults:
    """Per-increment results of one run (times are ccx total times: seating (0, 1], normal
    load (1, 2], tangential cycle (2, 6])."""

    times: NDArray[np.float64]  #: increment times
    normal_force: NDArray[np.float64]  #: P on the pad (flat bottom reaction fy), N/m
    tangential_force: NDArray[np.float64]  #: Q on the pad along x (= bottom reaction fx), N/m
    ref_displacement: NDArray[np.float64]  #: REF (ux, uy), m, [n, 2]
    contact: list[ContactState] = field(default_factory=list)
    dat: list[DatBlock] = field(default_factory=list)

    def at(self, time: float) -> int:
        """Index of the increment nearest to total time ``time``."""
        return int(np.argmin(np.abs(self.times - time)))

    def _block(self, kind: str, set_name: str, time: float) -> DatBlock:
        blocks = [b for b in self.dat if b.kind == kind and b.set_name == set_name]
        if not blocks:
            raise ValueError(f"no '{kind}' output for set {set_name} in the .dat")
        return min(blocks, key=lambda bb: abs(bb.time - time))

    def ip_stress(self, time: float, set_name: str = "FINE") -> tuple[NDArray[np.int64],
                                                                       NDArray[np.float64]]:
        """Integration-point stresses at ``time``: element ids [m] and per in-plane point
        (sxx, syy, szz, sxy) in Pa, [m, 4, 4] (thickness pairs averaged)."""
        rows = self._block("stresses", set_name, time).rows
        elems = rows[:, 0].astype(np.int64).reshape(-1, 8)[:, 0]
        return elems, rows[:, 2:6].reshape(-1, 2, 4, 4).mean(axis=1)

    def peeq(self, time: float, set_name: str = "FINE") -> tuple[NDArray[np.int64],
                                                                 NDArray[np.float64]]:
        """Equivalent plastic strain per element and in-plane point at ``time``, [m, 4]."""
        rows = self._block("equivalent plastic strain", set_name, time).rows
        elems = rows[:, 0].astype(np.int64).reshape(-1, 8)[:, 0]
        return elems, rows[:, 2].reshape(-1, 2, 4).mean(axis=1)


def contact_forces(mesh: Mesh, elems: NDArray[np.int64], stress: NDArray[np.float64],
                   nodes: NDArray[np.int64]) -> NDArray[np.float64]:
    """External (contact) force on each of ``nodes`` (1-based), N/m, [n, 2], from the
    integration-point stresses of the elements ``elems`` that hold every element around them."""
    conn = mesh.elements[elems - 1]
    f = internal_forces(mesh.nodes[conn], stress)
    total = np.zeros((mesh.n_nodes, 2))
    np.add.at(total, conn, f)
    return total[nodes - 1]


def tributary_length(x: NDArray[np.float64]) -> NDArray[np.float64]:
    """Half the distance between each point's neighbours along a sorted line, m."""
    ext = np.concatenate([[x[0]], x, [x[-1]]])
    return 0.5 * (ext[2:] - ext[:-2])


def read_results(job: str | Path, mesh: Mesh) -> FEResults:
    """Read ``<job>.dat`` written by a deck of :func:`tribodem.contact.fe.deck.write_deck`."""
    dat = read_dat(Path(job).with_suffix(".dat"))
    forces = [b for b in dat if b.kind == "total force"]
    disp = {(b.set_name, b.time): b.rows for b in dat if b.kind == "displacements"}
    times = np.array([b.time for b in forces])
    fxy = np.array([b.rows[0, :2] for b in forces]).reshape(-1, 2)
    uref = np.array([disp[("REF", t)][0, 1:3] for t in times]).reshape(-1, 2)
    res = FEResults(times=times, normal_force=fxy[:, 1], tangential_force=fxy[:, 0],
                    ref_displacement=uref, dat=dat)
    ubot = mesh.node_sets["UBOT"]
    xs = mesh.nodes[ubot - 1, 0]
    order = np.argsort(xs)
    ubot, xs = ubot[order], xs[order]
    length = tributary_length(xs)
    ltop = mesh.node_sets["LTOP"]
    xl = mesh.nodes[ltop - 1, 0]
    lorder = np.argsort(xl)
    for t in times:
        elems, s = res.ip_stress(t, "UCONT")
        f = contact_forces(mesh, elems, s, ubot)
        up = disp[("UBOT", t)]
        lo = disp[("LTOP", t)]
        u_up = _nodal(up, ubot)
        u_lo = np.interp(xs, xl[lorder], _nodal(lo, ltop)[lorder])
        res.contact.append(ContactState(time=float(t), x=xs, pressure=f[:, 1] / length,
                                        shear=f[:, 0] / length, slip=u_up - u_lo))
    return res


def _nodal(rows: NDArray[np.float64], ids: NDArray[np.int64]) -> NDArray[np.float64]:
    """x displacement of nodes ``ids`` from ``displacements`` rows (id, ux, uy, uz)."""
    lookup = {int(n): k for k, n in enumerate(rows[:, 0])}
    return np.array([rows[lookup[int(n)], 1] for n in ids])

_GP = 1.0 / np.sqrt(3.0)
#: in-plane (xi, eta) of the first four integration points of an expanded CPE4 (ccx order)
GAUSS_2X2 = np.array([[-_GP, -_GP], [_GP, -_GP], [-_GP, _GP], [_GP, _GP]])


def _shape_grad(xi: float, eta: float) -> NDArray[np.float64]:
    """d N_i / d(xi, eta) of the bilinear quadrilateral, [4, 2]."""
    return 0.25 * np.array([[-(1 - eta), -(1 - xi)], [(1 - eta), -(1 + xi)],
                            [(1 + eta), (1 + xi)], [-(1 + eta), (1 - xi)]])


def ip_coordinates(xy: NDArray[np.float64]) -> NDArray[np.float64]:
    """In-plane coordinates of the 2x2 integration points of quads ``xy`` [m, 4, 2] -> [m, 4, 2]."""
    out = np.empty_like(xy)
    for k, (xi, eta) in enumerate(GAUSS_2X2):
        n = 0.25 * np.array([(1 - xi) * (1 - eta), (1 + xi) * (1 - eta),
                             (1 + xi) * (1 + eta), (1 - xi) * (1 + eta)])
        out[:, k] = np.einsum("i,mij->mj", n, xy)
    return out


def internal_forces(xy: NDArray[np.float64], stress: NDArray[np.float64],
                    thickness: float = 1.0) -> NDArray[np.float64]:
    """Element nodal forces f = sum_gp B^T sigma det(J) w t (N; small strain, so exact for the
    linear-geometry ccx solution) of quads ``xy`` [m, 4, 2] with integration-point stresses
    ``stress`` (sxx, syy, szz, sxy) [m, 4, 4] -> [m, 4, 2]. At a free surface node the sum
    over its elements is minus the external (contact) force on it."""
    f = np.zeros_like(xy)
    for k, (xi, eta) in enumerate(GAUSS_2X2):
        dn = _shape_grad(xi, eta)  # [4, 2]
        jac = np.einsum("ia,mib->mab", dn, xy)  # J[a, b] = d x_b / d xi_a
        det = jac[:, 0, 0] * jac[:, 1, 1] - jac[:, 0, 1] * jac[:, 1, 0]
        inv = np.linalg.inv(jac)  # [m, 2, 2]
        dndx = np.einsum("mba,ia->mib", inv, dn)  # d N_i / d x_b  (J^-1 maps)
        sxx, syy, sxy = stress[:, k, 0], stress[:, k, 1], stress[:, k, 3]
        w = (det * thickness)[:, None]
        f[..., 0] += w * (dndx[..., 0] * sxx[:, None] + dndx[..., 1] * sxy[:, None])
        f[..., 1] += w * (dndx[..., 0] * sxy[:, None] + dndx[..., 1] * syy[:, None])
    return f
