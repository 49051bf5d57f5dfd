#!/usr/bin/env python3
"""Figures of a points report (bvhlab report on a scene with "points"), from the CSV files in REPORT_DIR:

  points_error_vs_time.png  wrong answers outside the ambiguous band (FP + FN, percent of the clear poses)
                            against the mean time per query, one panel per pair and density, one colour per
                            series; ADB's p_min values joined by a line (dotted: one per confirm_levels),
                            the goal's 4 % dashed
  points_fp_fn.png          FP and FN (percent of each distance's clear poses) against the protocol distance,
                            one row of two panels per pair and density, one colour per series
"""
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from plot_common import report_main, save  # noqa: E402

GOAL_PERCENT = 4.0


def percent(part, whole):
    return 100.0 * part / whole if whole else 0.0


def error_percent(r):
    """Wrong answers outside the band, percent of the clear poses."""
    return percent(int(r["fp"]) + int(r["fn"]), int(r["clear"]))


def groups(rows):
    """(pair, points) -> rows, in the order the run wrote them."""
    out = {}
    for r in rows:
        out.setdefault((r["pair"], int(r["points"])), []).append(r)
    return out


def series_colours(rows):
    """One colour per series, the same in every panel and figure."""
    names = list(dict.fromkeys(r["series"] for r in rows))
    # tab10's colours while they last; past 10 series tab20's 20 (its pairs of shades stay distinct).
    palette, size = (plt.get_cmap("tab10"), 10) if len(names) <= 10 else (plt.get_cmap("tab20"), 20)
    return {name: palette(k % size) for k, name in enumerate(names)}


def panel_grid(count, columns):
    rows = max(1, (count + columns - 1) // columns)
    fig, axes = plt.subplots(rows, columns, figsize=(5.2 * columns, 3.8 * rows), squeeze=False)
    return fig, axes


def adb_families(rows):
    """ADB's series by what follows "adb p_min=P" (the paper's rule, or a confirm_levels value), each sorted
    by mean time: each family is one line over its p_min values, the paper's rule solid."""
    families = {}
    for r in rows:
        if r["series"].startswith("adb p_min="):
            families.setdefault(" ".join(r["series"].split()[2:]), []).append(r)
    return [(sorted(f, key=lambda r: float(r["mean_us"])), "-" if rule == "" else ":")
            for rule, f in families.items()]


def figure_error_vs_time(summary, out):
    colours = series_colours(summary)
    by_group = groups(summary)
    fig, axes = panel_grid(len(by_group), min(2, len(by_group)))
    flat = [ax for row in axes for ax in row]
    for ax, ((pair, points), rows) in zip(flat, by_group.items()):
        for family, style in adb_families(rows):
            if len(family) > 1:
                ax.plot([float(r["mean_us"]) for r in family], [error_percent(r) for r in family], style,
                        color="0.6", linewidth=1, zorder=1)
        for r in rows:
            ax.scatter([max(float(r["mean_us"]), 1e-3)], [error_percent(r)], color=colours[r["series"]],
                       label=r["series"], zorder=2)
        ax.axhline(GOAL_PERCENT, color="0.3", linestyle="--", linewidth=0.8)
        ax.set_xscale("log")
        ax.set_ylim(bottom=0)
        ax.set_xlabel("mean µs per query")
        ax.set_ylabel("FP + FN, % of clear poses")
        ax.set_title(f"{pair}, {points} points", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
    for ax in flat[len(by_group):]:
        ax.set_visible(False)
    flat[0].legend(fontsize=6, loc="upper right")
    fig.suptitle("Point clouds: error outside the ambiguous band against time")
    save(fig, out, dpi=110)


def figure_fp_fn(rows, out):
    colours = series_colours(rows)
    by_group = groups(rows)
    fig, axes = plt.subplots(len(by_group), 2, figsize=(10.4, 3.4 * len(by_group)), squeeze=False)
    for ((pair, points), group_rows), panels in zip(by_group.items(), axes):
        for series in dict.fromkeys(r["series"] for r in group_rows):
            curve = sorted((r for r in group_rows if r["series"] == series), key=lambda r: float(r["distance"]))
            d = [float(r["distance"]) for r in curve]
            panels[0].plot(d, [percent(int(r["fp"]), int(r["clear"])) for r in curve], marker=".",
                           color=colours[series], label=series)
            panels[1].plot(d, [percent(int(r["fn"]), int(r["clear"])) for r in curve], marker=".",
                           color=colours[series], label=series)
        for ax, what in zip(panels, ("false positives", "false negatives")):
            ax.set_xlabel("distance")
            ax.set_ylabel(f"{what}, % of clear poses")
            ax.set_ylim(bottom=0)
            ax.set_title(f"{pair}, {points} points: {what}", fontsize=9)
            ax.grid(True, alpha=0.3)
    axes[0][0].legend(fontsize=6)
    save(fig, out, dpi=110)


def draw(args, summary, rows):
    figure_error_vs_time(summary, os.path.join(args.report_dir, "points_error_vs_time.png"))
    figure_fp_fn(rows, os.path.join(args.report_dir, "points_fp_fn.png"))


def main(argv=None):
    report_main(__file__, __doc__, ["points_summary.csv", "points_rows.csv"], draw, argv=argv)


if __name__ == "__main__":
    main()
