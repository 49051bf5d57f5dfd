"""The world report's figures: wrong pairs per schedule against the frame budget, computed from the rows as
missed plus false over candidates, and the broad-phase time against the object count.

Run by ctest with BVHLAB_SOURCE_DIR set; plain unittest, so it needs nothing beyond matplotlib.
"""
import tempfile
import unittest
from unittest import mock

from plot_script_checks import ReportScriptChecks, write_tables  # first: it puts bench/ on sys.path

import plot_world


def frame_row(schedule, budget, candidates, missed, false_pairs, series=None):
    return {"frame": "0", "hierarchy": "aabb", "series": series or f"frame {schedule} {budget}",
            "schedule": schedule, "budget": budget, "candidates": str(candidates), "missed": str(missed),
            "false_pairs": str(false_pairs)}


def broad_row(objects, micros, hierarchy="aabb"):
    return {"frame": "0", "hierarchy": hierarchy, "broad_phase": "sweep_and_prune", "objects": str(objects),
            "boxes_micros": "1", "update_micros": str(micros)}


def tables():
    rows = [frame_row("adb_probability", "bv_tests=100", 10, 0, 1), frame_row("adb_probability", "bv_tests=1000", 10, 0, 0),
            frame_row("", "", 10, 0, 0, series="exact")]
    scaling = [broad_row(n, n) for n in (100, 1000)]
    broad = [broad_row(100, 90), broad_row(100, 110), broad_row(100, 300, hierarchy="fcl_obbrss")]
    return {"world_frames.csv": rows, "world_broad_phase.csv": broad, "world_scaling.csv": scaling}


class WorldFigures(ReportScriptChecks, unittest.TestCase):
    script = plot_world
    required = ["world_frames.csv", "world_broad_phase.csv"]
    figures = ["world_errors_vs_budget.png", "world_broad_phase_vs_objects.png"]

    def test_wrong_pairs_count_missed_and_false_over_all_frames(self):
        rows = [frame_row("equal_split", "bv_tests=100", 10, 1, 1), frame_row("equal_split", "bv_tests=100", 30, 0, 2)]
        self.assertAlmostEqual(plot_world.wrong_percent(rows), 100.0 * 4 / 40)

    def test_budgets_are_read_by_kind(self):
        self.assertEqual(plot_world.budget_value("bv_tests=200"), ("bv_tests", 200.0))
        self.assertEqual(plot_world.budget_value("deadline_us=50;bv_tests=3"), ("deadline_us", 50.0))

    def test_a_policy_keeps_its_colour_and_a_variant_its_line_style(self):
        colors, styles = {}, {}
        plain = plot_world.schedule_style("adb_probability", colors, styles)
        memory = plot_world.schedule_style("adb_probability memory", colors, styles)
        other = plot_world.schedule_style("equal_split memory", colors, styles)
        confirming = plot_world.schedule_style("equal_split confirm_levels=1", colors, styles)
        self.assertEqual(plain["color"], memory["color"])
        self.assertNotEqual(memory["color"], other["color"])
        self.assertEqual(memory["linestyle"], other["linestyle"])
        self.assertEqual(len({plain["linestyle"], memory["linestyle"], confirming["linestyle"]}), 3)
        self.assertEqual(plot_world.schedule_style("adb_probability", colors, styles), plain)

    def test_both_figures_are_drawn(self):
        self.assertDrawsItsFigures(tables())

    def test_both_figures_are_drawn_without_a_scaling_run(self):
        self.assertDrawsItsFigures({k: v for k, v in tables().items() if k != "world_scaling.csv"})

    def test_refuses_without_the_frames_or_the_broad_phase(self):
        self.assertRefusesWithoutEachRequiredTable(tables())

    def test_the_scaling_run_and_the_scenes_broad_phase_reach_the_figure_in_their_roles(self):
        given = tables()
        with tempfile.TemporaryDirectory() as d, mock.patch.object(plot_world, "figure_errors_vs_budget"), \
                mock.patch.object(plot_world, "figure_broad_phase_vs_objects") as figure:
            write_tables(d, given)
            plot_world.main([d])
        scaling, broad, _ = figure.call_args.args
        self.assertEqual(scaling, given["world_scaling.csv"])
        self.assertEqual(broad, given["world_broad_phase.csv"])


if __name__ == "__main__":
    unittest.main()
