"""Trees of every volume and density: what they report, and saved and loaded trees answering like the
original, in this module and in the bvhlab CLI."""
import threading
import time

import numpy as np
import pytest

import bvhlab

POSES = np.concatenate([bvhlab.protocol_poses(d, 30) for d in (0.8, 1.3, 1.8)])


def assert_same_answers(a, b):
    for key, values in a.items():
        np.testing.assert_array_equal(values, b[key], err_msg=key)
    assert len(np.unique(a["probability"])) > 1, "the poses should not all get one answer"


def test_registered_names_and_sizes(gear):
    for bv in bvhlab.volumes():
        tree = bvhlab.Tree(gear, bv)
        assert (tree.bv, tree.density, tree.annotation) == (bv, "none", "none")
        assert tree.triangles == gear.triangle_count
        assert tree.nodes == 2 * gear.triangle_count - 1  # one triangle per leaf: a full binary tree
        assert tree.has_polygons and tree.model_bytes > 0 and tree.depth >= 11
    coarse = bvhlab.Tree(gear, "aabb", leaf=8, split="median")
    assert coarse.nodes < gear.triangle_count
    annotated = bvhlab.Tree(gear, "obb", "adb", grid=3, tau=0.5)
    assert (annotated.density, annotated.annotation) == ("adb", "adb grid=3 tau=0.5")
    assert annotated.model_bytes > bvhlab.Tree(gear, "obb").model_bytes
    assert annotated.annotate_seconds > 0


@pytest.mark.parametrize("bv", ["aabb", "dop24", "obb", "sphere", "rbox"])
def test_saved_tree_answers_like_the_original(tmp_path, gear, bv):
    tree = bvhlab.Tree(gear, bv, "adb")
    path = tmp_path / f"{bv}.tree"
    tree.save(path)
    loaded = bvhlab.Tree.load(path)
    for field in ("bv", "density", "annotation", "triangles", "nodes", "depth", "model_bytes"):
        assert getattr(loaded, field) == getattr(tree, field), field
    assert not loaded.has_polygons
    for p_min in (0.5, 0.9):
        assert_same_answers(bvhlab.query_batch(tree, tree, POSES, strategy="adb", p_min=p_min),
                            bvhlab.query_batch(loaded, loaded, POSES, strategy="adb", p_min=p_min))
    # exact strategies need the polygons back: the mesh is checked against the tree, then they answer alike
    with pytest.raises(ValueError, match="without polygons"):
        bvhlab.query(loaded, loaded, POSES[0])
    with_mesh = bvhlab.Tree.load(str(path), mesh=gear)
    assert with_mesh.has_polygons
    for strategy in ("exact", "guided_exact"):
        assert_same_answers(bvhlab.query_batch(tree, tree, POSES, strategy=strategy),
                            bvhlab.query_batch(with_mesh, with_mesh, POSES, strategy=strategy))


def test_saved_tree_is_the_clis(tmp_path, cli, gear_file, gear):
    """A tree saved here is what `bvhlab build` writes: the CLI reads it and answers the same."""
    mine = tmp_path / "mine.tree"
    tree = bvhlab.Tree(gear, "aabb", "adb")
    tree.save(mine)
    info = cli("info", mine, "--json")
    assert (info["bv"], info["annotation"], info["nodes"], info["triangles"]) == (
        "aabb", tree.annotation, tree.nodes, tree.triangles)
    for step in (3, 17):
        expected = cli("query", mine, mine, "--protocol", f"1.3,{step},50", "--strategy", "adb",
                       "--p-min", "0.8", "--json")
        r = bvhlab.query(tree, tree, bvhlab.protocol_pose(1.3, step, 50), strategy="adb", p_min=0.8)
        assert (r.collides, r.probability, r.counters["bv_tests"]) == (
            expected["collides"], expected["probability"], expected["bv_tests"])
    # and a tree the CLI builds loads here, equal to the one built here
    theirs = tmp_path / "theirs.tree"
    cli("build", gear_file, "--bv", "aabb", "--adb", "-o", theirs, parse_json=False)
    assert theirs.read_bytes() == mine.read_bytes()
    loaded = bvhlab.Tree.load(theirs, mesh=gear)
    assert_same_answers(bvhlab.query_batch(tree, tree, POSES), bvhlab.query_batch(loaded, loaded, POSES))


def test_a_mesh_that_does_not_fit_is_refused(tmp_path, gear):
    path = tmp_path / "gear.tree"
    bvhlab.Tree(gear).save(path)
    other = bvhlab.load_mesh("teapot.obj")
    with pytest.raises(ValueError, match="does not fit mesh"):
        bvhlab.Tree.load(path, mesh=other)
    # the same triangles moved: the leaves no longer contain them
    moved = bvhlab.Mesh(gear.vertices + [0.5, 0, 0], gear.triangles)
    with pytest.raises(ValueError, match="does not contain"):
        bvhlab.Tree.load(path, mesh=moved)


def test_broken_saved_trees_are_refused(tmp_path, gear):
    path = tmp_path / "t.tree"
    bvhlab.Tree(gear, "obb", "adb").save(path)
    data = bytearray(path.read_bytes())
    truncated = tmp_path / "truncated.tree"
    truncated.write_bytes(data[: len(data) // 2])
    flipped = tmp_path / "flipped.tree"
    data[len(data) // 2] ^= 0x40
    flipped.write_bytes(bytes(data))
    garbage = tmp_path / "garbage.tree"
    garbage.write_bytes(b"not a tree at all")
    for bad in (truncated, flipped, garbage):
        with pytest.raises(bvhlab.SavedTreeError, match=bad.name):
            bvhlab.Tree.load(bad)
    assert issubclass(bvhlab.SavedTreeError, ValueError)


def _wavy_grid(n):
    """A wavy n x n grid of quads (2 n^2 triangles): a mesh whose size the test chooses."""
    u = np.linspace(-1.0, 1.0, n + 1)
    x, y = np.meshgrid(u, u, indexing="ij")
    vertices = np.stack([x, y, 0.1 * np.sin(6 * x) * np.cos(5 * y)], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    corner = (i * (n + 1) + j).ravel()
    triangles = np.concatenate([np.stack([corner, corner + n + 1, corner + 1], axis=1),
                                np.stack([corner + 1, corner + n + 1, corner + n + 2], axis=1)])
    return bvhlab.Mesh(vertices, triangles.astype(np.int64))


def test_ctrl_c_interrupts_a_build_within_half_a_second():
    """SIGINT (Ctrl-C) in the middle of building and annotating a tree raises KeyboardInterrupt soon after,
    not once the tree is done, and no tree comes back. The mesh is sized from a small build's time so that the
    whole build would take at least 3 s."""
    import os
    import signal

    start = time.perf_counter()
    bvhlab.Tree(_wavy_grid(60), "aabb", density="adb", threads=1)
    per_triangle = max(time.perf_counter() - start, 1e-6) / (2 * 60 * 60)
    n = int(min(1500, np.ceil(np.sqrt(3.0 / per_triangle / 2))))
    mesh = _wavy_grid(n)
    timer = threading.Timer(0.2, lambda: os.kill(os.getpid(), signal.SIGINT))
    begin = time.perf_counter()
    timer.start()
    tree = None
    with pytest.raises(KeyboardInterrupt):
        tree = bvhlab.Tree(mesh, "aabb", density="adb", threads=1)
    late = time.perf_counter() - begin - 0.2
    timer.join()
    assert tree is None
    assert late < 0.5, f"KeyboardInterrupt {late:.2f} s after Ctrl-C (a mesh of {2 * n * n} triangles)"
