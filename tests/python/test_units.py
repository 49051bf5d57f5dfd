"""Units: a mesh knows whether it is normalised (and how), its trees carry that, saved trees record it, and a
normalised tree is never queried against one in its file's units (the CLI's rule)."""
import numpy as np
import pytest

import bvhlab
from conftest import box_mesh

OWN = {"normalized": False, "scale": 1.0, "centre": (0.0, 0.0, 0.0), "scaled_by": 1.0}


def numbers(units):
    return {key: value for key, value in units.items() if key != "description"}


def test_a_mesh_records_its_normalisation():
    assert numbers(box_mesh(center=(3, 0, 0)).units) == OWN
    raw = bvhlab.load_mesh("pinion.off")
    assert numbers(raw.units) == OWN and raw.units["description"] == "the mesh file's units"
    low, high = raw.bounds
    units = bvhlab.load_mesh("pinion.off", normalize=True).units
    assert units["normalized"] and units["scaled_by"] == 1
    assert units["scale"] == pytest.approx(2 / (high - low).max(), rel=1e-15)
    np.testing.assert_allclose(units["centre"], (low + high) / 2, rtol=1e-15)
    assert units["description"].startswith("normalised: scale ")
    assert raw.normalized().units == units  # one computation, whichever way it is asked for
    assert raw.normalized().normalized().units == units
    with pytest.raises(AttributeError):
        raw.units = units
    scaled = bvhlab.load_mesh("pinion.off", normalize=True, scale=3)
    assert numbers(scaled.units) == {**numbers(units), "scaled_by": 3.0}
    assert scaled.units["description"].endswith(", then scaled by 3")
    with pytest.raises(ValueError, match="normalise before scaling"):
        scaled.normalized()


@pytest.mark.parametrize("normalize", [False, True])
def test_saved_trees_keep_their_units(tmp_path, cli, normalize):
    mesh = bvhlab.load_mesh("pinion.off", normalize=normalize)
    tree = bvhlab.Tree(mesh, "obb", "adb")
    assert tree.units == mesh.units
    path = tmp_path / "t.tree"
    tree.save(path)
    assert bvhlab.Tree.load(path).units == mesh.units
    assert bvhlab.Tree.load(path, mesh=mesh).units == mesh.units
    info = cli("info", path, "--json")
    assert info["normalized"] == normalize
    if normalize:
        assert info["normalization"]["scale"] == mesh.units["scale"]
        assert tuple(info["normalization"]["centre"]) == mesh.units["centre"]


def test_a_tree_of_a_scaled_mesh_is_not_saved(tmp_path):
    tree = bvhlab.Tree(bvhlab.load_mesh("pinion.off", scale=2))
    with pytest.raises(ValueError, match="scaled by 2"):
        tree.save(tmp_path / "t.tree")
    assert not (tmp_path / "t.tree").exists()


def test_a_mesh_in_other_units_than_the_saved_tree_is_refused(tmp_path):
    raw = bvhlab.load_mesh("pinion.off")
    normalised = raw.normalized()
    for tree_mesh, other in ((raw, normalised), (normalised, raw), (normalised, box_mesh())):
        path = tmp_path / "t.tree"
        bvhlab.Tree(tree_mesh).save(path)
        with pytest.raises(ValueError, match="differ in units") as refused:
            bvhlab.Tree.load(path, mesh=other)
        assert tree_mesh.units["description"] in str(refused.value)
        assert other.units["description"] in str(refused.value)


def test_normalised_and_raw_trees_are_not_queried_together(tmp_path):
    raw = bvhlab.Tree(bvhlab.load_mesh("pinion.off"), "aabb", "adb")
    normalised = bvhlab.Tree(bvhlab.load_mesh("teapot.obj", normalize=True), "aabb", "adb")
    path = tmp_path / "n.tree"
    normalised.save(path)
    poses = bvhlab.protocol_poses(1.5, 4)
    for a, b in ((raw, normalised), (bvhlab.Tree.load(path), raw)):
        for run in (lambda: bvhlab.query(a, b, poses[0], strategy="adb"),
                    lambda: bvhlab.query_batch(a, b, poses, strategy="adb")):
            with pytest.raises(ValueError, match="different units") as refused:
                run()
            assert raw.units["description"] in str(refused.value)
            assert normalised.units["description"] in str(refused.value)
    # the same kind of units on both sides is what queries need, not the same normalisation
    assert len(bvhlab.query_batch(normalised, bvhlab.Tree.load(path), poses, strategy="adb")["collides"]) == 4
    scaled = bvhlab.Tree(bvhlab.load_mesh("pinion.off", scale=2), "aabb", "adb")
    assert len(bvhlab.query_batch(raw, scaled, poses, strategy="adb")["collides"]) == 4


def test_a_tree_the_cli_normalised_is_normalised_here(tmp_path, cli, source_dir):
    path = tmp_path / "cli.tree"
    mesh_file = f"{source_dir}/meshes/pinion.off"
    cli("build", mesh_file, "--bv", "aabb", "--adb", "--normalize", "-o", path, parse_json=False)
    loaded = bvhlab.Tree.load(path)
    normalised = bvhlab.load_mesh(mesh_file, normalize=True)
    assert loaded.units == normalised.units and loaded.units["normalized"]
    assert bvhlab.Tree.load(path, mesh=normalised).has_polygons
    with pytest.raises(ValueError, match="differ in units"):
        bvhlab.Tree.load(path, mesh=bvhlab.load_mesh(mesh_file))
    with pytest.raises(ValueError, match="different units"):
        bvhlab.query(loaded, bvhlab.Tree(bvhlab.load_mesh(mesh_file), "aabb", "adb"), np.eye(4), strategy="adb")
