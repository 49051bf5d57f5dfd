"""The deform report's figures: time per frame (update plus every query) per way of keeping the tree, and
wrong answers against time per density update, computed from the rows.

Run by ctest with BVHLAB_SOURCE_DIR set; plain unittest, so it needs nothing beyond matplotlib.
"""
import unittest

from plot_script_checks import ReportScriptChecks  # first: it puts bench/ on sys.path

import plot_deform


def row(frame, update, series, exact, tree, density, queries_total, missed=0, false_pairs=0):
    return {"frame": str(frame), "hierarchy": "aabb", "update": update, "series": series,
            "exact_strategy": "1" if exact else "0", "tree_micros": str(tree), "density_micros": str(density),
            "query_total_micros": str(queries_total), "queries": "10", "missed": str(missed),
            "false_pairs": str(false_pairs)}


def tables():
    rows = [row(f, u, "exact", True, t, 0, 50) for f in (1, 2) for u, t in (("refit", 10), ("rebuild", 90))]
    rows += [row(f, "refit + stale", "adb p_min=0.9", False, 10, 0, 5, missed=1) for f in (1, 2)]
    rows += [row(f, "rebuild + annotate", "adb p_min=0.9", False, 90, 900, 5) for f in (1, 2)]
    return {"deform_frames.csv": rows}


class DeformFigures(ReportScriptChecks, unittest.TestCase):
    script = plot_deform
    required = ["deform_frames.csv"]
    figures = ["deform_time_per_frame.png", "deform_error_vs_time.png"]

    def test_frame_time_is_update_plus_every_query(self):
        self.assertAlmostEqual(plot_deform.frame_micros(row(1, "refit", "exact", True, 100, 20, 3)), 123.0)

    def test_both_figures_are_drawn(self):
        self.assertDrawsItsFigures(tables())

    def test_refuses_without_its_frames(self):
        self.assertRefusesWithoutEachRequiredTable(tables())


if __name__ == "__main__":
    unittest.main()
