"""The report's figures stay legible: one colour per series, no calibration line across an empty bin, p_min
labels apart, numbers on short log axes, series side by side rather than on top of one another.

Run by ctest with BVHLAB_SOURCE_DIR set; plain unittest, so it needs nothing beyond matplotlib.
"""
import os
import sys
import unittest

sys.path.insert(0, os.path.join(os.environ.get("BVHLAB_SOURCE_DIR", "."), "bench"))

import plot_report  # noqa: E402
from matplotlib import pyplot as plt  # noqa: E402


def calibration_bin(low, count=60):
    return {"bin_low": str(low), "bin_high": str(round(low + 0.1, 10)), "count": str(count)}


class SeriesColours(unittest.TestCase):
    def test_every_series_has_its_own_colour(self):
        for n in (2, 10, 20, 30):
            colours = plot_report.series_colours([f"s{i}" for i in range(n)])
            distinct = {tuple(round(c, 6) for c in colour[:3]) for colour in colours.values()}
            self.assertEqual(len(distinct), n, f"{n} series")


class CalibrationRuns(unittest.TestCase):
    def test_a_gap_splits_the_line(self):
        bins = [calibration_bin(0.0), calibration_bin(0.1), calibration_bin(0.4), calibration_bin(0.5)]
        runs = plot_report.adjacent_runs(bins)
        self.assertEqual([len(r) for r in runs], [2, 2])

    def test_adjacent_bins_stay_one_line(self):
        bins = [calibration_bin(x / 10) for x in range(10)]
        self.assertEqual(len(plot_report.adjacent_runs(bins)), 1)


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
