"""STL triangle meshes (ASCII and binary) and height maps as triangles.

Seed 003 (section 3.2.6) exchanges the first-body geometry between the FE and DE phases as
``.stl`` files. Triangles are ``(n, 3, 3)`` float arrays (triangle, vertex, xyz; m); the
vertex order gives the outward normal by the right-hand rule. Binary STL stores float32:
reading returns those values exactly (as float64). ASCII is written with 17 significant
digits, so any float64 coordinates round-trip bit for bit.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tribodem.io.results import atomic_write, write_text

_BIN_DTYPE = np.dtype([("normal", "<f4", (3,)), ("v", "<f4", (3, 3)), ("attr", "<u2")])


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
    """Write triangles (m) to an STL file, binary (default, float32) or ASCII (17 digits);
    returns the path."""
    t = _checked(triangles)
    path = Path(path)
    nrm = triangle_normals(t)
    if binary:
        rec = np.zeros(t.shape[0], dtype=_BIN_DTYPE)
        rec["normal"] = nrm
        rec["v"] = t
        header = f"binary STL {name}".encode("ascii", "replace")[:80].ljust(80, b" ")
        payload = header + np.uint32(t.shape[0]).tobytes() + rec.tobytes()
        return atomic_write(path, lambda p: p.write_bytes(payload))
    lines = [f"solid {name}"]
    for k in range(t.shape[0]):
        nx, ny, nz = nrm[k]
        lines.append(f"  facet normal {nx:.9g} {ny:.9g} {nz:.9g}")
        lines.append("    outer loop")
        for v in t[k]:
            lines.append(f"      vertex {v[0]:.17g} {v[1]:.17g} {v[2]:.17g}")
        lines.append("    endloop")
        lines.append("  endfacet")
    lines.append(f"endsolid {name}")
    return write_text(path, "\n".join(lines) + "\n")


def read_stl(path: str | Path) -> np.ndarray:
    """Triangles ``(n, 3, 3)`` (float64 of the stored values) of an ASCII or binary STL."""
    path = Path(path)
    data = path.read_bytes()
    if len(data) >= 84:
        n = int(np.frombuffer(data, dtype="<u4", count=1, offset=80)[0])
        if len(data) == 84 + 50 * n:
            rec = np.frombuffer(data, dtype=_BIN_DTYPE, count=n, offset=84)
            return rec["v"].astype(np.float64)
    head = data[:512].lstrip().lower()
    if not head.startswith(b"solid"):
        raise ValueError(f"stl '{path}': neither binary (size does not match the triangle "
                         "count) nor ASCII (no 'solid' header)")
    tokens = data.split()
    idx = [k for k, tok in enumerate(tokens) if tok.lower() == b"vertex"]
    if len(idx) % 3:
        raise ValueError(f"stl '{path}': {len(idx)} vertices is not a multiple of 3")
    try:
        v = np.array([[float(tokens[k + 1]), float(tokens[k + 2]), float(tokens[k + 3])]
                      for k in idx], dtype=np.float64)
    except (ValueError, IndexError) as exc:
        raise ValueError(f"stl '{path}': malformed vertex line ({exc})") from exc
    return v.reshape(-1, 3, 3)


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
