"""Meshes from numpy arrays and from files: what goes in comes out, and a file keeps its own coordinates."""
import os

import numpy as np
import pytest

import bvhlab
from conftest import box_mesh


def read_off(path):
    """The vertices and triangles of a plain OFF file of triangles, read without the library."""
    with open(path) as f:
        lines = [line.split() for line in f if line.strip() and not line.startswith("#")]
    assert lines[0] == ["OFF"]
    nv, nf = int(lines[1][0]), int(lines[1][1])
    vertices = np.array(lines[2:2 + nv], float)
    faces = np.array([row[1:4] for row in lines[2 + nv:2 + nv + nf]], int)
    return vertices, faces


def sorted_rows(a):
    return a[np.lexsort(a.T[::-1])]


def test_arrays_round_trip():
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    triangles = np.array([[0, 1, 2], [0, 1, 3], [1, 2, 3]], dtype=np.int64)
    m = bvhlab.Mesh(vertices, triangles, "tet")
    assert m.name == "tet" and m.vertex_count == 4 and m.triangle_count == 3
    np.testing.assert_array_equal(m.vertices, vertices)
    np.testing.assert_array_equal(m.triangles, triangles)
    np.testing.assert_array_equal(m.bounds, [[0, 0, 0], [1, 1, 1]])


def test_other_real_and_integer_dtypes_convert_exactly():
    vertices = np.array([[0.5, 0, 0], [1, 0.25, 0], [0, 1, 0.125]], np.float32)
    m = bvhlab.Mesh(vertices, np.array([[0, 1, 2]], np.uint8))
    assert m.vertices.dtype == np.float64
    np.testing.assert_array_equal(m.vertices, vertices.astype(np.float64))
    np.testing.assert_array_equal(m.triangles, [[0, 1, 2]])
    # Python lists are arrays too
    m = bvhlab.Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    np.testing.assert_array_equal(m.vertices[1], [1, 0, 0])


def test_file_keeps_its_coordinates_by_default(source_dir):
    path = os.path.join(source_dir, "meshes", "pinion.off")
    vertices, faces = read_off(path)
    m = bvhlab.load_mesh(path)
    assert m.name == "pinion" and m.triangle_count == len(faces)
    # assimp reads coordinates as 32-bit floats: the file's numbers rounded so, not rescaled or moved
    expected = sorted_rows(np.unique(vertices.astype(np.float32).astype(np.float64), axis=0))
    np.testing.assert_array_equal(sorted_rows(np.unique(m.vertices, axis=0)), expected)


def test_normalize_and_scale(source_dir):
    raw = bvhlab.load_mesh(os.path.join(source_dir, "meshes", "pinion.off"))
    lo, hi = raw.bounds
    centre, longest = (lo + hi) / 2, (hi - lo).max()
    normalized = bvhlab.load_mesh("pinion.off", normalize=True)  # a name from the mesh catalog
    np.testing.assert_allclose(normalized.vertices, (raw.vertices - centre) * (2 / longest), atol=1e-12)
    assert (normalized.bounds[1] - normalized.bounds[0]).max() == pytest.approx(2)
    np.testing.assert_allclose(raw.normalized().vertices, normalized.vertices, atol=1e-15)
    scaled = bvhlab.load_mesh("pinion.off", normalize=True, scale=3)
    np.testing.assert_allclose(scaled.vertices, 3 * normalized.vertices, atol=1e-12)


def test_loaded_mesh_builds_the_same_tree_as_arrays(source_dir):
    """A mesh handed over as arrays answers like the same mesh loaded from its file."""
    loaded = bvhlab.load_mesh("pinion.off", normalize=True)
    copy = bvhlab.Mesh(loaded.vertices, loaded.triangles)
    poses = bvhlab.protocol_poses(1.4, 30)
    a = bvhlab.query_batch(bvhlab.Tree(loaded), bvhlab.Tree(loaded), poses)
    b = bvhlab.query_batch(bvhlab.Tree(copy), bvhlab.Tree(copy), poses)
    for key in a:
        np.testing.assert_array_equal(a[key], b[key], err_msg=key)
    assert 0 < a["collides"].sum() < len(poses)  # the distance is one where the answer varies


def test_box_helper_is_closed():
    m = box_mesh()
    assert m.triangle_count == 12
    # every edge of a closed surface is shared by exactly two triangles
    edges = {}
    for t in m.triangles:
        for i in range(3):
            e = tuple(sorted((t[i], t[(i + 1) % 3])))
            edges[e] = edges.get(e, 0) + 1
    assert set(edges.values()) == {2}
