"""The world report's figures: wrong pairs per schedule against the frame budget, computed from the rows as
missed plus false over candidates, and the broad-phase time against the object count.

Run by ctest with BVHLAB_SOURCE_DIR set; plain unittest, so it needs nothing beyond matplotlib.
"""
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.environ.get("BVHLAB_SOURCE_DIR", "."), "bench"))

import plot_world  # noqa: E402


def frame_row(schedule, budget, candidates, missed, false_pairs, series=None):
    return {"frame": "0", "hierarchy": "aabb", "series": series or f"frame {schedule} {budget}",
            "schedule": schedule, "budget": budget, "candidates": str(candidates), "missed": str(missed),
            "false_pairs": str(false_pairs)}


class WorldFigures(unittest.TestCase):
    def test_wrong_pairs_count_missed_and_false_over_all_frames(self):
        rows = [frame_row("equal_split", "bv_tests=100", 10, 1, 1), frame_row("equal_split", "bv_tests=100", 30, 0, 2)]
        self.assertAlmostEqual(plot_world.wrong_percent(rows), 100.0 * 4 / 40)

    def test_budgets_are_read_by_kind(self):
        self.assertEqual(plot_world.budget_value("bv_tests=200"), ("bv_tests", 200.0))
        self.assertEqual(plot_world.budget_value("deadline_us=50;bv_tests=3"), ("deadline_us", 50.0))

    def test_both_figures_are_drawn(self):
        rows = [frame_row("adb_probability", "bv_tests=100", 10, 0, 1), frame_row("adb_probability", "bv_tests=1000", 10, 0, 0),
                frame_row("", "", 10, 0, 0, series="exact")]
        scaling = [{"hierarchy": "aabb", "broad_phase": "sweep_and_prune", "objects": n, "boxes_micros": "1",
                    "update_micros": str(n)} for n in ("100", "1000")]
        with tempfile.TemporaryDirectory() as d:
            plot_world.figure_errors_vs_budget(rows, os.path.join(d, "a.png"))
            plot_world.figure_broad_phase_vs_objects(scaling, [], os.path.join(d, "b.png"))
            self.assertGreater(os.path.getsize(os.path.join(d, "a.png")), 1000)
            self.assertGreater(os.path.getsize(os.path.join(d, "b.png")), 1000)


if __name__ == "__main__":
    unittest.main()
