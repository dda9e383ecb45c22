"""VTK output for ParaView: particles as vertex clouds, force chains as line cells.

Files are VTK XML unstructured grids (``.vtu``, written by meshio, atomically) plus a
``.pvd`` collection indexing the snapshots with their simulated times. Points are written
in 3D (a 2D model's at z = 0), as VTK requires. meshio reads back any file with at least
one cell; its reader refuses a file without cells (a valid VTK file, which ParaView opens):
a braking run writes no force-chain file for a snapshot without chains (:func:`has_lines`).
"""

from __future__ import annotations

from pathlib import Path

import meshio
import numpy as np

from tribodem.io.results import atomic_write, write_text


def points_3d(points: np.ndarray) -> np.ndarray:
    """``points`` as a contiguous float (N, 3) array: 2D points get z = 0 (what meshio does
    itself, with a warning on stdout, for the VTK format)."""
    pts = np.asarray(points, dtype=np.float64).reshape(len(points), -1)
    if pts.shape[1] < 3:
        pts = np.hstack([pts, np.zeros((pts.shape[0], 3 - pts.shape[1]))])
    return np.ascontiguousarray(pts)


def has_lines(lines: np.ndarray) -> bool:
    """Whether ``lines`` (pairs of point indices) holds at least one line: a ``.vtu``
    without any cell is not written (meshio could not read it back)."""
    return np.asarray(lines).size > 0


def write_points(path: str | Path, points: np.ndarray, point_data: dict[str, np.ndarray]
                 ) -> Path:
    """Particles as VTK vertices with per-point data (vectors as (N, 3) arrays)."""
    pts = points_3d(points)
    cells = [("vertex", np.arange(pts.shape[0], dtype=np.int64).reshape(-1, 1))]
    mesh = meshio.Mesh(pts, cells, point_data={k: np.asarray(v) for k, v in point_data.items()})
    return atomic_write(path, lambda p: meshio.write(p, mesh, file_format="vtu"))


def write_lines(path: str | Path, points: np.ndarray, lines: np.ndarray,
                cell_data: dict[str, np.ndarray]) -> Path:
    """Line cells between ``points`` (force chains: contacts, bonds) with per-line data.
    Without any line the file has no cell: ParaView opens it, meshio does not (callers
    that want it readable skip it: :func:`has_lines`)."""
    pts = points_3d(points)
    ln = np.asarray(lines, dtype=np.int64).reshape(-1, 2)
    mesh = meshio.Mesh(pts, [("line", ln)],
                       cell_data={k: [np.asarray(v)] for k, v in cell_data.items()})
    return atomic_write(path, lambda p: meshio.write(p, mesh, file_format="vtu"))


def write_pvd(path: str | Path, entries: list[tuple[float, str]]) -> Path:
    """ParaView collection: ``entries`` are (time s, relative file name)."""
    rows = "\n".join(f'    <DataSet timestep="{t:.9g}" part="0" file="{f}"/>' for t, f in entries)
    text = ('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n'
            f"  <Collection>\n{rows}\n  </Collection>\n</VTKFile>\n")
    return write_text(path, text)
