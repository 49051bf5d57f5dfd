#!/usr/bin/env python3
"""Figures of a deform report (bvhlab report on a scene with "deform"), from deform_frames.csv in REPORT_DIR:

  deform_time_per_frame.png  update (tree and density) plus every query of the frame, per frame, one line per
                             hierarchy and way of updating it (refit, rebuild, FCL's refit and rebuild), for
                             the exact strategies
  deform_error_vs_time.png   wrong answers (missed and false, percent of the queries) against the time per
                             frame, one point per density update and strategy on the ADB trees, with the
                             rebuilt and re-annotated tree as the reference
"""
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from plot_common import group_by, report_main, save  # noqa: E402


def frame_micros(r):
    return float(r["tree_micros"]) + float(r["density_micros"]) + float(r["query_total_micros"])


def by_series(rows):
    """[((hierarchy, update, series), its rows)], sorted: one line or point of a figure each."""
    return sorted(group_by(rows, lambda r: (r["hierarchy"], r["update"], r["series"])).items())


def figure_time_per_frame(rows, out):
    fig, ax = plt.subplots(figsize=(7.0, 4.6))
    exact = [r for r in rows if r["exact_strategy"] == "1"]
    for (hierarchy, update, series), group in by_series(exact):
        group.sort(key=lambda r: int(r["frame"]))
        style = "--" if "rebuild" in update else "-"
        ax.plot([int(r["frame"]) for r in group], [frame_micros(r) / 1000 for r in group], style, marker=".",
                label=f"{hierarchy}: {update} ({series})")
    ax.set_yscale("log")
    ax.set_xlabel("frame")
    ax.set_ylabel("ms per frame (update + every query)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title("Keeping a deforming object's tree: refit against rebuild")
    save(fig, out, dpi=120)


def figure_error_vs_time(rows, out):
    fig, ax = plt.subplots(figsize=(7.0, 4.6))
    approximate = [r for r in rows if r["exact_strategy"] == "0"]
    for (hierarchy, update, series), group in by_series(approximate):
        queries = sum(int(r["queries"]) for r in group)
        wrong = sum(int(r["missed"]) + int(r["false_pairs"]) for r in group)
        times = sorted(frame_micros(r) for r in group)
        marker = "s" if "rebuild" in update else "o"
        ax.scatter([times[len(times) // 2] / 1000], [100.0 * wrong / queries if queries else 0.0], marker=marker,
                   label=f"{hierarchy}: {update} ({series})")
    ax.set_xscale("log")
    ax.set_xlabel("ms per frame (update + every query), median")
    ax.set_ylabel("wrong answers, % of queries (missed + false)")
    ax.set_ylim(bottom=0)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title("Error against time per density update")
    save(fig, out, dpi=120)


def draw(args, rows):
    figure_time_per_frame(rows, os.path.join(args.report_dir, "deform_time_per_frame.png"))
    figure_error_vs_time(rows, os.path.join(args.report_dir, "deform_error_vs_time.png"))


def main(argv=None):
    report_main(__file__, __doc__, ["deform_frames.csv"], draw, argv=argv)


if __name__ == "__main__":
    main()
