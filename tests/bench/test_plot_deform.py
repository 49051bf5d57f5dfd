"""The deform report's figures: time per frame (update plus every query) per way of keeping the tree, and
wrong answers against time per density update, computed from the rows.

Run by ctest with BVHLAB_SOURCE_DIR set; plain unittest, so it needs nothing beyond matplotlib.
"""
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.environ.get("BVHLAB_SOURCE_DIR", "."), "bench"))

import plot_deform  # noqa: E402


def row(frame, update, series, exact, tree, density, queries_total, missed=0, false_pairs=0):
    return {"frame": str(frame), "hierarchy": "aabb", "update": update, "series": series,
            "exact_strategy": "1" if exact else "0", "tree_micros": str(tree), "density_micros": str(density),
            "query_total_micros": str(queries_total), "queries": "10", "missed": str(missed),
            "false_pairs": str(false_pairs)}


class DeformFigures(unittest.TestCase):
    def test_frame_time_is_update_plus_every_query(self):
        self.assertAlmostEqual(plot_deform.frame_micros(row(1, "refit", "exact", True, 100, 20, 3)), 123.0)

    def test_both_figures_are_drawn(self):
        rows = [row(f, u, "exact", True, t, 0, 50) for f in (1, 2) for u, t in (("refit", 10), ("rebuild", 90))]
        rows += [row(f, "refit + stale", "adb p_min=0.9", False, 10, 0, 5, missed=1) for f in (1, 2)]
        rows += [row(f, "rebuild + annotate", "adb p_min=0.9", False, 90, 900, 5) for f in (1, 2)]
        with tempfile.TemporaryDirectory() as d:
            plot_deform.figure_time_per_frame(rows, os.path.join(d, "a.png"))
            plot_deform.figure_error_vs_time(rows, os.path.join(d, "b.png"))
            self.assertGreater(os.path.getsize(os.path.join(d, "a.png")), 1000)
            self.assertGreater(os.path.getsize(os.path.join(d, "b.png")), 1000)


if __name__ == "__main__":
    unittest.main()
