"""STL triangle meshes (ASCII and binary, read and written by meshio) and height maps as
triangles.

Lu (2018) (section 3.2.6) exchanges the first-body geometry between the FE and DE phases as
``.stl`` files. Triangles are ``(n, 3, 3)`` float arrays (triangle, vertex, xyz; m); the
vertex order gives the outward normal by the right-hand rule. Binary STL stores float32:
reading returns those values exactly (as float64). ASCII is written with the shortest
decimal that reads back the same float64 (meshio writes Python's ``repr``), so any float64
coordinates round-trip bit for bit.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tribodem.io.results import atomic_write


def triangle_normals(triangles: np.ndarray) -> np.ndarray:
    """Unit normals (right-hand rule) of ``(n, 3, 3)`` triangles; zero for degenerate ones."""
    t = np.asarray(triangles, dtype=np.float64)
    nrm = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    ln = np.linalg.norm(nrm, axis=1, keepdims=True)
    return np.divide(nrm, ln, out=np.zeros_like(nrm), where=ln > 0)


def triangle_areas(triangles: np.ndarray) -> np.ndarray:
    """Areas (m^2) of ``(n, 3, 3)`` triangles."""
    t = np.asarray(triangles, dtype=np.float64)
    return 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1)


def _checked(triangles: np.ndarray) -> np.ndarray:
    t = np.asarray(triangles, dtype=np.float64)
    if t.ndim != 3 or t.shape[1:] != (3, 3):
        raise ValueError(f"stl: triangles have shape {t.shape}, expected (n, 3, 3)")
    if not np.all(np.isfinite(t)):
        raise ValueError("stl: triangles contain non-finite coordinates")
    return t


def write_stl(path: str | Path, triangles: np.ndarray, binary: bool = True,
              name: str = "tribodem") -> Path:
    """Write triangles (m) to an STL file, binary (default, float32) or ASCII (float64 that
    read back bit for bit; the solid named ``name``), atomically; returns the path."""
    import meshio

    t = _checked(triangles)
    n = t.shape[0]
    mesh = meshio.Mesh(t.reshape(-1, 3), [("triangle", np.arange(3 * n).reshape(n, 3))],
                       cell_data={"facet_normals": [triangle_normals(t)]})

    def w(p: Path) -> None:
        meshio.write(p, mesh, file_format="stl", binary=binary)
        if not binary:  # meshio's ASCII solid has no name: give it ``name``
            body = p.read_text()
            body = body.removeprefix("solid\n").removesuffix("endsolid\n")
            p.write_text(f"solid {name}\n{body}endsolid {name}\n")
    return atomic_write(path, w)


def read_stl(path: str | Path) -> np.ndarray:
    """Triangles ``(n, 3, 3)`` (float64 of the stored values) of an ASCII or binary STL
    (meshio; a binary file is told by its size, whatever its header says); ``ValueError``
    for a file that is neither."""
    import meshio

    path = Path(path)
    size = path.stat().st_size
    with path.open("rb") as fh:
        head = fh.read(512)
    binary = size >= 84 and 84 + 50 * int.from_bytes(head[80:84], "little") == size
    if not binary and not head.lstrip().lower().startswith(b"solid"):
        raise ValueError(f"stl '{path}': neither binary (size does not match the triangle "
                         "count) nor ASCII (no 'solid' header)")
    try:  # meshio sizes an ASCII file as if binary first: uint32 arithmetic may overflow
        with np.errstate(over="ignore"):
            mesh = meshio.read(path, file_format="stl")
    except (meshio.ReadError, ValueError, IndexError) as exc:
        raise ValueError(f"stl '{path}': malformed ({type(exc).__name__}: {exc})") from exc
    cells = mesh.cells_dict.get("triangle")
    if cells is None:
        return np.zeros((0, 3, 3))
    return np.asarray(mesh.points, dtype=np.float64)[np.asarray(cells)]


def heightmap_to_triangles(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Triangles of the height map ``z[i, j]`` at ``(x[i], y[j])`` (m): two per grid cell,
    normals up (+z) -- a first-body surface as the seed's exchanged STL geometry."""
    x = np.asarray(x, dtype=np.float64).reshape(-1)
    y = np.asarray(y, dtype=np.float64).reshape(-1)
    z = np.asarray(z, dtype=np.float64)
    if z.shape != (x.size, y.size):
        raise ValueError(f"heightmap_to_triangles: z has shape {z.shape}, expected "
                         f"({x.size}, {y.size})")
    if x.size < 2 or y.size < 2:
        raise ValueError("heightmap_to_triangles: need >= 2 points along x and y")
    xx, yy = np.meshgrid(x, y, indexing="ij")
    pts = np.stack([xx, yy, z], axis=-1)
    p00 = pts[:-1, :-1].reshape(-1, 3)
    p10 = pts[1:, :-1].reshape(-1, 3)
    p01 = pts[:-1, 1:].reshape(-1, 3)
    p11 = pts[1:, 1:].reshape(-1, 3)
    t1 = np.stack([p00, p10, p11], axis=1)
    t2 = np.stack([p00, p11, p01], axis=1)
    return np.stack([t1, t2], axis=1).reshape(-1, 3, 3)
