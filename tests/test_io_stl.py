"""STL read/write (ASCII, binary) round trips and height maps as triangles."""

from __future__ import annotations

import numpy as np
import pytest

from tribodem.io.stl import (
    heightmap_to_triangles,
    read_stl,
    triangle_areas,
    triangle_normals,
    write_stl,
)


@pytest.fixture
def tris() -> np.ndarray:
    rng = np.random.default_rng(3)
    return rng.normal(0, 1e-3, (57, 3, 3)) + np.array([0.01, -0.02, 3e-4])


@pytest.mark.parametrize("binary", [True, False])
def test_round_trip_is_bitwise(tmp_path, tris: np.ndarray, binary: bool) -> None:
    """Binary: the float32 values bit for bit; ASCII (17 digits): the float64 values."""
    path = write_stl(tmp_path / "s.stl", tris, binary=binary, name="body")
    back = read_stl(path)
    assert back.shape == tris.shape and back.dtype == np.float64
    expect = tris.astype(np.float32).astype(np.float64) if binary else tris
    assert np.array_equal(back, expect)
    assert np.abs(back - tris).max() <= 1e-7 * np.abs(tris).max()
    f32 = tris.astype(np.float32).astype(np.float64)
    for fmt in (True, False):  # float32 data survive either format
        assert np.array_equal(read_stl(write_stl(tmp_path / "t.stl", f32, binary=fmt)), f32)


def test_binary_size_and_ascii_text(tmp_path, tris: np.ndarray) -> None:
    b = write_stl(tmp_path / "b.stl", tris)
    assert b.stat().st_size == 84 + 50 * len(tris)
    a = write_stl(tmp_path / "a.stl", tris[:2], binary=False, name="x")
    text = a.read_text()
    assert text.startswith("solid x") and text.count("vertex") == 6
    assert text.rstrip().endswith("endsolid x")


def test_binary_file_whose_header_says_solid(tmp_path, tris: np.ndarray) -> None:
    """Some exporters start binary headers with 'solid': the size decides."""
    p = write_stl(tmp_path / "b.stl", tris)
    data = bytearray(p.read_bytes())
    data[:5] = b"solid"
    p.write_bytes(bytes(data))
    assert np.array_equal(read_stl(p), tris.astype(np.float32).astype(np.float64))


def test_bad_files_are_refused(tmp_path) -> None:
    p = tmp_path / "bad.stl"
    p.write_bytes(b"\x00" * 100)
    with pytest.raises(ValueError, match="neither binary"):
        read_stl(p)
    with pytest.raises(ValueError, match="expected"):
        write_stl(tmp_path / "x.stl", np.zeros((3, 3)))


def test_heightmap_flat_area_and_normals() -> None:
    x = np.array([0.0, 0.1, 0.25, 0.7, 1.0]) * 1e-3
    y = np.linspace(-2e-3, 1e-3, 7)
    tri = heightmap_to_triangles(x, y, np.full((x.size, y.size), 5e-6))
    assert tri.shape == (2 * 4 * 6, 3, 3)
    area = triangle_areas(tri).sum()
    assert area == pytest.approx((x[-1] - x[0]) * (y[-1] - y[0]), rel=1e-15)
    assert np.array_equal(triangle_normals(tri), np.tile([0.0, 0.0, 1.0], (len(tri), 1)))


def test_heightmap_tilted_plane_area() -> None:
    x = np.linspace(0, 1, 9)
    y = np.linspace(0, 2, 5)
    z = 0.5 * x[:, None] + 0.0 * y[None, :]
    tri = heightmap_to_triangles(x, y, z)
    assert triangle_areas(tri).sum() == pytest.approx(2 * np.sqrt(1.25), rel=1e-13)
    assert (triangle_normals(tri)[:, 2] > 0).all()
