"""Scenes: the rows run_scene returns are the CLI's results.csv, and each row is what the batch query answers
on the same trees and poses."""
import csv
import json
import os

import numpy as np
import pytest

import bvhlab

DISTANCES, STEPS = [0.8, 1.4, 2.0], 24


def scene(gear_file):
    return {
        "name": "python",
        "objects": [{"mesh": str(gear_file), "name": "gear"}],
        "hierarchies": [{"bv": "aabb"}, {"bv": "obb"}],
        "annotation": {"type": "adb", "grid": 2, "tau": 0.25},
        "strategies": [{"type": "exact"}, {"type": "adb", "p_min": [0.5, 0.9]}],
        "workload": {"type": "protocol", "distances": DISTANCES, "steps": STEPS},
        "report": {"cgal_sample": 4},
    }


@pytest.fixture(scope="module")
def run(gear_file):
    return bvhlab.run_scene(scene(gear_file))


# Columns that do not depend on timing.
DETERMINED = ["mesh", "hierarchy", "bv", "annotation", "strategy", "label", "budget", "queries", "distance",
              "truth_colliding_rate", "answer_colliding_rate", "fp_rate", "fn_rate", "inexact_rate",
              "bv_tests_per_query", "triangle_tests_per_query", "nodes_visited_per_query", "model_bytes"]


def test_rows_are_the_clis(tmp_path, cli, gear_file, run):
    scene_file = tmp_path / "scene.json"
    scene_file.write_text(json.dumps(scene(gear_file)))
    cli("run", scene_file, "-o", tmp_path / "out", "--no-cache", "-q", parse_json=False)
    with open(tmp_path / "out" / "results.csv") as f:
        expected = list(csv.DictReader(f))
    assert len(run["rows"]) == len(expected) == 2 * 3 * len(DISTANCES)
    for row, want in zip(run["rows"], expected):
        for column in DETERMINED:
            value = row[column]
            if isinstance(value, str):
                assert value == want[column], column
            else:  # results.csv prints 6 significant digits
                assert value == pytest.approx(float(want[column]), rel=1e-5, abs=1e-12), column
    # and a scene file runs like the dict
    again = bvhlab.run_scene(scene_file)
    assert [{c: r[c] for c in DETERMINED} for r in again["rows"]] == [{c: r[c] for c in DETERMINED}
                                                                        for r in run["rows"]]


def test_rows_agree_with_batch_queries(gear, run):
    trees = {bv: bvhlab.Tree(gear, bv, "adb") for bv in ("aabb", "obb")}
    for row in run["rows"]:
        tree = trees[row["bv"]]
        params = {"p_min": row["p_min"]} if row["strategy"] == "adb" else {}
        out = bvhlab.query_batch(tree, tree, bvhlab.protocol_poses(row["distance"], STEPS),
                                 strategy=row["strategy"], **params)
        assert row["queries"] == STEPS
        assert row["answer_colliding_rate"] == pytest.approx(out["collides"].mean()), row["label"]
        assert row["bv_tests_per_query"] == pytest.approx(out["bv_tests"].mean()), row["label"]
        if row["strategy"] == "exact":
            assert row["truth_colliding_rate"] == pytest.approx(out["collides"].mean())
    rates = [r["truth_colliding_rate"] for r in run["rows"]]
    assert min(rates) < 1 and max(rates) > 0, "the distances should span colliding and separated poses"


def test_the_rest_of_results_json(run):
    assert run["scene"]["name"] == "python"
    assert run["stats"]["queries"] == len(run["rows"]) * STEPS
    assert run["stats"]["cgal_mismatches"] == 0 and run["stats"]["cgal_checked"] > 0
    assert {m["bv"] for m in run["models"]} == {"aabb", "obb"}
    assert [s["name"] for s in run["policies"]["strategies"]] == bvhlab.strategies()
    assert [d["name"] for d in bvhlab.policies()["densities"]] == bvhlab.densities()
    assert np.isfinite([c["bin_low"] for c in run["calibration"]]).all()


def test_times_are_per_pose_statistics_of_warm_passes(gear_file):
    warm = scene(gear_file)
    warm["timing"] = {"repeats": 3, "statistic": "median"}
    out = bvhlab.run_scene(warm)
    stats = out["stats"]
    assert stats["timing_repeats"] == 3 and stats["timing_statistic"] == "median"
    assert stats["timed_samples"] == 3 * stats["queries"]
    assert 0 <= stats["stalled_samples"] <= stats["timed_samples"]
    for row in out["rows"]:
        assert 0 <= row["median_time_us"] <= row["p99_time_us"] <= row["max_time_us"], row["label"]
    # the summary band: where the gear's ground truth has both colliding and separated poses, else all
    mixed = {r["distance"] for r in out["rows"] if 0.05 <= r["truth_colliding_rate"] <= 0.95}
    inside = {r["distance"] for r in out["rows"] if r["in_summary"]}
    assert inside == ({d for d in DISTANCES if min(mixed) <= d <= max(mixed)} if mixed else set(DISTANCES))


def test_bad_timing_is_refused_naming_the_field(gear_file):
    bad = scene(gear_file)
    bad["timing"] = {"repeats": 0}
    with pytest.raises(ValueError, match="/timing/repeats: expected at least 1"):
        bvhlab.run_scene(bad)


def test_calibrated_series_come_back_beside_the_raw_ones(gear_file, run):
    calibrated = bvhlab.run_scene(dict(scene(gear_file), calibration={"training_seed": 3, "training_steps": 40}))
    # The answers are the raw strategy's: the same rows; the calibration bins come twice, raw then calibrated.
    assert [r["answer_colliding_rate"] for r in calibrated["rows"]] == [r["answer_colliding_rate"]
                                                                        for r in run["rows"]]
    bins = calibrated["calibration"]
    assert len(bins) == 2 * len(run["calibration"])
    assert [b["calibrated"] for b in bins[:20]] == [False] * 10 + [True] * 10
    assert calibrated["stats"]["calibration_fitted"] + calibrated["stats"]["calibration_cache_hits"] == 4
    for raw, through_map in zip(bins[0::20], bins[10::20]):
        assert (raw["hierarchy"], raw["p_min"]) == (through_map["hierarchy"], through_map["p_min"])


def test_per_pose_records(gear, gear_file):
    with pytest.raises(ValueError, match='per_pose: expected one of none, all, wrong; got "some"'):
        bvhlab.run_scene(scene(gear_file), per_pose="some")
    assert "poses" not in bvhlab.run_scene(scene(gear_file))
    everything = bvhlab.run_scene(scene(gear_file), per_pose="all")
    poses = everything["poses"]
    assert len(poses) == sum(r["queries"] for r in everything["rows"])
    trees = {bv: bvhlab.Tree(gear, bv, "adb") for bv in ("aabb", "obb")}
    for record in poses[::7]:  # the pose column is [R | t] row by row: a 4 x 4 matrix less its last row
        matrix = np.vstack([np.array([float(x) for x in record["pose"].split(",")]).reshape(3, 4), [0, 0, 0, 1]])
        params = {"p_min": record["p_min"]} if record["strategy"] == "adb" else {}
        tree = trees[record["bv"]]
        assert bvhlab.query(tree, tree, matrix, strategy=record["strategy"], **params).collides == \
            record["answer"], record
        assert bvhlab.query(tree, tree, matrix).collides == record["truth"], record
    wrong = bvhlab.run_scene(scene(gear_file), per_pose="wrong")
    errors = sum(round((r["fp_rate"] + r["fn_rate"]) * r["queries"]) for r in wrong["rows"])
    assert len(wrong["poses"]) == errors > 0
    assert all(p["answer"] != p["truth"] and p["false_positive"] != p["false_negative"] for p in wrong["poses"])


def world_scene(gear_file):
    return {
        "objects": [{"mesh": str(gear_file), "name": "gear"}],
        "hierarchies": [{"bv": "aabb", "annotation": {"type": "adb"}}],
        "strategies": [{"type": "exact"}],
        "world": {"instances": [{"object": "gear", "count": 10}],
                  "region": {"min": [-2, -2, -2], "max": [2, 2, 2]},
                  "motion": {"type": "random_walk", "frames": 4, "seed": 5, "step": 0.2, "turn_deg": 10},
                  "frame_budgets": [{"schedules": ["adb_probability"], "budgets": [{"bv_tests": 1}]}]},
    }


def test_world_scene_rows(gear, gear_file, cli, tmp_path):
    world = bvhlab.run_scene(world_scene(gear_file))
    assert world["instances"] == 10 and world["frames"] == 4
    exact = [r for r in world["series"] if r["series"] == "exact" and r["hierarchy"] == "aabb"]  # not FCL's
    budgeted = [r for r in world["series"] if r["schedule"] == "adb_probability"]
    assert len(exact) == len(budgeted) == 4
    assert sum(r["colliding"] for r in exact) > 0
    assert all(r["missed"] == r["false_pairs"] == 0 for r in exact)
    assert sum(r["flagged"] for r in budgeted) > 0  # one BV test cannot settle a crowded frame
    # The CLI writes the same exact answers per frame.
    file = tmp_path / "world.json"
    file.write_text(json.dumps(world_scene(gear_file)))
    cli("run", file, "-o", tmp_path / "out", "--quiet", parse_json=False)
    with open(tmp_path / "out" / "world_frames.csv") as f:
        rows = [r for r in csv.DictReader(f) if r["series"] == "exact" and r["hierarchy"] == "aabb"]
    assert [int(r["colliding"]) for r in rows] == [r["colliding"] for r in exact]


def test_world_pair_rows_add_up_to_the_frame_rows(gear_file, cli, tmp_path):
    everything = bvhlab.run_scene(world_scene(gear_file), per_pose="all")
    wrong = bvhlab.run_scene(world_scene(gear_file), per_pose="wrong")
    assert "pairs" not in bvhlab.run_scene(world_scene(gear_file))
    frames = [r for r in everything["series"] if r["hierarchy"] == "aabb"]
    for row in frames:
        mine = [p for p in everything["pairs"]
                if p["frame"] == row["frame"] and p["series"] == row["series"] and p["hierarchy"] == "aabb"]
        assert len(mine) == row["candidates"]
        assert sum(p["truth"] for p in mine) == row["colliding"]
        assert sum(p["collides"] and not p["truth"] for p in mine) == row["false_pairs"]
        assert sum(p["truth"] and not p["collides"] for p in mine) == row["missed"]
        assert sum(p["flagged"] for p in mine) == row["flagged"]
        assert sum(p["bv_tests"] for p in mine) == row["bv_tests"]
        timed = [p["micros"] for p in mine]
        assert all(t is None for t in timed) if row["schedule"] else all(t >= 0 for t in timed)
    assert wrong["pairs"] == [p for p in everything["pairs"] if p["collides"] != p["truth"]] != []
    # The CLI writes the same rows to world_pairs.csv.
    file = tmp_path / "world.json"
    file.write_text(json.dumps(world_scene(gear_file)))
    cli("run", file, "-o", tmp_path / "out", "--quiet", "--per-pose", "wrong", parse_json=False)
    with open(tmp_path / "out" / "world_pairs.csv") as f:
        written = list(csv.DictReader(f))
    assert [(int(r["frame"]), r["series"], r["a"], r["b"], int(r["collides"])) for r in written] == [
        (p["frame"], p["series"], p["a"], p["b"], int(p["collides"])) for p in wrong["pairs"]]


def deform_scene(gear_file):
    return {
        "objects": [{"mesh": str(gear_file), "name": "gear", "normalize": True}],
        "hierarchies": [{"bv": "aabb"}, {"bv": "obb"}],
        "annotation": {"type": "adb"},
        "strategies": [{"type": "exact"}, {"type": "adb", "p_min": 0.9, "hierarchies": ["aabb"]}],
        "deform": {"object": "gear", "deformation": "bend", "frames": 2,
                   "poses": {"distances": [1.0, 1.8], "steps": 4},
                   "density_updates": [{"type": "stale"}, {"type": "recount_all"}]},
    }


def test_deform_scene_rows(gear_file, cli, tmp_path):
    deform = bvhlab.run_scene(deform_scene(gear_file))
    assert deform["frames"] == 2 and deform["poses"] == 8
    rows = deform["rows"]
    exact = [r for r in rows if r["exact_strategy"]]
    assert {(r["hierarchy"], r["update"]) for r in exact} == {
        ("aabb", "refit"), ("aabb", "rebuild"), ("obb", "refit"), ("obb", "rebuild")}
    assert all(r["missed"] == r["false_pairs"] == 0 for r in exact)
    recounted = [r for r in rows if r["update"] == "refit + recount_all"]
    assert recounted and all(r["count_error"] == 0 for r in recounted)
    # The CLI writes the same rows.
    file = tmp_path / "deform.json"
    file.write_text(json.dumps(deform_scene(gear_file)))
    cli("run", file, "-o", tmp_path / "out", "--quiet", parse_json=False)
    with open(tmp_path / "out" / "deform_frames.csv") as f:
        written = list(csv.DictReader(f))
    assert [(r["hierarchy"], r["update"], int(r["colliding"])) for r in written] == [
        (r["hierarchy"], r["update"], r["colliding"]) for r in rows]
    with pytest.raises(ValueError, match="per_pose: does not apply to a deform scene"):
        bvhlab.run_scene(deform_scene(gear_file), per_pose="all")


def test_points_scene_rows(source_dir, cli, tmp_path):
    """A points scene runs from Python as from the CLI: the same experiment behind both, the same rows."""
    scene_file = os.path.join(source_dir, "bench", "scenes", "points_small.json")
    points = bvhlab.run_scene(scene_file)
    summary = points["summary"]
    assert {r["series"] for r in summary} >= {"exact_mesh", "exact_points", "adb p_min=0.9"}
    exact_mesh = [r for r in summary if r["series"] == "exact_mesh"]
    assert exact_mesh and all(r["fp"] == r["fn"] == 0 for r in exact_mesh)
    assert points["cgal_mismatches"] == 0 and points["cgal_checked"] > 0
    cli("run", scene_file, "-o", tmp_path / "out", "--quiet", parse_json=False)
    with open(tmp_path / "out" / "points_summary.csv") as f:
        written = list(csv.DictReader(f))
    key = lambda r: (r["pair"], int(r["points"]), r["series"], int(r["clear"]), int(r["fp"]), int(r["fn"]))
    assert [key(r) for r in written] == [key(r) for r in summary]
    with pytest.raises(ValueError, match="per_pose: does not apply to a points scene"):
        bvhlab.run_scene(scene_file, per_pose="wrong")
