"""The report's figures stay legible: one colour per series, no calibration line across an empty bin, p_min
labels apart, numbers on short log axes, series side by side rather than on top of one another.

Run by ctest with BVHLAB_SOURCE_DIR set; plain unittest, so it needs nothing beyond matplotlib.
"""
import math
import os
import unittest

from plot_script_checks import ReportScriptChecks  # first: it puts bench/ on sys.path

import plot_report
from matplotlib import pyplot as plt
from matplotlib.colors import to_rgba


def calibration_bin(low, count=60, p_min="0.9", mesh="m", reported=None, observed=None):
    reported = low + 0.05 if reported is None else reported
    return {"mesh": mesh, "hierarchy": "aabb", "strategy": "adb", "p_min": p_min, "budget": "",
            "bin_low": str(low), "bin_high": str(round(low + 0.1, 10)), "count": str(count),
            "mean_probability": "" if count == 0 else str(reported),
            "collision_frequency": "" if count == 0 else str(reported if observed is None else observed)}


def result_row(p_min, mesh="m", strategy="adb", exact="0"):
    return {"mesh": mesh, "hierarchy": "aabb", "strategy": strategy, "p_min": p_min, "budget": "",
            "label": f"{strategy} p_min={p_min}" if p_min else strategy, "exact": exact, "distance": "1.2",
            "queries": "10", "fp_rate": "0", "fn_rate": "0", "mean_time_us": "1", "bytes_per_triangle": "1"}


def series_line(ax):
    """The one line of a calibration panel that is neither the diagonal nor the tolerance band."""
    lines = [line for line in ax.lines if line.get_linestyle() == "-"]
    assert len(lines) == 1, [line.get_label() for line in ax.lines]
    return lines[0]


def segments(values):
    """How many unbroken runs of numbers a line's data has (NaN breaks a matplotlib line)."""
    runs, inside = 0, False
    for v in values:
        if math.isnan(v):
            inside = False
        elif not inside:
            runs, inside = runs + 1, True
    return runs


class CalibrationLine(unittest.TestCase):
    def test_an_empty_bin_breaks_the_line(self):
        bins = [calibration_bin(0.0), calibration_bin(0.1), calibration_bin(0.2, count=0), calibration_bin(0.3)]
        xs, ys = plot_report.calibration_line(bins)
        self.assertTrue(math.isnan(xs[2]) and math.isnan(ys[2]))
        self.assertEqual(segments(ys), 2)

    def test_a_missing_bin_breaks_the_line_too(self):
        bins = [calibration_bin(0.0), calibration_bin(0.1), calibration_bin(0.4), calibration_bin(0.5)]
        self.assertEqual(segments(plot_report.calibration_line(bins)[1]), 2)

    def test_adjacent_bins_stay_one_line(self):
        xs, ys = plot_report.calibration_line([calibration_bin(x / 10) for x in range(10)])
        self.assertEqual(segments(ys), 1)
        self.assertEqual(len(ys), 10)

    def test_the_gap_judges_only_bins_with_enough_answers(self):
        bins = [calibration_bin(0.1, count=100, reported=0.15, observed=0.12),
                calibration_bin(0.5, count=49, reported=0.55, observed=0.0),
                calibration_bin(0.8, count=50, reported=0.85, observed=0.79)]
        gap, judged = plot_report.calibration_gap(bins)
        self.assertAlmostEqual(gap, 0.06)
        self.assertEqual(judged, 2)
        self.assertEqual(plot_report.calibration_gap([calibration_bin(0.5, count=3)]), (None, 0))


class CalibrationFigure(unittest.TestCase):
    def setUp(self):
        # Two meshes, three ADB series each (p_min 0.5 has an empty decile in the middle), and an exact one.
        self.rows = [result_row(p, mesh) for mesh in ("m", "n") for p in ("0.5", "0.9", "0.99")]
        self.rows.append(result_row("", "m", strategy="exact", exact="1"))
        self.calibration = []
        for mesh in ("m", "n"):
            for p in ("0.5", "0.9", "0.99"):
                for b in range(10):
                    count = 0 if (p == "0.5" and b == 4) else 20 if b == 7 else 100
                    self.calibration.append(calibration_bin(b / 10, count, p, mesh))
        self.fig, self.axes = plot_report.draw_calibration(self.calibration, self.rows)

    def tearDown(self):
        plt.close("all")

    def test_one_panel_per_series_and_mesh(self):
        self.assertEqual(len(self.axes), 6)
        self.assertEqual({mesh for mesh, _ in self.axes}, {"m", "n"})

    def test_the_empty_decile_breaks_that_series_line_only(self):
        for (mesh, (_, label)), ax in self.axes.items():
            ys = series_line(ax).get_ydata()
            self.assertEqual(segments(ys), 2 if label == "adb p_min=0.5" else 1, (mesh, label))

    def test_each_series_has_one_colour_its_figure_2_colour_and_no_other_series_has_it(self):
        expected = plot_report.inexact_colours(self.rows)
        seen = {}
        for (mesh, key), ax in self.axes.items():
            colour = to_rgba(expected[key])
            self.assertEqual(to_rgba(series_line(ax).get_color()), colour)
            for collection in ax.collections[1:]:  # the first is the tolerance band
                for edge in collection.get_edgecolors():
                    self.assertEqual(tuple(edge), colour)
            seen.setdefault(colour, set()).add(key)
        self.assertTrue(all(len(keys) == 1 for keys in seen.values()), seen)
        self.assertEqual(len(seen), 3)  # the same series on both meshes keeps its colour

    def test_deciles_with_few_answers_are_hollow(self):
        ax = self.axes[("m", ("aabb", "adb p_min=0.9"))]
        filled, hollow = ax.collections[1], ax.collections[2]
        self.assertEqual(len(filled.get_offsets()), 9)
        self.assertEqual(len(hollow.get_offsets()), 1)  # the 20-answer decile
        self.assertEqual(len(hollow.get_facecolors()), 0)
        self.assertGreater(len(filled.get_facecolors()), 0)

    def test_draws_without_any_inexact_series(self):
        fig, axes = plot_report.draw_calibration([], [result_row("", strategy="exact", exact="1")])
        self.assertEqual(axes, {})
        self.assertIn("no inexact strategy", [t.get_text() for t in fig.axes[0].texts])


class CalibratedSeries(unittest.TestCase):
    def test_a_calibrated_series_gets_its_own_panel_in_its_raw_series_colour(self):
        rows = [result_row("0.9")]
        raw = [calibration_bin(b / 10) for b in range(10)]
        calibrated = [dict(calibration_bin(b / 10), calibrated="1") for b in range(10)]
        fig, axes = plot_report.draw_calibration(raw + calibrated, rows)
        self.assertEqual(list(axes), [("m", ("aabb", "adb p_min=0.9")), ("m", ("aabb", "adb p_min=0.9 calibrated"))])
        colours = [to_rgba(series_line(ax).get_color()) for ax in axes.values()]
        self.assertEqual(colours[0], colours[1])
        self.assertIn("calibrated", axes[("m", ("aabb", "adb p_min=0.9 calibrated"))].get_title())
        plt.close(fig)


class PminCurves(unittest.TestCase):
    def test_a_variant_of_the_same_hierarchy_is_a_curve_of_its_own(self):
        plain, confirming = result_row("0.9"), result_row("0.9")
        confirming["label"] = "adb p_min=0.9 confirm_levels=1"
        self.assertEqual(plot_report.curve_name(plain), "adb")
        self.assertEqual(plot_report.curve_name(confirming), "adb confirm_levels=1")


class Walks(unittest.TestCase):
    def test_a_wide_or_coherent_series_is_drawn_apart_from_its_strategy(self):
        plain, wide, coherent = (result_row("", strategy="exact", exact="1") for _ in range(3))
        wide["label"], coherent["label"] = "exact wide", "exact coherent"
        walks = [plot_report.walk_of(r) for r in (plain, wide, coherent)]
        self.assertEqual(walks, ["exact", "exact wide", "exact coherent"])
        styles = {plot_report.style_for("aabb", w, ["aabb"], walks)[1:] for w in walks}
        self.assertEqual(len(styles), 3)  # line and marker differ: one colour per hierarchy


class Script(ReportScriptChecks, unittest.TestCase):
    """The command line; `bvhlab report`'s tests (test_bench_run) draw the five figures from a real run."""

    script = plot_report
    required = ["results.csv"]

    def test_refuses_without_results(self):
        self.assertRefusesWithoutEachRequiredTable({"results.csv": [result_row("0.9")]})


def write_text(path, text):
    with open(path, "w") as f:
        f.write(text)


def fail_drawing(path):
    raise ValueError(f"cannot draw {path}")


class DrawEach(unittest.TestCase):
    """The figures are drawn side by side in processes: every job runs, in one process or several, and a
    job's failure reaches the caller."""

    def test_every_job_runs_whatever_the_workers(self):
        import tempfile

        import plot_common

        for workers in (1, 2):
            with tempfile.TemporaryDirectory() as folder:
                paths = [os.path.join(folder, f"{k}.txt") for k in range(5)]
                plot_common.draw_each([(write_text, p, p) for p in paths], workers=workers)
                for p in paths:
                    with open(p) as f:
                        self.assertEqual(f.read(), p)

    def test_a_failing_job_is_raised(self):
        import plot_common

        for workers in (1, 2):
            with self.assertRaisesRegex(ValueError, "cannot draw fig4"):
                plot_common.draw_each([(write_text, os.devnull, ""), (fail_drawing, "fig4")], workers=workers)


class Dodge(unittest.TestCase):
    def test_offsets_are_distinct_and_stay_between_neighbouring_distances(self):
        offsets = plot_report.dodge(5, [1.2, 1.4, 1.6])
        self.assertEqual(len(set(offsets)), 5)
        self.assertLess(max(abs(o) for o in offsets), 0.1)

    def test_one_series_is_not_moved(self):
        self.assertEqual(plot_report.dodge(1, [1.2, 1.4]), [0.0])


class Axes(unittest.TestCase):
    def tearDown(self):
        plt.close("all")

    def test_a_log_axis_under_a_decade_still_has_numbers(self):
        fig, ax = plt.subplots()
        ax.plot([1, 2], [3.1, 8.7])
        plot_report.log_axis(ax)
        ax.set_ylim(3, 9)
        fig.canvas.draw()
        labels = [t.get_text() for t in ax.get_yticklabels() if t.get_text()]
        self.assertGreaterEqual(len(labels), 1, labels)
        self.assertIn("5", labels)

    def test_close_p_min_labels_do_not_overlap(self):
        fig, ax = plt.subplots()
        points = [(10.0, 5.0, "0.9", "a"), (10.05, 5.01, "0.99", "a"), (10.1, 5.02, "0.5", "a")]
        ax.plot([p[0] for p in points], [p[1] for p in points])
        plot_report.spread_labels(ax, points, lambda key: "black")
        fig.canvas.draw()
        boxes = [t.get_window_extent() for t in ax.texts]
        self.assertEqual(len(boxes), 3)
        for i in range(len(boxes)):
            for j in range(i + 1, len(boxes)):
                self.assertFalse(boxes[i].overlaps(boxes[j]), (ax.texts[i].get_text(), ax.texts[j].get_text()))


if __name__ == "__main__":
    unittest.main()
