"""bvhlab.PointCloud and trees over point clouds: arrays, files and sampling; point queries against the exact
answer on the meshes the clouds were sampled from; and the refusals."""
import numpy as np
import pytest

import bvhlab
from conftest import box_mesh, matrix, rotation_z


@pytest.fixture(scope="module")
def gear_cloud(gear):
    return bvhlab.PointCloud.sample(gear, 4000, seed=3)


def shifted(pose, offset):
    out = np.array(pose, float)
    out[:3, 3] += offset
    return out


def clear_truth(mesh_a, mesh_b, pose, band):
    """The exact answer on the meshes, or None when moving B by `band` along an axis changes it: the surfaces
    are then within about a point spacing of touching, where a cloud may answer either way."""
    truth = bvhlab.query(mesh_a, mesh_b, pose).collides
    for axis in range(3):
        for sign in (-1, 1):
            offset = np.zeros(3)
            offset[axis] = sign * band
            if bvhlab.query(mesh_a, mesh_b, shifted(pose, offset)).collides != truth:
                return None
    return truth


def test_arrays_round_trip_and_bad_arrays_are_refused():
    rng = np.random.default_rng(1)
    points = rng.normal(size=(40, 3))
    normals = points / np.linalg.norm(points, axis=1)[:, None]
    areas = np.full(40, 0.25)
    cloud = bvhlab.PointCloud(points, normals, areas, name="ball")
    assert len(cloud) == 40 and cloud.name == "ball"
    np.testing.assert_array_equal(cloud.points, points)
    np.testing.assert_array_equal(cloud.normals, normals)
    np.testing.assert_array_equal(cloud.areas, areas)
    bare = bvhlab.PointCloud(points)
    assert bare.normals is None and bare.areas is None
    bad = points.copy()
    bad[7, 1] = np.nan
    with pytest.raises(bvhlab.PointCloudError, match="point 7"):
        bvhlab.PointCloud(bad)
    with pytest.raises(ValueError, match=r"points: expected shape \(N, 3\)"):
        bvhlab.PointCloud(points[:, :2])
    with pytest.raises(ValueError, match="areas"):
        bvhlab.PointCloud(points, areas=areas[:10])
    with pytest.raises(ValueError, match="area"):
        bvhlab.PointCloud(points, areas=-areas)
    far = points.copy()
    far[3, 0] = 1e200  # the box sums of the density would overflow: refused where the cloud is made
    with pytest.raises(bvhlab.PointCloudError, match="point 3 has a coordinate beyond 1e15"):
        bvhlab.PointCloud(far)
    with pytest.raises(ValueError, match="coincident"):
        bvhlab.PointCloud(np.ones((5, 3)))
    with pytest.raises(TypeError):
        bvhlab.PointCloud("points")


def test_files_and_sampling(tmp_path, gear):
    cloud = bvhlab.PointCloud.sample(gear, 500, seed=7)
    again = bvhlab.PointCloud.sample(gear, 500, seed=7)
    other = bvhlab.PointCloud.sample(gear, 500, seed=8)
    np.testing.assert_array_equal(cloud.points, again.points)
    assert not np.array_equal(cloud.points, other.points)
    # Uniform sampling: every point stands for the same share of the mesh's area.
    assert np.allclose(cloud.areas, cloud.areas[0]) and cloud.areas[0] > 0
    varying = bvhlab.PointCloud.sample(gear, 500, seed=7, ratio=4)
    assert varying.areas.std() > 0.1 * varying.areas.mean()  # k-NN areas follow the density
    normalised = bvhlab.PointCloud.sample(gear.normalized(), 100)
    assert normalised.units["normalized"] and not cloud.units["normalized"]

    path = tmp_path / "gear.ply"
    cloud.save(path)
    loaded = bvhlab.PointCloud.load(path)
    np.testing.assert_allclose(loaded.points, cloud.points, rtol=0, atol=1e-12)
    np.testing.assert_allclose(loaded.normals, cloud.normals, rtol=0, atol=1e-12)
    assert loaded.areas is None  # PLY keeps no areas
    with pytest.raises(FileNotFoundError):
        bvhlab.PointCloud.load(tmp_path / "missing.ply")
    (tmp_path / "broken.xyz").write_text("0 0 0\n1 2\n")
    with pytest.raises(bvhlab.PointCloudError, match="broken.xyz"):
        bvhlab.PointCloud.load(tmp_path / "broken.xyz")
    with pytest.raises(ValueError):
        bvhlab.PointCloud.sample(gear, 0)


@pytest.mark.parametrize("bv", ["aabb", "obb"])
def test_cloud_queries_agree_with_the_meshes_on_clear_poses(gear, gear_cloud, bv):
    mesh_tree = bvhlab.Tree(gear, bv, "adb")
    cloud_tree = bvhlab.Tree(gear_cloud, bv, "adb")
    assert cloud_tree.points == 4000 and cloud_tree.triangles == 0
    band = 2 * np.sqrt(gear_cloud.areas.sum() / len(gear_cloud))  # two point spacings
    poses = [shifted(matrix(rotation_z(angle), [0, 0, 0]), [x, 0.1, 0])
             for angle in (0, 17, 40) for x in (0.3, 0.8, 1.5, 1.9, 2.2, 2.6)]
    checked = {True: 0, False: 0}
    for pose in poses:
        truth = clear_truth(mesh_tree, mesh_tree, pose, band)
        if truth is None:
            continue
        checked[truth] += 1
        exact = bvhlab.query(cloud_tree, cloud_tree, pose)
        assert exact.collides == truth and exact.exact
        assert exact.counters["bv_tests"] > 0
        assert bvhlab.query(cloud_tree, mesh_tree, pose).collides == truth  # a cloud against a mesh
        assert bvhlab.query(mesh_tree, cloud_tree, pose).collides == truth  # and the other way
        assert bvhlab.query(cloud_tree, cloud_tree, pose, strategy="guided_exact").collides == truth
        # ADB with exact leaf evidence: a crossing found at a leaf is certain, and apart is apart.
        for strategy in ("adb", "adb_dfs"):
            answer = bvhlab.query(cloud_tree, cloud_tree, pose, strategy=strategy, p_min=0.999,
                                  confirm_levels=4)
            assert answer.collides == truth, (strategy, truth)
    assert checked[True] >= 3 and checked[False] >= 3, checked


def test_batches_and_budgets_on_clouds(gear_cloud):
    tree = bvhlab.Tree(gear_cloud, "aabb", "adb")
    translations = np.array([[x, 0.1, 0.0] for x in (0.3, 1.0, 1.9, 2.5)])
    batch = bvhlab.query_batch(tree, tree, translations=translations, strategy="adb", p_min=0.9)
    for k, t in enumerate(translations):
        single = bvhlab.query(tree, tree, translation=t, strategy="adb", p_min=0.9)
        assert batch["collides"][k] == single.collides
        assert batch["bv_tests"][k] == single.counters["bv_tests"]
    capped = bvhlab.query_batch(tree, tree, translations=translations, strategy="time_critical", bv_tests=1,
                                 p_min=0.999)
    assert capped["budget_exhausted"].any()
    assert (capped["bv_tests"] <= 1).all()


def test_point_trees_refuse_what_does_not_apply(tmp_path, gear, gear_cloud):
    cloud_tree = bvhlab.Tree(gear_cloud, "aabb", "adb")
    with pytest.raises(ValueError, match="all_contacts lists intersecting triangle pairs"):
        bvhlab.query(cloud_tree, cloud_tree, np.eye(4), strategy="all_contacts")
    with pytest.raises(ValueError, match="records no points"):
        cloud_tree.save(tmp_path / "cloud.tree")
    without_areas = bvhlab.PointCloud(gear_cloud.points)
    with pytest.raises(ValueError, match="no per-point areas"):
        bvhlab.Tree(without_areas, "aabb", "adb")
    assert bvhlab.Tree(without_areas, "aabb", "none").points == 4000  # exact needs no areas
    with pytest.raises(ValueError, match="does not annotate trees over points"):
        bvhlab.Tree(gear_cloud, "aabb", "adb_paper")
    with pytest.raises(ValueError, match="leaf"):
        bvhlab.Tree(gear_cloud, "aabb", leaf=0)
    with pytest.raises(bvhlab.PointCloudError):  # a surface needs k + 1 = 11 points
        bvhlab.Tree(bvhlab.PointCloud(gear_cloud.points[:5]), "aabb")
    plain = bvhlab.Tree(gear_cloud, "aabb")
    with pytest.raises(ValueError, match="does not run on trees with density 'none'"):
        bvhlab.query(plain, plain, np.eye(4), strategy="adb")
    with pytest.raises(ValueError, match="differ in BV or density"):
        bvhlab.query(plain, cloud_tree, np.eye(4))
    # A mesh side must carry its triangles: the cloud's surface is tested at them.
    saved = tmp_path / "gear.tree"
    bvhlab.Tree(gear, "aabb", "adb").save(saved)
    with pytest.raises(ValueError, match="holds no polygons"):
        bvhlab.query(cloud_tree, bvhlab.Tree.load(saved), np.eye(4))
    # One pose cannot be in two kinds of units.
    normalised = bvhlab.Tree(bvhlab.PointCloud.sample(gear.normalized(), 500), "aabb", "adb")
    with pytest.raises(ValueError, match="different units"):
        bvhlab.query(normalised, cloud_tree, np.eye(4))


def test_the_cli_queries_clouds_as_the_module_does(tmp_path, cli, gear_file, gear, gear_cloud):
    """`bvhlab query --cloud` and the module build the same trees from the same files (k-NN areas: a cloud
    file has none) and answer alike, with the same work."""
    path = tmp_path / "gear.ply"
    gear_cloud.save(path)
    loaded = bvhlab.PointCloud.load(path)
    loaded.assign_knn_areas(10)
    cloud_tree = bvhlab.Tree(loaded, "aabb", "adb")
    mesh_tree = bvhlab.Tree(gear, "aabb", "adb")
    answers = set()
    for x in (0.3, 1.0, 1.9, 2.5):
        for strategy, params in (("exact", {}), ("adb", {"p_min": 0.99})):
            options = ["--p-min", "0.99"] if params else []
            for b_file, b_tree, sides in ((path, cloud_tree, "both"), (gear_file, mesh_tree, "a")):
                expected = cli("query", path, b_file, "--cloud", sides, "--pose", f"{x},0.1,0",
                               "--strategy", strategy, *options, "--json")
                got = bvhlab.query(cloud_tree, b_tree, translation=[x, 0.1, 0], strategy=strategy, **params)
                assert (expected["collides"], expected["bv_tests"]) == (got.collides, got.counters["bv_tests"])
                answers.add(got.collides)
    assert answers == {True, False}
