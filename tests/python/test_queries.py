"""Queries: exact answers against geometry, the batch against single queries, both against the bvhlab CLI."""
import threading
import time

import numpy as np
import pytest

import bvhlab
from conftest import box_mesh, matrix, rotation_z

STRATEGIES = [  # (strategy, its parameters, density the trees need)
    ("exact", {}, "none"),
    ("all_contacts", {}, "none"),
    ("guided_exact", {}, "adb"),
    ("guided_exact_dfs", {}, "adb"),
    ("adb", {"p_min": 0.5}, "adb"),
    ("adb", {"p_min": 0.95}, "adb"),
    ("adb_dfs", {"p_min": 0.9}, "adb"),
    ("adb_larger", {"p_min": 0.9}, "adb"),
    ("time_critical", {"p_min": 0.9, "bv_tests": 40}, "adb"),
    ("distance", {}, "none"),
    ("tolerance", {"tolerance": 0.05}, "none"),
    ("distance_anytime", {"bv_tests": 30}, "none"),
]
EXACT = [("exact", "none"), ("all_contacts", "none"), ("guided_exact", "adb"), ("guided_exact_dfs", "adb")]


@pytest.fixture(scope="module")
def cube_trees():
    """Unit cubes (side 1, centred) of every registered volume, with and without the ADB density."""
    cube = box_mesh()
    return {(bv, d): bvhlab.Tree(cube, bv, d) for bv in bvhlab.volumes() for d in ("none", "adb")}


@pytest.mark.parametrize("strategy,density", EXACT)
def test_exact_answers_follow_the_geometry(cube_trees, strategy, density):
    # B translated by d along x: the cubes touch at d = 1 (closed triangles: touching collides)
    distances = [0.5, 1.0, 1.0 + 1e-9, 1.5]
    expected = [True, True, False, False]
    # rotated 45 degrees about z, B reaches sqrt(1/2) along x: contact up to d = 1/2 + sqrt(1/2)
    reach = 0.5 + np.sqrt(0.5)
    turned = [reach - 1e-6, reach + 1e-6]
    for bv in bvhlab.volumes():
        tree = cube_trees[(bv, density)]
        for d, want in zip(distances, expected):
            r = bvhlab.query(tree, tree, translation=[d, 0, 0], strategy=strategy)
            assert (r.collides, r.exact, r.probability) == (want, True, float(want)), (bv, d)
        for d, want in zip(turned, [True, False]):
            r = bvhlab.query(tree, tree, matrix(rotation_z(45), [d, 0, 0]), strategy=strategy)
            assert r.collides == want, (bv, d)


@pytest.fixture(scope="module")
def stick_scene():
    """A: a small cube at (0, 1.5, 0). B: a stick along +x from the origin, length 2."""
    a = bvhlab.Tree(box_mesh(center=(0, 1.5, 0), half=(0.2, 0.2, 0.2)))
    b = bvhlab.Tree(box_mesh(center=(1, 0, 0), half=(1, 0.05, 0.05)))
    # (rotation about z, translation) -> whether the turned stick reaches A
    cases = [(90, [0, 0, 0], True), (-90, [0, 0, 0], False), (90, [0, -1, 0], False), (90, [0, 0.2, 0], True),
             (180, [0, 1.5, 0], True), (0, [-3, 1.5, 0], False)]
    return a, b, cases


def test_pose_layout_single_and_batch(stick_scene):
    """x -> R x + t with R row-major as numpy holds it: a transposed R would turn the stick the other way."""
    a, b, cases = stick_scene
    rotations = np.array([rotation_z(deg) for deg, _, _ in cases])
    translations = np.array([t for _, t, _ in cases], float)
    expected = [want for _, _, want in cases]
    for (deg, t, want), r in zip(cases, rotations):
        assert bvhlab.query(a, b, matrix(r, t)).collides == want, (deg, t)
        assert bvhlab.query(a, b, rotation=r, translation=t).collides == want, (deg, t)
    matrices = np.array([matrix(r, t) for r, t in zip(rotations, translations)])
    assert list(bvhlab.query_batch(a, b, matrices)["collides"]) == expected
    both = bvhlab.query_batch(a, b, rotations=rotations, translations=translations)
    assert list(both["collides"]) == expected
    # rotations default to identities: the stick along +x at y = 1.5 passes through A when moved left
    moved = bvhlab.query_batch(a, b, translations=[[-1, 1.5, 0], [-1, 3, 0]])
    assert list(moved["collides"]) == [True, False]


def test_witness_and_contacts(cube_trees):
    tree = cube_trees[("aabb", "none")]
    pose = matrix(rotation_z(30), [0.8, 0.1, 0])
    exact = bvhlab.query(tree, tree, pose)
    everything = bvhlab.query(tree, tree, pose, strategy="all_contacts")
    assert exact.collides and everything.collides
    contacts = {tuple(c) for c in everything.contacts}
    assert everything.contacts.shape[1] == 2 and len(contacts) == len(everything.contacts) > 1
    assert exact.witness in contacts
    assert all(0 <= a < 12 and 0 <= b < 12 for a, b in contacts)
    batch = bvhlab.query_batch(tree, tree, pose[None], strategy="all_contacts")
    assert batch["contact_count"][0] == len(contacts)
    apart = bvhlab.query(tree, tree, translation=[3, 0, 0], strategy="all_contacts")
    assert apart.witness is None and apart.contacts.shape == (0, 2)
    assert bvhlab.query_batch(tree, tree, translations=[[3, 0, 0]])["witness_a"][0] == -1


@pytest.fixture(scope="module")
def gear_trees(gear):
    return {d: bvhlab.Tree(gear, "aabb", d) for d in ("none", "adb")}


@pytest.mark.parametrize("strategy,params,density", STRATEGIES)
def test_batch_equals_single_queries(gear_trees, strategy, params, density):
    tree = gear_trees[density]
    poses = np.concatenate([bvhlab.protocol_poses(d, 24) for d in (0.8, 1.4, 2.0)])
    batch = bvhlab.query_batch(tree, tree, poses, strategy=strategy, **params)
    assert all(len(v) == len(poses) for v in batch.values())
    for k, pose in enumerate(poses):
        r = bvhlab.query(tree, tree, rotation=pose[:3, :3], translation=pose[:3, 3], strategy=strategy,
                         **params)
        single = {"collides": r.collides, "probability": r.probability, "exact": r.exact,
                  "budget_exhausted": r.budget_exhausted, "contact_count": len(r.contacts),
                  "witness_a": r.witness[0] if r.witness else -1,
                  "witness_b": r.witness[1] if r.witness else -1,
                  **r.counters}
        assert single == {key: batch[key][k].item() for key in single}, k
    if strategy in ("exact", "all_contacts", "guided_exact", "guided_exact_dfs"):
        np.testing.assert_array_equal(batch["probability"], batch["collides"].astype(float))
        assert batch["exact"].all()
    else:
        assert ((batch["probability"] >= 0) & (batch["probability"] <= 1)).all()


@pytest.mark.parametrize("strategy,params,density", STRATEGIES)
def test_queries_equal_the_cli(cli, gear_file, gear_trees, strategy, params, density):
    """The same query through `bvhlab query` (trees built by the runner)."""
    tree = gear_trees[density]
    options = ["--strategy", strategy, "--density", density, "--no-cache", "--json"]
    if strategy == "all_contacts":
        options.append("--all-contacts")  # the CLI prints the contacts for this flag only
    for name, value in params.items():
        options += ["--" + name.replace("_", "-"), value]
    for step in (0, 7, 23):
        expected = cli("query", gear_file, gear_file, "--protocol", f"1.2,{step},50", *options)
        r = bvhlab.query(tree, tree, bvhlab.protocol_pose(1.2, step, 50), strategy=strategy, **params)
        got = {"collides": r.collides, "probability": r.probability, "exact": r.exact,
               "budget_exhausted": r.budget_exhausted, **r.counters}
        assert got == {key: expected[key] for key in got}, step
        assert list(r.witness) == expected["witness"] if r.witness else "witness" not in expected
        if strategy == "all_contacts":
            assert sorted(map(list, r.contacts.tolist())) == sorted(expected["contacts"])


@pytest.mark.parametrize("bv", ["obb", "rbox", "sphere", "dop24"])
def test_every_volume_equals_the_cli(cli, gear_file, gear, bv):
    tree = bvhlab.Tree(gear, bv)
    expected = cli("query", gear_file, gear_file, "--protocol", "1.5,11,50", "--bv", bv, "--no-cache",
                   "--json")
    r = bvhlab.query(tree, tree, bvhlab.protocol_pose(1.5, 11, 50))
    assert (r.collides, r.counters["bv_tests"], r.counters["triangle_tests"]) == (
        expected["collides"], expected["bv_tests"], expected["triangle_tests"])


def test_distances_follow_the_geometry(cube_trees):
    """Unit cubes d apart along x face each other across a gap of d - 1; rotated, the batch gives the same."""
    runs_on = next(s for s in bvhlab.policies()["strategies"] if s["name"] == "distance")["volumes"]
    assert "aabb" in runs_on and "rbox" not in runs_on
    poses = np.stack([matrix(rotation_z(a), [2.5, 0.1, 0]) for a in range(0, 90, 10)])
    for bv in bvhlab.volumes():
        tree = cube_trees[(bv, "none")]
        if bv not in runs_on:
            with pytest.raises(ValueError, match=f"volume '{bv}', which has no distance bound"):
                bvhlab.query(tree, tree, translation=[2, 0, 0], strategy="distance")
            continue
        for d in (0.5, 1.25, 3.0):
            r = bvhlab.query(tree, tree, translation=[d, 0, 0], strategy="distance")
            assert r.distance == pytest.approx(max(d - 1, 0), abs=1e-15), (bv, d)
            assert r.lower_bound == r.distance and r.collides == (d < 1)
            assert r.points.shape == (2, 3) and len(r.nearest) == 2
            assert np.linalg.norm(r.points[1] - r.points[0]) == pytest.approx(r.distance, abs=1e-15)
        batch = bvhlab.query_batch(tree, tree, poses, strategy="distance")
        assert batch["points"].shape == (len(poses), 2, 3)
        for k, pose in enumerate(poses):
            r = bvhlab.query(tree, tree, pose, strategy="distance")
            assert batch["distance"][k] == r.distance and (batch["nearest_a"][k], batch["nearest_b"][k]) == r.nearest
            np.testing.assert_array_equal(batch["points"][k], r.points)
    tree = cube_trees[("aabb", "none")]
    exact = bvhlab.query_batch(tree, tree, poses)
    assert np.isnan(exact["distance"]).all() and (exact["nearest_a"] == -1).all()
    assert bvhlab.query(tree, tree, translation=[3, 0, 0]).distance is None


def test_contact_geometry_lies_where_the_cubes_meet(cube_trees):
    """Unit cubes half overlapping: every contact's segment lies in the overlap box, its normal is unit."""
    tree = cube_trees[("aabb", "none")]
    shift = np.array([0.5, 0.2, 0.1])
    r = bvhlab.query(tree, tree, translation=shift, strategy="all_contacts", contact_geometry=True)
    g = r.contact_geometry
    k = len(r.contacts)
    assert k > 0 and g["triangles"].shape == (k, 2) and g["segments"].shape == (k, 2, 3)
    np.testing.assert_array_equal(g["triangles"], r.contacts)
    low, high = np.maximum(-0.5, shift - 0.5), np.minimum(0.5, shift + 0.5)
    for points in (g["segments"][:, 0], g["segments"][:, 1], g["points"]):
        assert (points >= low - 1e-12).all() and (points <= high + 1e-12).all()
    np.testing.assert_allclose(g["points"], g["segments"].mean(axis=1), atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(g["normals"], axis=1), 1, atol=1e-12)
    first = bvhlab.query(tree, tree, translation=shift, contact_geometry=True)
    assert first.contact_geometry["triangles"].tolist() == [list(first.witness)]
    assert bvhlab.query(tree, tree, translation=shift).contact_geometry is None
    assert len(bvhlab.query(tree, tree, translation=[3, 0, 0], contact_geometry=True).contact_geometry["points"]) == 0
    with pytest.raises(ValueError, match="strategy adb tests no triangles"):
        adb = cube_trees[("aabb", "adb")]
        bvhlab.query(adb, adb, translation=shift, strategy="adb", contact_geometry=True)


@pytest.mark.parametrize("strategy", ["exact", "all_contacts"])
def test_batch_contact_geometry_is_the_single_queries(gear_trees, strategy):
    """query_batch(..., contact_geometry=True): pose i's contacts are rows offsets[i]:offsets[i + 1], the
    geometry query(..., contact_geometry=True) gives at that pose."""
    tree = gear_trees["none"]
    poses = np.concatenate([bvhlab.protocol_poses(d, 12) for d in (1.0, 2.0)])
    batch = bvhlab.query_batch(tree, tree, poses, strategy=strategy, contact_geometry=True)
    offsets = batch["contact_offsets"]
    assert offsets.shape == (len(poses) + 1,) and offsets[0] == 0 and (np.diff(offsets) >= 0).all()
    rows = offsets[-1]
    assert rows > 0 and batch["contact_segments"].shape == (rows, 2, 3)
    for i, pose in enumerate(poses):
        single = bvhlab.query(tree, tree, pose, strategy=strategy, contact_geometry=True).contact_geometry
        for key in ("triangles", "segments", "points", "normals", "coplanar"):
            np.testing.assert_array_equal(batch["contact_" + key][offsets[i]:offsets[i + 1]], single[key])
    counts = np.diff(offsets)
    assert (counts[batch["collides"]] > 0).all() and (counts[~batch["collides"]] == 0).all()
    assert batch["collides"].any() and not batch["collides"].all()
    assert "contact_offsets" not in bvhlab.query_batch(tree, tree, poses, strategy=strategy)
    with pytest.raises(ValueError, match="tests no triangles"):
        adb = gear_trees["adb"]
        bvhlab.query_batch(adb, adb, poses, strategy="adb", contact_geometry=True)


def test_budget_is_kept(gear_trees):
    tree = gear_trees["adb"]
    poses = bvhlab.protocol_poses(1.6, 40)
    out = bvhlab.query_batch(tree, tree, poses, strategy="time_critical", bv_tests=15)
    assert (out["bv_tests"] <= 15).all()
    assert out["budget_exhausted"].any()
    assert not out["exact"][out["budget_exhausted"]].any()


def test_protocol_poses_are_the_protocol():
    poses = bvhlab.protocol_poses(1.5, 8)
    assert poses.shape == (8, 4, 4)
    for k, pose in enumerate(poses):
        theta = 2 * np.pi * k / 8
        c, s = np.cos(theta), np.sin(theta)
        rz = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
        rx = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
        np.testing.assert_allclose(pose, matrix(rz @ rx, [1.5, 0, 0]), atol=1e-15)
        np.testing.assert_array_equal(bvhlab.protocol_pose(1.5, k, 8), pose)


def test_concurrent_batches_answer_as_one(gear_trees):
    """Batches run without the GIL: two threads at once give what one thread gives."""
    tree = gear_trees["adb"]
    poses = np.concatenate([bvhlab.protocol_poses(d, 200) for d in (1.0, 1.6)])
    expected = {s: bvhlab.query_batch(tree, tree, poses, strategy=s) for s in ("exact", "adb")}
    results = {}

    def work(strategy):
        results[strategy] = bvhlab.query_batch(tree, tree, poses, strategy=strategy)

    threads = [threading.Thread(target=work, args=(s,)) for s in expected]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for s in expected:
        for key in expected[s]:
            np.testing.assert_array_equal(results[s][key], expected[s][key], err_msg=f"{s} {key}")


def test_batch_releases_the_gil(gear_trees):
    """While one thread runs a batch, another runs Python: the GIL is released around the loop (held
    throughout, it would keep this thread from waking up between the batch's start and its end)."""
    tree = gear_trees["none"]
    poses = bvhlab.protocol_poses(0.9, 1000)
    while True:  # a batch long enough to look into its middle
        start = time.perf_counter()
        bvhlab.query_batch(tree, tree, poses)
        if time.perf_counter() - start > 0.3:
            break
        poses = np.concatenate([poses, poses])
    worker = threading.Thread(target=bvhlab.query_batch, args=(tree, tree, poses))
    stamps = []
    begin = time.perf_counter()
    worker.start()
    while worker.is_alive():
        stamps.append(time.perf_counter())
        time.sleep(0.001)
    end = time.perf_counter()
    low, high = begin + 0.3 * (end - begin), begin + 0.7 * (end - begin)
    assert any(low < s < high for s in stamps)


def test_ctrl_c_interrupts_a_batch_within_half_a_second(gear_trees):
    """SIGINT (Ctrl-C) in the middle of a batch raises KeyboardInterrupt soon after, not after the batch: the
    loop hands the signal to Python between chunks of poses. The batch is made long enough (at least 3 s) that
    an answer after the whole batch would be far too late."""
    import os
    import signal

    tree = gear_trees["none"]
    poses = bvhlab.protocol_poses(0.9, 1000)
    start = time.perf_counter()
    bvhlab.query_batch(tree, tree, poses)
    per_pose = max(time.perf_counter() - start, 1e-6) / len(poses)
    repeats = min(4000, int(np.ceil(3.0 / per_pose / len(poses))))
    long_batch = np.tile(poses, (repeats, 1, 1))
    timer = threading.Timer(0.2, lambda: os.kill(os.getpid(), signal.SIGINT))
    begin = time.perf_counter()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        bvhlab.query_batch(tree, tree, long_batch)
    late = time.perf_counter() - begin - 0.2
    timer.join()
    assert late < 0.5, f"KeyboardInterrupt {late:.2f} s after Ctrl-C (a batch of {len(long_batch)} poses)"


def assert_same_answers_with_less_work(reference, other, work):
    """Two batches of the same poses: the same answers and contacts, some colliding and some not, and the
    second with less of `work` in all."""
    for key in ("collides", "exact", "contact_count"):
        np.testing.assert_array_equal(other[key], reference[key], err_msg=key)
    assert 0 < reference["collides"].sum() < len(reference["collides"])
    assert other[work].sum() < reference[work].sum()


@pytest.mark.parametrize("strategy", ["exact", "all_contacts"])
def test_coherent_batches_answer_as_cold_ones_with_less_work(gear_trees, strategy):
    """coherent=True starts each pose where the previous one ended: the cold answers, fewer BV tests; a
    CoherentState carries the sequence over to the next call, and chunked or split, the work is the same."""
    tree = gear_trees["none"]
    poses = np.concatenate([bvhlab.protocol_poses(d, 150) for d in (1.4, 2.0)])
    coherent = bvhlab.query_batch(tree, tree, poses, strategy=strategy, coherent=True)
    assert_same_answers_with_less_work(bvhlab.query_batch(tree, tree, poses, strategy=strategy), coherent,
                                       "bv_tests")
    state = bvhlab.CoherentState()
    half = len(poses) // 2
    first = bvhlab.query_batch(tree, tree, poses[:half], strategy=strategy, coherent=True, state=state)
    assert state.front_size > 0 or state.witness_hits > 0  # what the first half left
    second = bvhlab.query_batch(tree, tree, poses[half:], strategy=strategy, coherent=True, state=state)
    np.testing.assert_array_equal(np.concatenate([first["bv_tests"], second["bv_tests"]]), coherent["bv_tests"])


@pytest.mark.parametrize("strategy", ["exact", "all_contacts"])
def test_wide_batches_answer_as_binary_ones(gear, strategy):
    """wide=True walks the trees' wide layout: the binary walk's answers (and contacts) on fewer node pairs,
    the single query too; refused by name where it does not run."""
    trees = {bv: bvhlab.Tree(gear, bv, "none") for bv in ("obb", "rss")}
    tree = trees["obb"]
    poses = np.concatenate([bvhlab.protocol_poses(d, 60) for d in (0.9, 1.4, 2.0)])
    binary = bvhlab.query_batch(tree, tree, poses, strategy=strategy)
    assert_same_answers_with_less_work(binary, bvhlab.query_batch(tree, tree, poses, strategy=strategy, wide=True),
                                       "nodes_visited")
    single = bvhlab.query(tree, tree, poses[0], strategy=strategy, wide=True)
    assert single.collides == bool(binary["collides"][0])
    with pytest.raises(ValueError, match="strategy adb_dfs does not run on wide trees"):
        bvhlab.query_batch(tree, tree, poses, strategy="adb_dfs", wide=True)
    with pytest.raises(ValueError, match="bounding volume 'rss' has no wide layout"):
        bvhlab.query_batch(trees["rss"], trees["rss"], poses, strategy=strategy, wide=True)
    with pytest.raises(ValueError, match="coherent or wide, not both"):
        bvhlab.query_batch(tree, tree, poses, strategy=strategy, wide=True, coherent=True)


def test_wide_adb_batches_are_honest(gear_trees):
    """strategy="adb" with wide=True walks the wide layout of an annotated tree: its own answers (other pairs
    are estimated), an exact "no" only where the exact answer is "no", four BV tests a step."""
    tree = gear_trees["adb"]
    poses = np.concatenate([bvhlab.protocol_poses(d, 40) for d in (0.8, 1.4, 2.0)])
    truth = bvhlab.query_batch(tree, tree, poses, strategy="exact")["collides"]
    walked = bvhlab.query_batch(tree, tree, poses, strategy="adb", p_min=0.9, wide=True)
    exact_no = walked["exact"] & ~walked["collides"]
    assert not truth[exact_no].any()
    assert (walked["probability"][walked["collides"]] > 0.9).all()
    assert (walked["bv_tests"] % 4 == 1).all()
    assert 0 < walked["collides"].sum() < len(poses)


def test_wide_distances_are_the_binary_ones(gear):
    """strategy="distance" with wide=True walks an OBB tree's wide layout: the binary walk's distances, bit for
    bit; on boxes it is refused by name."""
    tree = bvhlab.Tree(gear, "obb", "none")
    poses = np.concatenate([bvhlab.protocol_poses(d, 40) for d in (1.0, 1.6, 2.0)])
    binary = bvhlab.query_batch(tree, tree, poses, strategy="distance")
    walked = bvhlab.query_batch(tree, tree, poses, strategy="distance", wide=True)
    np.testing.assert_array_equal(walked["distance"], binary["distance"])
    assert (binary["distance"] > 0).sum() > 20 and (binary["distance"] == 0).sum() > 5
    boxes = bvhlab.Tree(gear, "aabb", "none")
    with pytest.raises(ValueError, match="strategy distance has no wide walk on 'aabb' trees"):
        bvhlab.query(boxes, boxes, poses[0], strategy="distance", wide=True)


def test_coherent_states_take_their_bounds(gear_trees):
    """CoherentState's keywords are its bounds: with max_jump 0 every pose that is not answered by the
    remembered contact or the root pair alone jumps, and jumps in a row cost the cold query's work (and at
    most that test more); the default sees no jump on small steps. Nonsense is refused by name."""
    tree = gear_trees["none"]
    poses = bvhlab.protocol_poses(1.4, 2000)[:60]  # steps of 0.18 degrees
    cold = bvhlab.query_batch(tree, tree, poses)
    jumping = bvhlab.CoherentState(max_jump=0.0, max_cold_run=0)
    assert jumping.options["max_jump"] == 0.0 and jumping.options["max_cold_run"] == 0
    every = bvhlab.query_batch(tree, tree, poses, coherent=True, state=jumping)
    np.testing.assert_array_equal(every["collides"], cold["collides"])
    assert jumping.jumps > len(poses) // 2
    assert (every["bv_tests"][2:] <= cold["bv_tests"][2:] + 1).all()
    steady = bvhlab.CoherentState()
    assert steady.options == {"max_jump": 0.2, "max_pairs": 2**18, "max_cold_run": 128, "raise_hold": 8,
                              "judge": "work"}
    bvhlab.query_batch(tree, tree, poses, coherent=True, state=steady)
    assert steady.jumps == 0
    for bad, name in [({"max_jump": -1.0}, "max_jump"), ({"max_jump": float("nan")}, "max_jump"),
                      ({"max_pairs": 0}, "max_pairs"), ({"raise_hold": 256}, "raise_hold"),
                      ({"judge": "fast"}, "judge")]:
        with pytest.raises(ValueError, match=name):
            bvhlab.CoherentState(**bad)


def test_coherent_batches_refuse_what_cannot_run_coherent(gear_trees):
    tree, annotated = gear_trees["none"], gear_trees["adb"]
    poses = bvhlab.protocol_poses(1.0, 10)
    assert all(s["coherent"] for s in bvhlab.policies()["strategies"])  # refusals: test_policies.cpp
    with pytest.raises(ValueError, match="give coherent=True"):
        bvhlab.query_batch(tree, tree, poses, state=bvhlab.CoherentState())
    state = bvhlab.CoherentState()
    bvhlab.query_batch(tree, tree, poses, coherent=True, state=state)
    with pytest.raises(ValueError, match="made for other trees"):
        bvhlab.query_batch(annotated, annotated, poses, coherent=True, state=state)
