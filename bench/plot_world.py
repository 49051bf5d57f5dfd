#!/usr/bin/env python3
"""Figures of a world report (bvhlab report on a scene with "world"), from the CSV files in REPORT_DIR:

  world_errors_vs_budget.png        wrong pairs (missed and false, percent of the candidate pairs) against the
                                    frame budget, one line per schedule, per budget kind (BV tests, µs);
                                    the per-pair strategies as horizontal references
  world_broad_phase_vs_objects.png  broad-phase time per frame (world boxes plus update and pair finding)
                                    against the object count, log-log (from world_scaling.csv; the scene's
                                    own count when the scene asks for no scaling, else as points beside the
                                    lines); FCL's managers (rows of the hierarchy fcl_obbrss, timed at the
                                    scene's own count only) as single points
"""
import os
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from plot_common import group_by, report_main, save  # noqa: E402


def budget_value(budget):
    """("bv_tests", 200.0) from "bv_tests=200"; the first part of a combined budget."""
    kind, _, value = budget.split(";")[0].partition("=")
    return kind, float(value)


def wrong_percent(rows):
    candidates = sum(int(r["candidates"]) for r in rows)
    wrong = sum(int(r["missed"]) + int(r["false_pairs"]) for r in rows)
    return 100.0 * wrong / candidates if candidates else 0.0


LINE_STYLES = ["-", "--", ":", "-."]


def schedule_style(schedule, colors, styles):
    """A colour per policy (the schedule's first word), a line style per variant (the rest: memory, confirm_levels=L):
    the same across both panels."""
    policy, _, variant = schedule.partition(" ")
    color = colors.setdefault(policy, f"C{len(colors) % 10}")
    style = styles.setdefault(variant, LINE_STYLES[len(styles) % len(LINE_STYLES)])
    return {"color": color, "linestyle": style}


def figure_errors_vs_budget(rows, out):
    budgeted = [r for r in rows if r["schedule"]]
    kinds = sorted({budget_value(r["budget"])[0] for r in budgeted}) or ["bv_tests"]
    fig, axes = plt.subplots(1, len(kinds), figsize=(5.6 * len(kinds), 4.4), squeeze=False)
    references = group_by([r for r in rows if not r["schedule"]], lambda r: (r["hierarchy"], r["series"]))
    colors, styles, legend = {}, {}, {}
    for ax, kind in zip(axes[0], kinds):
        lines = defaultdict(dict)
        for (hierarchy, schedule, budget), group in group_by(
            budgeted, lambda r: (r["hierarchy"], r["schedule"], r["budget"])
        ).items():
            k, value = budget_value(budget)
            if k == kind:
                lines[(hierarchy, schedule)][value] = wrong_percent(group)
        for (hierarchy, schedule), points in sorted(lines.items()):
            xs = sorted(points)
            (line,) = ax.plot(xs, [points[x] for x in xs], marker="o", markersize=4,
                              **schedule_style(schedule, colors, styles))
            legend.setdefault(f"{schedule} ({hierarchy})", line)
        # References at one level (the exact series, all at 0) share a line and one label, not overprinted ones.
        levels = defaultdict(list)
        for (hierarchy, series), group in sorted(references.items()):
            levels[round(wrong_percent(group), 2)].append(f"{series} ({hierarchy})")
        for level, labels in sorted(levels.items()):
            ax.axhline(level, linestyle=":", linewidth=1, color="grey")
            ax.annotate(", ".join(labels), (0.01, level), xycoords=("axes fraction", "data"), fontsize=7,
                        color="grey", va="bottom")
        ax.set_xscale("log")
        ax.set_xlabel("frame budget, " + ("BV tests" if kind == "bv_tests" else "microseconds"))
        ax.set_ylabel("wrong pairs, % of candidate pairs (missed + false)")
        ax.set_ylim(bottom=0)
        ax.grid(True, alpha=0.3)
    # One legend beside the panels: a schedule keeps its colour and style in both.
    # The figure is widened by what the legend measures, so long schedule names never cover a panel.
    drawn = fig.legend(list(legend.values()), list(legend.keys()), loc="center right", fontsize=7)
    legend_inches = drawn.get_window_extent(fig.canvas.get_renderer()).width / fig.dpi + 0.2
    fig.set_figwidth(5.6 * len(kinds) + legend_inches)
    fig.suptitle("Pair errors against the frame budget")
    save(fig, out, dpi=120, rect=(0, 0, 1 - legend_inches / fig.get_figwidth(), 1))


FCL_HIERARCHY = "fcl_obbrss"  # world.hpp: kFclWorldHierarchy


def scene_medians(broad):
    """{(hierarchy, broad phase): {objects: median µs per frame of world boxes + update}} at the scene's count."""
    points = defaultdict(dict)
    for key, group in group_by(broad, lambda r: (r["hierarchy"], r["broad_phase"])).items():
        times = sorted(float(r["boxes_micros"]) + float(r["update_micros"]) for r in group)
        points[key][int(group[0]["objects"])] = times[len(times) // 2]
    return points


def figure_broad_phase_vs_objects(scaling, broad, out):
    fig, ax = plt.subplots(figsize=(6.2, 4.4))
    points = defaultdict(dict)
    for r in scaling:
        points[(r["hierarchy"], r["broad_phase"])][int(r["objects"])] = float(r["boxes_micros"]) + float(
            r["update_micros"]
        )
    if not points:
        points = scene_medians(broad)
    else:
        # The scene's own frames as points apart (timed amid the narrow phases, not in a loop of their own),
        # so that FCL's points have bvhlab's beside them.
        for (hierarchy, name), by_count in scene_medians(broad).items():
            if hierarchy == FCL_HIERARCHY or (hierarchy, name) in points:
                points[(hierarchy + ", scene", name)] = by_count
    for (hierarchy, name), by_count in sorted(points.items()):
        xs = sorted(by_count)
        alone = len(xs) == 1
        ax.plot(xs, [by_count[x] for x in xs], marker="s" if hierarchy.startswith(FCL_HIERARCHY) else "o",
                linestyle="none" if alone else "-", label=f"{name} ({hierarchy})")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("objects")
    ax.set_ylabel("µs per frame (world boxes + update + pairs), median")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Broad phase against the object count")
    save(fig, out, dpi=120)


def draw(args, rows, broad, scaling):
    figure_errors_vs_budget(rows, os.path.join(args.report_dir, "world_errors_vs_budget.png"))
    figure_broad_phase_vs_objects(scaling, broad, os.path.join(args.report_dir, "world_broad_phase_vs_objects.png"))


def main(argv=None):
    report_main(__file__, __doc__, ["world_frames.csv", "world_broad_phase.csv"], draw,
                optional=["world_scaling.csv"], argv=argv)


if __name__ == "__main__":
    main()
