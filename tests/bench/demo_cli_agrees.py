"""The demo's CLI (bvhlab-demo, `make demo`) against the full one: on every volume it compiles, the same
answers and work on colliding and separate poses, with and without ADB; any other volume, any other
density, and any scene but a pairs scene, refused by name.

Usage: demo_cli_agrees.py FULL_CLI DEMO_CLI
"""
import json
import os
import subprocess
import sys
import tempfile

DEMO_VOLUMES = ["aabb", "dop24", "obb", "rbox"]
LEFT_OUT = ["dop6", "dop14", "dop18", "dop26", "sphere"]
POSES = ["0.5,0,0", "1.2,0.3,0", "2.5,0,0"]
ANSWER = ["collides", "bv_tests", "triangle_tests", "nodes_visited", "probability", "witness"]


def query(cli, bv, pose, strategy):
    command = [cli, "query", "pinion.off", "pinion.off", "--normalize", "--bv", bv, "--pose", pose,
               "--no-cache", "--json"] + strategy
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    return done.returncode, done.stdout, done.stderr


def main(full, demo):
    failures = []
    for bv in DEMO_VOLUMES:
        for strategy in ([], ["--strategy", "adb", "--p-min", "0.9"]):
            for pose in POSES:
                answers = []
                for cli in (full, demo):
                    status, out, err = query(cli, bv, pose, strategy)
                    if status != 0:
                        failures.append(f"{cli} {bv} {pose} {strategy}: status {status}: {err.strip()}")
                        break
                    answer = json.loads(out)
                    answers.append({key: answer.get(key) for key in ANSWER})
                if len(answers) == 2 and answers[0] != answers[1]:
                    failures.append(f"{bv} {pose} {strategy}: full {answers[0]} demo {answers[1]}")
    for bv in LEFT_OUT:
        status, _, err = query(demo, bv, POSES[0], [])
        expected = f"bounding volume {bv} is not compiled into this program"
        if status != 1 or expected not in err:
            failures.append(f"demo CLI on {bv}: status {status}, stderr {err.strip()!r}; expected {expected!r}")
        status, _, err = query(full, bv, POSES[0], [])
        if status != 0:
            failures.append(f"full CLI on {bv}: status {status}: {err.strip()}")
    for density in ("adb_paper", "adb_normal"):
        strategy = ["--strategy", "adb", "--density", density]
        status, _, err = query(demo, "aabb", POSES[0], strategy)
        expected = f"density {density} on aabb trees is not compiled into this program"
        if status != 1 or expected not in err:
            failures.append(f"demo CLI on {density}: status {status}, stderr {err.strip()!r}; expected {expected!r}")
        status, _, err = query(full, "aabb", POSES[0], strategy)
        if status != 0:
            failures.append(f"full CLI on {density}: status {status}: {err.strip()}")
    scenes = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "bench", "scenes")
    with tempfile.TemporaryDirectory() as out:
        for kind in ("world", "deform", "points"):
            command = [demo, "report", os.path.join(scenes, kind + ".json"), "-o", out, "--no-cache", "--quiet"]
            done = subprocess.run(command, capture_output=True, text=True, check=False)
            expected = f"/{kind}: a {kind} scene is not run by this program (the demo's"
            if done.returncode != 1 or expected not in done.stderr:
                failures.append(f"demo CLI on {kind}.json: status {done.returncode}, stderr "
                                f"{done.stderr.strip()!r}; expected {expected!r}")
    for failure in failures:
        print(failure)
    print(f"{len(failures)} failures")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
