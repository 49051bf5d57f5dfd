"""The points report's figures: error outside the band against time per pair and density, and FP and FN
against the distance, computed from the rows.

Run by ctest with BVHLAB_SOURCE_DIR set; plain unittest, so it needs nothing beyond matplotlib.
"""
import unittest

from plot_script_checks import ReportScriptChecks  # first: it puts bench/ on sys.path

import plot_points


def row(points, series, distance, clear, fp, fn, mean_us):
    return {"pair": "pinion", "points": str(points), "spacing": "0.05", "distance": str(distance),
            "series": series, "poses": "10", "clear": str(clear), "ambiguous": str(10 - clear),
            "colliding": "3", "fp": str(fp), "fn": str(fn), "median_us": str(mean_us / 2),
            "mean_us": str(mean_us)}


def tables():
    series = ("exact_points", "adb p_min=0.9", "adb p_min=0.99", "fcl_octree res=1")
    rows = [row(p, s, d, 8, k % 2, 0, 10.0 * (k + 1)) for p in (500, 2000) for d in (0.4, 1.2)
            for k, s in enumerate(series)]
    summary = [dict(r, distance="") for r in rows if r["distance"] == "0.4"]
    return {"points_summary.csv": summary, "points_rows.csv": rows}


class PointsFigures(ReportScriptChecks, unittest.TestCase):
    script = plot_points
    required = ["points_summary.csv", "points_rows.csv"]
    figures = ["points_error_vs_time.png", "points_fp_fn.png"]

    def test_error_is_fp_plus_fn_of_the_clear_poses_only(self):
        self.assertAlmostEqual(plot_points.error_percent(row(100, "adb p_min=0.9", 1.0, 8, 1, 1, 3.0)), 25.0)
        self.assertEqual(plot_points.error_percent(row(100, "adb p_min=0.9", 1.0, 0, 0, 0, 3.0)), 0.0)

    def test_groups_keep_the_run_order_per_pair_and_density(self):
        rows = [row(p, s, 1.0, 8, 0, 0, 1.0) for p in (2000, 500) for s in ("exact_points", "adb p_min=0.9")]
        self.assertEqual(list(plot_points.groups(rows)), [("pinion", 2000), ("pinion", 500)])

    def test_each_series_keeps_its_colour_and_they_differ(self):
        names = [f"adb p_min={p}" for p in range(14)]
        colours = plot_points.series_colours([row(100, n, 1.0, 8, 0, 0, 1.0) for n in names])
        self.assertEqual(len(set(colours.values())), len(names))

    def test_both_figures_are_drawn(self):
        self.assertDrawsItsFigures(tables())

    def test_refuses_without_the_summary_or_the_rows(self):
        self.assertRefusesWithoutEachRequiredTable(tables())


if __name__ == "__main__":
    unittest.main()
