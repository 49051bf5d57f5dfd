"""Bad input raises a Python exception naming the problem, never a crash or a silent answer."""
import numpy as np
import pytest

import bvhlab
from conftest import box_mesh, matrix, rotation_z

V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
T = np.array([[0, 1, 2], [0, 1, 3]])


@pytest.fixture(scope="module")
def trees():
    cube = box_mesh()
    return {"plain": bvhlab.Tree(cube), "adb": bvhlab.Tree(cube, "aabb", "adb"),
            "obb": bvhlab.Tree(cube, "obb")}


@pytest.mark.parametrize("vertices,triangles,error,message", [
    (np.where(np.arange(12).reshape(4, 3) == 4, np.nan, V), T, ValueError, r"vertices\[1\] has a NaN"),
    (np.where(np.arange(12).reshape(4, 3) == 11, np.inf, V), T, ValueError,
     r"vertices\[3\] has a NaN or infinite"),
    (V * 1e16, T, ValueError, "beyond 1e15"),
    (V[:, :2], T, ValueError, r"vertices: expected shape \(N, 3\), got \(4, 2\)"),
    (V.ravel(), T, ValueError, r"expected shape \(N, 3\), got \(12,\)"),
    (V[None], T, ValueError, "expected shape"),
    (V.astype(str), T, TypeError, "vertices: expected real numbers"),
    (V.astype(complex), T, TypeError, "got dtype complex128"),
    (V > 0, T, TypeError, "got dtype bool"),
    (None, T, TypeError, "vertices: expected real numbers \\(float64\\), got dtype object"),
    ([[0, 0, 0], [1, 0]], T, TypeError, "vertices"),
    (V, T.astype(float), TypeError, "triangles: expected integer vertex indices, got dtype float64"),
    (V, T[:, :2], ValueError, r"triangles: expected shape \(M, 3\)"),
    (V, np.array([[0, 1, 4]]), ValueError,
     r"triangles\[0, 2\] = 4 is out of range \(the mesh has 4 vertices\)"),
    (V, np.array([[0, 1, 2], [-1, 1, 2]]), ValueError, r"triangles\[1, 0\] = -1 is out of range"),
    (V, np.array([[0, 1, 2**40]], np.uint64), ValueError, "is out of range"),
    (V, np.zeros((0, 3), int), ValueError, "no triangles"),
    (np.ones((4, 3)), T, ValueError, "zero size"),
])
def test_bad_mesh_arrays(vertices, triangles, error, message):
    with pytest.raises(error, match=message):
        bvhlab.Mesh(vertices, triangles)


def test_bad_mesh_files(tmp_path):
    with pytest.raises(FileNotFoundError, match="no-such-mesh.obj"):
        bvhlab.load_mesh(tmp_path / "no-such-mesh.obj")
    broken = tmp_path / "broken.off"
    broken.write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n")  # a vertex and the face missing
    with pytest.raises(bvhlab.MeshError, match="broken.off"):
        bvhlab.load_mesh(broken)
    nan = tmp_path / "nan.off"
    nan.write_text("OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n")
    with pytest.raises(bvhlab.MeshError, match="nan.off"):
        bvhlab.load_mesh(nan)
    with pytest.raises(ValueError, match="scale"):
        bvhlab.load_mesh("pinion.off", scale=0)
    with pytest.raises(TypeError, match="path"):
        bvhlab.load_mesh(42)


@pytest.mark.parametrize("kwargs,message", [
    ({"bv": "abb"}, "unknown bounding volume 'abb' \\(known: aabb, "),
    ({"density": "adbb"}, "unknown density 'adbb'"),
    ({"density": "adb", "grid": 7}, "grid"),
    ({"density": "adb", "tau": -1}, "tau"),
    ({"density": "none", "grid": 2}, "grid"),
    ({"density": "adb", "tau": "a lot"}, "parameter tau: expected a number, got str"),
    ({"leaf": 0}, "leaf"),
    ({"split": "middle"}, "unknown split method 'middle'"),
    ({"threads": -1}, "threads"),
])
def test_bad_tree_arguments(kwargs, message):
    error = TypeError if kwargs.get("tau") == "a lot" else ValueError
    with pytest.raises(error, match=message):
        bvhlab.Tree(box_mesh(), **kwargs)


def test_bad_saved_tree_paths(tmp_path, trees):
    with pytest.raises(FileNotFoundError, match="missing.tree"):
        bvhlab.Tree.load(tmp_path / "missing.tree")
    with pytest.raises(FileNotFoundError, match="no-folder"):
        trees["plain"].save(tmp_path / "no-folder" / "t.tree")


SCALED = matrix(2 * np.eye(3), [0, 0, 0])
REFLECTED = matrix(np.diag([1.0, 1.0, -1.0]), [0, 0, 0])
SHEARED = matrix([[1, 0.1, 0], [0, 1, 0], [0, 0, 1]], [0, 0, 0])
PROJECTIVE = np.eye(4)
PROJECTIVE[3, 0] = 0.5


@pytest.mark.parametrize("pose,error,message", [
    (SCALED, ValueError, "not orthonormal"),
    (REFLECTED, ValueError, "reflection"),
    (SHEARED, ValueError, "not orthonormal"),
    (PROJECTIVE, ValueError, "last row must be 0 0 0 1"),
    (np.where(np.eye(4) == 1, np.nan, 0), ValueError, "NaN or infinite"),
    (matrix(np.eye(3), [np.inf, 0, 0]), ValueError, "NaN or infinite"),
    (np.eye(3), ValueError, r"pose: expected shape \(4, 4\), got \(3, 3\)"),
    (np.eye(4).astype(complex), TypeError, "pose: expected real numbers"),
    ("identity", TypeError, "pose"),
])
def test_non_rigid_or_malformed_poses(trees, pose, error, message):
    with pytest.raises(error, match=message):
        bvhlab.query(trees["plain"], trees["plain"], pose)


def test_bad_rotation_and_translation(trees):
    t = trees["plain"]
    with pytest.raises(ValueError, match="rotation is a reflection"):
        bvhlab.query(t, t, rotation=-np.eye(3), translation=[0, 0, 0])
    with pytest.raises(ValueError, match=r"translation: expected shape \(3,\)"):
        bvhlab.query(t, t, translation=[1, 2])
    with pytest.raises(ValueError, match="translation has a NaN"):
        bvhlab.query(t, t, translation=[np.nan, 0, 0])
    with pytest.raises(ValueError, match="not both"):
        bvhlab.query(t, t, np.eye(4), translation=[1, 0, 0])


def test_a_query_without_a_pose_is_refused(trees):
    t = trees["plain"]
    for kwargs in ({}, {"rotation": np.eye(3)}):
        with pytest.raises(ValueError, match=r"give a pose \(4, 4\), or a translation"):
            bvhlab.query(t, t, **kwargs)
    assert bvhlab.query(t, t, translation=[0, 0, 0]).collides  # the identity, when asked for


def test_bad_batches(trees):
    t = trees["plain"]
    good = bvhlab.protocol_poses(1.0, 6)
    bad = good.copy()
    bad[3, :3, :3] *= 1.01
    with pytest.raises(ValueError, match=r"poses\[3\]: transform: rotation is not orthonormal"):
        bvhlab.query_batch(t, t, bad)
    bad = good.copy()
    bad[5, 0, 3] = np.nan
    with pytest.raises(ValueError, match=r"poses\[5\]: the matrix has a NaN"):
        bvhlab.query_batch(t, t, bad)
    with pytest.raises(ValueError, match=r"poses: expected shape \(K, 4, 4\), got \(6, 4, 3\)"):
        bvhlab.query_batch(t, t, good[:, :, :3])
    with pytest.raises(ValueError,
                       match=r"rotations: expected shape \(K, 3, 3\) with K = 2, got \(3, 3, 3\)"):
        bvhlab.query_batch(t, t, rotations=np.stack([np.eye(3)] * 3), translations=np.zeros((2, 3)))
    with pytest.raises(ValueError, match=r"rotations\[1\], translations\[1\]: transform: rotation is a reflection"):
        bvhlab.query_batch(t, t, rotations=np.stack([np.eye(3), -np.eye(3)]), translations=np.zeros((2, 3)))
    with pytest.raises(ValueError, match="give poses"):
        bvhlab.query_batch(t, t)
    with pytest.raises(TypeError, match="got dtype <U"):
        bvhlab.query_batch(t, t, good.astype(str))
    empty = bvhlab.query_batch(t, t, np.zeros((0, 4, 4)))
    assert all(len(v) == 0 for v in empty.values())


@pytest.mark.parametrize("tree,kwargs,message", [
    ("plain", {"strategy": "fastest"}, "unknown strategy 'fastest'"),
    ("adb", {"strategy": "adb", "p_min": 1.5}, "p_min"),
    ("adb", {"strategy": "adb", "p_min": float("nan")}, "p_min"),
    ("adb", {"strategy": "adb", "pmin": 0.5}, "pmin"),
    ("plain", {"strategy": "exact", "p_min": 0.5}, "p_min"),
    ("adb", {"strategy": "time_critical"}, "needs a budget"),
    ("plain", {"strategy": "exact", "bv_tests": 10}, "takes no budget"),
    ("adb", {"strategy": "time_critical", "bv_tests": -1}, "bv_tests must be >= 0"),
    ("adb", {"strategy": "time_critical", "deadline_us": float("nan")}, "deadline_us must be finite"),
    ("plain", {"strategy": "adb"}, "does not run on trees with density 'none' \\(it runs on: adb, adb_paper, adb_normal\\)"),
    ("plain", {"strategy": "guided_exact"}, "density 'none'"),
])
def test_bad_strategies(trees, tree, kwargs, message):
    t = trees[tree]
    with pytest.raises(ValueError, match=message):
        bvhlab.query(t, t, np.eye(4), **kwargs)
    with pytest.raises(ValueError, match=message):
        bvhlab.query_batch(t, t, np.eye(4)[None], **kwargs)


def test_trees_of_different_types(trees):
    with pytest.raises(ValueError, match=r"differ in BV or density \(aabb, none vs obb, none\)"):
        bvhlab.query(trees["plain"], trees["obb"], np.eye(4))
    with pytest.raises(ValueError, match="differ in BV or density"):
        bvhlab.query(trees["plain"], trees["adb"], np.eye(4))
    other = bvhlab.Tree(box_mesh(), "aabb", "adb", grid=3)
    with pytest.raises(ValueError, match="annotated with other parameters"):
        bvhlab.query(trees["adb"], other, np.eye(4), strategy="adb")
    with pytest.raises(TypeError):
        bvhlab.query(trees["plain"], "tree", np.eye(4))


def test_bad_scenes(tmp_path):
    with pytest.raises(FileNotFoundError, match="missing.json"):
        bvhlab.run_scene(tmp_path / "missing.json")
    bad = {"objects": [{"mesh": "pinion.off"}], "hierarchies": [{"bv": "abb"}],
           "strategies": [{"type": "exact"}]}
    with pytest.raises(bvhlab.SceneError, match="/hierarchies/0/bv"):
        bvhlab.run_scene(bad)
    broken = tmp_path / "broken.json"
    broken.write_text("{ not json")
    with pytest.raises(bvhlab.SceneError, match="broken.json"):
        bvhlab.run_scene(broken)
    with pytest.raises(TypeError, match="run_scene"):
        bvhlab.run_scene(3)
    with pytest.raises(ValueError, match="threads"):
        bvhlab.run_scene(bad, threads=-2)


def test_rotations_accept_integer_arrays(trees):
    """Integer arrays are real numbers too: an exact identity and a quarter turn need no floats."""
    t = trees["plain"]
    turn = np.rint(rotation_z(90)).astype(int)
    assert bvhlab.query(t, t, rotation=turn, translation=[0, 0, 0]).collides
    assert not bvhlab.query(t, t, np.eye(4, dtype=int) + np.pad([[0, 0, 0, 5]], ((0, 3), (0, 0)))).collides
