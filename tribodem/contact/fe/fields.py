"""The finite-element fields of a run for ParaView: each ccx job as a ``.vtu``, the run's
jobs in one ``.pvd``.

A ccx job leaves its mesh in ``job.frd`` (nodes and elements, as ccx wrote them: the morphed,
worn bodies of that cycle) and its fields in ``job.dat`` (the ``*NODE PRINT`` / ``*EL PRINT``
sets of the deck) and, when the deck asks for them (``*NODE FILE`` / ``*EL FILE``: the decks
of :func:`tribodem.contact.fe.model.run` with ``frd=True``), in nodal blocks of the ``.frd``.
:func:`job_vtu` writes ``job.vtu`` beside them (meshio, atomically):

- the mesh: points (m) and cells (4-node quadrilaterals of the plane-strain backend, 8-node
  bricks of the 3D one; the element types tribodem writes: the linear ones of
  :data:`FRD_CELLS`), cell data ``material`` (ccx's material number of each element, in
  the ``.frd``'s order: 1 ``LOWER``, 2 ``UPPER`` in tribodem's decks) and ``element`` (its
  ccx id);
- at the job's last output time (the end of its cycle): the stresses the ``.dat`` prints,
  averaged over each element's integration points, as cell data ``stress_Pa`` (6
  components in ParaView's symmetric-tensor order xx, yy, zz, xy, yz, xz) and
  ``von_mises_Pa``; ``peeq`` (equivalent plastic strain) when the bodies are plastic; nan
  in the elements the deck does not print (away from the contact);
- every nodal block of the ``.frd`` at that time (``DISP`` as ``displacement_m``, ...) as
  point data.

:func:`write_fields` does it for every job of a run's ``fe`` folder (from its ``jobs.csv``:
the job that served each cycle, a retried one's successful deck) and writes
``fe/fields.pvd``, one entry per job with the last cycle it served as the time. A job whose
``.vtu`` is newer than its ``.frd`` and ``.dat`` is not converted again (a resumed run
converts only its new jobs).
"""

from __future__ import annotations

import csv
import logging
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from tribodem.contact.fe.results import read_dat_last, read_frd
from tribodem.io.results import atomic_write
from tribodem.io.vtk import write_pvd

log = logging.getLogger(__name__)

#: ccx ``.frd`` element type -> (meshio cell type, nodes): the linear elements, whose node
#: order is VTK's
FRD_CELLS = {1: ("hexahedron", 8), 2: ("wedge", 6), 3: ("tetra", 4), 7: ("triangle", 3),
             9: ("quad", 4), 11: ("line", 2)}
#: the ``.pvd`` of a run's jobs, in its ``fe`` folder
FIELDS_PVD = "fields.pvd"


@dataclass
class FrdMesh:
    """The mesh of an ``.frd`` file: node ids and coordinates (m), and per cell type its
    connectivity (0-based rows of ``points``), element ids and material numbers."""

    node_ids: NDArray[np.int64]
    points: NDArray[np.float64]
    cells: dict[str, list[list[int]]] = field(default_factory=dict)
    element_ids: dict[str, list[int]] = field(default_factory=dict)
    materials: dict[str, list[int]] = field(default_factory=dict)
    material_names: list[str] = field(default_factory=list)


def _widths(header: str) -> int:
    """Width of an id in a block of the ``.frd`` whose header line is ``header``: its
    format flag (the last field: 0 short, 1 long; 2 is binary, not read here)."""
    flag = int(header.split()[-1])
    if flag not in (0, 1):
        raise ValueError(f"binary .frd blocks (format {flag}) are not read; ask ccx for "
                         "ASCII output")
    return 5 if flag == 0 else 10


def read_frd_mesh(path: str | Path) -> FrdMesh:
    """The nodes (block ``2C``) and elements (block ``3C``) of an ASCII ``.frd`` file;
    ``ValueError`` for an element type outside :data:`FRD_CELLS`."""
    lines = Path(path).read_text().splitlines()
    ids: list[int] = []
    xyz: list[tuple[float, float, float]] = []
    mesh = FrdMesh(np.zeros(0, dtype=np.int64), np.zeros((0, 3)))
    i = 0
    while i < len(lines):
        ln = lines[i]
        if ln.startswith("    1UMAT"):
            mesh.material_names.append(ln[14:].strip().lstrip("M").strip())
        elif ln.startswith("    2C"):
            w = _widths(ln)
            i += 1
            while not lines[i].startswith(" -3"):
                s = lines[i]
                ids.append(int(s[3:3 + w]))
                c = 3 + w
                xyz.append((float(s[c:c + 12]), float(s[c + 12:c + 24]),
                            float(s[c + 24:c + 36])))
                i += 1
        elif ln.startswith("    3C"):
            w = _widths(ln)
            i += 1
            while not lines[i].startswith(" -3"):
                head = lines[i]  # " -1" id, type, group, material
                eid = int(head[3:3 + w])
                etype, _, mat = (int(v) for v in head[3 + w:].split()[:3])
                if etype not in FRD_CELLS:
                    raise ValueError(f"element type {etype} of element {eid} in '{path}' is "
                                     f"not read (allowed: {sorted(FRD_CELLS)})")
                kind, nn = FRD_CELLS[etype]
                conn: list[int] = []
                i += 1
                while lines[i].startswith(" -2"):
                    s = lines[i]
                    conn += [int(s[k:k + w]) for k in range(3, len(s.rstrip()) - w + 1, w)]
                    i += 1
                mesh.cells.setdefault(kind, []).append(conn[:nn])
                mesh.element_ids.setdefault(kind, []).append(eid)
                mesh.materials.setdefault(kind, []).append(mat)
            continue
        i += 1
    mesh.node_ids = np.asarray(ids, dtype=np.int64)
    mesh.points = np.asarray(xyz, dtype=float).reshape(-1, 3)
    row = {int(n): k for k, n in enumerate(mesh.node_ids)}
    mesh.cells = {k: [[row[n] for n in c] for c in cs] for k, cs in mesh.cells.items()}
    return mesh


#: ccx's stress order (sxx, syy, szz, sxy, sxz, syz) -> ParaView's (xx, yy, zz, xy, yz, xz)
_TO_PARAVIEW = [0, 1, 2, 3, 5, 4]


def _von_mises(s: NDArray[np.float64]) -> NDArray[np.float64]:
    """von Mises stress of [..., 6] (xx, yy, zz, xy, yz, xz), Pa."""
    return np.sqrt(0.5 * ((s[..., 0] - s[..., 1]) ** 2 + (s[..., 1] - s[..., 2]) ** 2
                          + (s[..., 2] - s[..., 0]) ** 2)
                   + 3.0 * (s[..., 3] ** 2 + s[..., 4] ** 2 + s[..., 5] ** 2))


def _element_means(rows: list[NDArray[np.float64]], width: int
                   ) -> dict[int, NDArray[np.float64]]:
    """Per element id the mean over its integration points of the columns after (id, point)
    of ``rows`` (``.dat`` blocks of one kind, the same element in several sets counted
    once per point)."""
    sums: dict[int, NDArray[np.float64]] = {}
    seen: set[tuple[int, int]] = set()
    counts: dict[int, int] = {}
    for r in rows:
        for v in r.reshape(-1, width):
            key = (int(v[0]), int(v[1]))
            if key in seen:
                continue
            seen.add(key)
            e = key[0]
            sums[e] = sums.get(e, 0.0) + v[2:]
            counts[e] = counts.get(e, 0) + 1
    return {e: s / counts[e] for e, s in sums.items()}


def _cell_field(mesh: FrdMesh, kind: str, means: dict[int, NDArray[np.float64]],
                ncomp: int) -> NDArray[np.float64]:
    """The per-element values ``means`` on the cells of type ``kind`` (nan elsewhere)."""
    eids = mesh.element_ids[kind]
    out = np.full((len(eids), ncomp), np.nan)
    for k, e in enumerate(eids):
        v = means.get(e)
        if v is not None:
            out[k] = v[:ncomp]
    return out


def job_vtu(frd: str | Path, dat: str | Path | None = None, out: str | Path | None = None
            ) -> Path:
    """Write the ``.vtu`` of one ccx job (see the module's docstring): the mesh of ``frd``,
    the stresses (and PEEQ) of ``dat`` (default: beside it; left out when there is none) at
    its last output time and the ``.frd``'s nodal blocks at that time. ``out``: default
    ``frd`` with the suffix ``.vtu``. Returns its path."""
    import meshio

    frd = Path(frd)
    dat = frd.with_suffix(".dat") if dat is None else Path(dat)
    out = frd.with_suffix(".vtu") if out is None else Path(out)
    mesh = read_frd_mesh(frd)
    kinds = list(mesh.cells)
    cell_data: dict[str, list[NDArray]] = {
        "material": [np.asarray(mesh.materials[k], dtype=np.int32) for k in kinds],
        "element": [np.asarray(mesh.element_ids[k], dtype=np.int64) for k in kinds]}
    time = None
    if dat.is_file():
        time, blocks = read_dat_last(dat)
        stress = [b.rows for b in blocks if b.kind == "stresses" and b.rows.size]
        if stress:
            means = _element_means(stress, stress[0].shape[1])
            tensors = [_cell_field(mesh, k, means, 6)[:, _TO_PARAVIEW] for k in kinds]
            cell_data["stress_Pa"] = tensors
            cell_data["von_mises_Pa"] = [_von_mises(s) for s in tensors]
        peeq = [b.rows for b in blocks if b.kind == "equivalent plastic strain"
                and b.rows.size]
        if peeq:
            means = _element_means(peeq, peeq[0].shape[1])
            cell_data["peeq"] = [_cell_field(mesh, k, means, 1)[:, 0] for k in kinds]
    point_data: dict[str, NDArray] = {}
    nodal = read_frd(frd)
    if nodal:
        last = max(b.time for b in nodal) if time is None else time
        row = {int(n): k for k, n in enumerate(mesh.node_ids)}
        for b in nodal:
            if abs(b.time - last) > 1e-9 * max(abs(last), 1.0):
                continue
            vals = np.full((mesh.points.shape[0], b.values.shape[1]), np.nan)
            idx = [row.get(int(n), -1) for n in b.nodes]
            ok = np.array([k >= 0 for k in idx], dtype=bool)
            vals[np.asarray(idx)[ok]] = b.values[ok]
            name = {"DISP": "displacement_m", "STRESS": "stress_frd_Pa",
                    "PE": "peeq_frd"}.get(b.name, b.name.lower())
            point_data[name] = vals[:, 0] if vals.shape[1] == 1 else vals
    m = meshio.Mesh(mesh.points, [(k, np.asarray(mesh.cells[k], dtype=np.int64))
                                  for k in kinds], point_data=point_data,
                    cell_data=cell_data)
    return atomic_write(out, lambda p: meshio.write(p, m, file_format="vtu"))


def _jobs(fe_dir: Path, cycles_done: int | None) -> list[tuple[int, Path]]:
    """(the last cycle it served, its ``.frd``) of every job in ``fe_dir/jobs.csv`` up to
    ``cycles_done`` (the last row of a cycle run twice: a resumed cycle), in cycle order."""
    path = fe_dir / "jobs.csv"
    if not path.is_file():
        return []
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    by_cycle: dict[int, tuple[int, Path]] = {}
    for r in rows:
        try:
            cycle, span = int(r["cycle"]), int(r.get("cycles") or 1)
        except (KeyError, TypeError, ValueError):
            continue
        if cycles_done is not None and cycle > cycles_done:
            continue
        deck = Path(r.get("deck") or "")
        # the deck as recorded may be another machine's path: the job folder in fe_dir
        frd = fe_dir / deck.parent.name / deck.with_suffix(".frd").name
        by_cycle[cycle] = (cycle + max(span, 1) - 1, frd)
    return [by_cycle[c] for c in sorted(by_cycle)]


def _fresh(vtu: Path, *sources: Path) -> bool:
    """Whether ``vtu`` exists and is newer than each existing source."""
    if not vtu.is_file():
        return False
    t = vtu.stat().st_mtime_ns
    return all(not s.is_file() or s.stat().st_mtime_ns <= t for s in sources)


def write_fields(fe_dir: str | Path, cycles_done: int | None = None) -> Path | None:
    """Every job of the run's ccx folder ``fe_dir`` as ``.vtu`` (:func:`job_vtu`, skipped
    when up to date) and ``fe_dir/fields.pvd`` listing them with the last cycle each served
    as the time; ``cycles_done``: the jobs of later cycles (an earlier, longer run in the
    folder) are left out. A job that cannot be converted is reported (a warning) and left
    out. Returns the ``.pvd`` (None without any job)."""
    fe_dir = Path(fe_dir)
    entries: list[tuple[float, str]] = []
    for last_cycle, frd in _jobs(fe_dir, cycles_done):
        if not frd.is_file():
            continue
        vtu = frd.with_suffix(".vtu")
        if not _fresh(vtu, frd, frd.with_suffix(".dat")):
            try:
                job_vtu(frd)
            except (ValueError, IndexError, KeyError, OSError) as err:
                log.warning("the fields of %s are not converted for ParaView: %s: %s", frd,
                            type(err).__name__, err)
                continue
        entries.append((float(last_cycle), vtu.relative_to(fe_dir).as_posix()))
    if not entries:
        return None
    return write_pvd(fe_dir / FIELDS_PVD, entries)

