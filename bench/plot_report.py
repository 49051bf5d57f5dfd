#!/usr/bin/env python3
"""Draws the five figures of a bvhlab report from its results.csv and calibration.csv.

    plot_report.py REPORT_DIR [--band MESH=TEXT ...] [--distance-label "..."] [--operating-strategy adb]
                   [--operating-hierarchy aabb] [--operating-p-min 0.9]

The labels come from the scene (`bvhlab report` passes them): the distance axis says whether distances are
in normalised or the scene's own units, or separations, and figure 3 names each pair's summary band (the
rows results.csv marks "in_summary"; --quality-min/--quality-max for a results.csv without that column).
Figure 3 draws one curve over p_min per hierarchy and set of other parameters (confirm_levels=1 is a curve of
its own, dashed); whether each curve follows its work is judged in the report's README, which has the
per-pose times that judgement needs.

Strategies are told apart by the columns results.csv takes from bvhlab's strategy table: "exact" (1 for an
exact strategy), "strategy" (its name) and "label" (name, labelled parameters, budget); no strategy name is
spelled out here.

Figures (PNG, in REPORT_DIR):
  fig1_time_vs_distance.png   mean time per query against distance, every hierarchy
  fig2_errors_vs_distance.png false-positive and false-negative rates against distance
  fig3_error_vs_time.png      error against mean time over p_min (the Pareto curve)
  fig4_calibration.png        reported probability against observed collision frequency, a panel per series
  fig5_time_vs_size.png       mean time per query against model size
`bvhlab report` runs this; it needs only matplotlib, the standard library and plot_common.py beside it.
"""
import math
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from plot_common import draw_each, report_main  # noqa: E402

DEFAULT_DISTANCE_LABEL = "distance d of B's centre"
TIME_LABEL = "mean time per query (µs)"
CALIBRATION_MIN_ANSWERS = 50  # deciles with fewer answers are drawn but not judged, as in the README
CALIBRATION_TOLERANCE = 0.05  # the target gap between reported and observed


def num(value):
    return float(value) if value not in ("", None) else math.nan


def series_label(row):
    return row["label"].replace("bv_tests=", "budget ").replace("deadline_us=", "deadline µs ")


def series_key(row):
    return (row["hierarchy"], row.get("label") or (row["strategy"], row["p_min"], row["budget"]))


def is_exact(row):
    return row["exact"] == "1"


def meshes_of(rows):
    seen = []
    for r in rows:
        if r["mesh"] not in seen:
            seen.append(r["mesh"])
    return seen


def grouped(rows):
    """{(hierarchy, series label): [rows sorted by distance]}, in first-appearance order."""
    out = {}
    for r in rows:
        out.setdefault(series_key(r), []).append(r)
    for k in out:
        if "distance" in out[k][0]:
            out[k].sort(key=lambda r: num(r["distance"]))
    return out


def in_summary(row, lo, hi):
    """Whether a row counts in the summary: its pair's band as results.csv marks it ("in_summary"), else the
    distances in [lo, hi]."""
    if row.get("in_summary", "") != "":
        return row["in_summary"] == "1"
    return lo - 1e-12 <= num(row["distance"]) <= hi + 1e-12


def aggregate(rows, lo, hi, band=False):
    """Query-weighted means of one series' rows over distances in [lo, hi], or with band=True over the rows
    inside their pair's summary band."""
    picked = [r for r in rows if (in_summary(r, lo, hi) if band else lo - 1e-12 <= num(r["distance"]) <= hi + 1e-12)
              and int(r["queries"]) > 0]
    q = sum(int(r["queries"]) for r in picked)
    if q == 0:
        return None

    def mean(col):
        return sum(num(r[col]) * int(r["queries"]) for r in picked) / q

    return {
        "time": mean("mean_time_us"),
        "fp": mean("fp_rate"),
        "fn": mean("fn_rate"),
        "bytes": num(picked[0]["bytes_per_triangle"]),
        "bv": mean("bv_tests_per_query") if "bv_tests_per_query" in picked[0] else math.nan,
        "queries": q,
    }


def subplots(n, width=6.0, height=4.2, rows_per_mesh=1):
    """A grid with at most two meshes side by side; returns the figure and, per mesh, its column of axes."""
    columns = min(2, max(1, n))
    mesh_rows = math.ceil(max(1, n) / columns)
    fig, grid = plt.subplots(mesh_rows * rows_per_mesh, columns, figsize=(width * columns, height * mesh_rows * rows_per_mesh),
                             squeeze=False, constrained_layout=True)
    per_mesh = []
    for i in range(max(1, n)):
        r, c = divmod(i, columns)
        per_mesh.append([grid[r * rows_per_mesh + k][c] for k in range(rows_per_mesh)])
    for i in range(max(1, n), mesh_rows * columns):  # an odd number of meshes leaves one slot empty
        r, c = divmod(i, columns)
        for k in range(rows_per_mesh):
            grid[r * rows_per_mesh + k][c].set_visible(False)
    return fig, per_mesh, grid


def floor_at_zero(ax):
    """Rates cannot be negative: start the axis just below 0, in proportion to its range."""
    top = ax.get_ylim()[1]
    ax.set_ylim(bottom=-0.03 * max(top, 1e-9), top=top)


def legend_below(fig, axes):
    handles, labels = [], []
    for ax in axes.flat:
        if not ax.get_visible():
            continue
        for h, l in zip(*ax.get_legend_handles_labels()):
            if l not in labels:
                handles.append(h)
                labels.append(l)
    if handles:
        # Below the axes, outside the figure: savefig(bbox_inches="tight") grows the canvas to include it
        # (matplotlib 3.6 has no "outside" legend placement).
        fig.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, 0.0), ncol=min(3, len(labels)),
                   fontsize=9, frameon=False)


def series_colours(keys):
    """One distinct colour per series key, in order: tab10, then the rest of tab20, then a hue wheel."""
    palette = list(plt.get_cmap("tab10").colors) + list(plt.get_cmap("tab20").colors[1::2])
    extra = max(0, len(keys) - len(palette))
    palette += [plt.get_cmap("hsv")(i / max(1, extra)) for i in range(extra)]
    return {k: palette[i] for i, k in enumerate(keys)}


def layered(index):
    """Marker size and drawing order for the index-th series: later series smaller and on top, so that a
    series lying on another stays visible."""
    return {"markersize": max(5.0, 9.0 - 0.5 * index), "zorder": 3 + index}


def log_axis(ax, axis="y"):
    """A log axis that shows numbers even when it spans less than a decade (1, 2, 5 per decade)."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    target = ax.yaxis if axis == "y" else ax.xaxis
    (ax.set_yscale if axis == "y" else ax.set_xscale)("log")
    target.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    target.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    target.set_minor_formatter(NullFormatter())


def spread_labels(ax, points, colour_of, min_pixels=14):
    """Annotates (x, y, text) points, pushing a label up while it would overlap one already placed."""
    ax.figure.canvas.draw()  # fixes the data-to-pixel transform
    placed = []
    for x, y, text, key in points:
        px, py = ax.transData.transform((x, y))
        dy = 4
        while any(abs(px - qx) < 3 * min_pixels and abs(py + dy - qy) < min_pixels for qx, qy in placed):
            dy += min_pixels
        placed.append((px, py + dy))
        ax.annotate(text, (x, y), textcoords="offset points", xytext=(5, dy * 72 / ax.figure.dpi), fontsize=8,
                    color=colour_of(key))


LINES = ["-", "--", ":", "-.", (0, (5, 1, 1, 1))]
MARKERS = ["o", "s", "^", "D", "v", "P", "X", "*"]


def walk_of(row):
    """The strategy with how it walks the trees ("exact", "exact wide", "exact coherent"): what line and
    marker tell apart."""
    return " ".join([row["strategy"]] + [w for w in row.get("label", "").split() if w in ("wide", "coherent")])


def style_for(hierarchy, strategy, hierarchies, strategies):
    """Colour by hierarchy, line and marker by strategy and walk (walk_of, in the order they first appear)."""
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    colour = colours[hierarchies.index(hierarchy) % len(colours)]
    index = strategies.index(strategy) if strategy in strategies else 0
    return colour, LINES[index % len(LINES)], MARKERS[index % len(MARKERS)]


def is_operating(row, args):
    return (row["strategy"] == args.operating_strategy and row["hierarchy"] == args.operating_hierarchy
            and row["p_min"] and not row["budget"] and abs(float(row["p_min"]) - args.operating_p_min) < 1e-12)


def curve_name(row):
    """The series' label without its p_min: the curve of figure 3 it is a point of."""
    return " ".join(word for word in row["label"].split() if not word.startswith("p_min="))


def is_sweep(row, args):
    """A point of the operating strategy's curve over p_min (no budget)."""
    return row["strategy"] == args.operating_strategy and row["p_min"] and not row["budget"]


def exact_and_operating_panels(rows, args):
    """Figures 1 and 5: a panel per mesh showing the exact strategies and the operating one. Returns the figure,
    its axes and [(panel, mesh, [(series rows, (colour, line, marker), label)])]."""
    meshes = meshes_of(rows)
    hierarchies = list(dict.fromkeys(r["hierarchy"] for r in rows))
    strategies = list(dict.fromkeys(walk_of(r) for r in rows))
    fig, per_mesh, axes = subplots(len(meshes))
    panels = []
    for (ax,), mesh in zip(per_mesh, meshes):
        shown = [s for s in grouped([r for r in rows if r["mesh"] == mesh]).values()
                 if is_exact(s[0]) or is_operating(s[0], args)]
        panels.append((ax, mesh, [(s, style_for(s[0]["hierarchy"], walk_of(s[0]), hierarchies, strategies),
                                   f"{s[0]['hierarchy']}: {series_label(s[0])}") for s in shown]))
    return fig, axes, panels


def figure_time_vs_distance(rows, args, out):
    """Time per query against distance, and below each panel the work that explains it: BV tests per query."""
    meshes = meshes_of(rows)
    hierarchies = list(dict.fromkeys(r["hierarchy"] for r in rows))
    strategies = list(dict.fromkeys(walk_of(r) for r in rows))
    fig, per_mesh, axes = subplots(len(meshes), rows_per_mesh=2, height=3.4)
    for (time_ax, work_ax), mesh in zip(per_mesh, meshes):
        shown = [s for s in grouped([r for r in rows if r["mesh"] == mesh]).values()
                 if is_exact(s[0]) or is_operating(s[0], args)]
        for i, series in enumerate(shown):
            colour, line, marker = style_for(series[0]["hierarchy"], walk_of(series[0]), hierarchies, strategies)
            style = dict(marker=marker, color=colour, label=f"{series[0]['hierarchy']}: {series_label(series[0])}",
                         **layered(i))
            d = [num(r["distance"]) for r in series]
            time_ax.plot(d, [num(r["mean_time_us"]) for r in series], line, **style)
            work_ax.plot(d, [num(r.get("bv_tests_per_query", "")) for r in series], line, **style)
        time_ax.set_title(f"{mesh}: time per query")
        work_ax.set_title(f"{mesh}: work per query (FCL counts none)")
        for ax, label in ((time_ax, TIME_LABEL), (work_ax, "BV tests per query")):
            log_axis(ax)
            ax.set_xlabel(args.distance_label, fontsize=9)
            ax.set_ylabel(label)
            ax.grid(True, which="both", alpha=0.3)
    legend_below(fig, axes)
    fig.savefig(out, dpi=110, bbox_inches="tight")
    plt.close(fig)


def dodge(series_count, distances):
    """Horizontal offsets that keep series at equal rates (often 0%) side by side instead of on top."""
    if series_count < 2 or len(distances) < 2:
        return [0.0] * series_count
    step = min(b - a for a, b in zip(distances, distances[1:]) if b > a) if len(set(distances)) > 1 else 1.0
    width = 0.25 * step
    return [width * (i / (series_count - 1) - 0.5) for i in range(series_count)]


def figure_errors_vs_distance(rows, args, out):
    meshes = meshes_of(rows)
    inexact = [r for r in rows if not is_exact(r)]
    colours = inexact_colours(rows)  # one colour per series, the same in every panel and in figure 4
    distances = sorted({num(r["distance"]) for r in rows})
    fig, per_mesh, axes = subplots(len(meshes), rows_per_mesh=2, height=3.6)
    for (fp_ax, fn_ax), mesh in zip(per_mesh, meshes):
        series_list = list(grouped([r for r in inexact if r["mesh"] == mesh]).values())
        for i, (series, offset) in enumerate(zip(series_list, dodge(len(series_list), distances))):
            first = series[0]
            marker = "^" if is_sweep(first, args) else "D"
            style = dict(marker=marker, color=colours[series_key(first)], label=f"{first['hierarchy']}: {series_label(first)}",
                         **layered(i))
            d = [num(r["distance"]) + offset for r in series]
            fp_ax.plot(d, [100 * num(r["fp_rate"]) for r in series], **style)
            fn_ax.plot(d, [100 * num(r["fn_rate"]) for r in series], **style)
        fp_ax.set_title(f"{mesh}: false positives")
        fn_ax.set_title(f"{mesh}: false negatives")
        for ax, kind in ((fp_ax, "false-positive"), (fn_ax, "false-negative")):
            ax.set_xlabel(args.distance_label + ("; series side by side" if len(series_list) > 1 else ""),
                          fontsize=9)
            ax.set_ylabel(kind + " rate (% of queries)")
            floor_at_zero(ax)
            ax.grid(True, alpha=0.3)
        if not series_list:
            fp_ax.text(0.5, 0.5, "no inexact strategy", ha="center", transform=fp_ax.transAxes)
    legend_below(fig, axes)
    fig.savefig(out, dpi=110, bbox_inches="tight")
    plt.close(fig)


def annotate_work(ax, x, y, bv_tests, colour):
    """BV tests per query as a small number beside a point: the work behind its time (none for FCL)."""
    if math.isfinite(bv_tests):
        ax.annotate(f"{bv_tests:.0f}", (x, y), textcoords="offset points", xytext=(5, 4), fontsize=7, color=colour)


def figure_error_vs_time(rows, args, out):
    meshes = meshes_of(rows)
    hierarchies = list(dict.fromkeys(r["hierarchy"] for r in rows))
    strategies = list(dict.fromkeys(walk_of(r) for r in rows))
    fig, per_mesh, axes = subplots(len(meshes))
    for (ax,), mesh in zip(per_mesh, meshes):
        groups = grouped([r for r in rows if r["mesh"] == mesh])
        curves = {}
        budget_markers = iter(["D", "P", "X", "*", "v", "<", ">"])  # one marker per time-critical budget
        for i, series in enumerate(groups.values()):
            first = series[0]
            agg = aggregate(series, args.quality_min, args.quality_max, band=True)
            if agg is None:
                continue
            if is_sweep(first, args):
                curves.setdefault((first["hierarchy"], curve_name(first)), []).append((float(first["p_min"]), agg))
                continue
            colour, _, marker = style_for(first["hierarchy"], walk_of(first), hierarchies, strategies)
            if first["budget"]:
                marker = next(budget_markers, "D")
            ax.plot([agg["time"]], [100 * (agg["fp"] + agg["fn"])], marker, color=colour, linestyle="none",
                    label=f"{first['hierarchy']}: {series_label(first)}", **layered(i))
            annotate_work(ax, agg["time"], 100 * (agg["fp"] + agg["fn"]), agg["bv"], colour)
        labels = []
        for (hierarchy, name), points in curves.items():
            points.sort(key=lambda p: p[0])
            colour, line, marker = style_for(hierarchy, args.operating_strategy, hierarchies, strategies)
            xs = [p[1]["time"] for p in points]
            ys = [100 * (p[1]["fp"] + p[1]["fn"]) for p in points]
            plain = name == args.operating_strategy  # variants (confirm_levels=...) of the same hierarchy: dashed
            ax.plot(xs, ys, "-" if plain else "--", marker="^", color=colour, label=f"{hierarchy}: {name} over p_min")
            labels += [(x, y, f"{p:g}" + (f" · {a['bv']:.0f}" if math.isfinite(a["bv"]) else ""), hierarchy)
                       for (p, a), x, y in zip(points, xs, ys)]
        log_axis(ax, "x")
        bands = dict(b.split("=", 1) for b in args.band if "=" in b)
        ax.set_title(f"{mesh}: error vs time, {bands.get(mesh, args.quality_text)}", fontsize=9)
        ax.set_xlabel(TIME_LABEL + ", log scale")
        ax.set_ylabel("wrong answers (FP + FN, % of queries)")
        floor_at_zero(ax)
        ax.grid(True, which="both", alpha=0.3)
        spread_labels(ax, labels, lambda h: style_for(h, args.operating_strategy, hierarchies, strategies)[0])
    legend_below(fig, axes)
    fig.savefig(out, dpi=110, bbox_inches="tight")
    plt.close(fig)


def inexact_colours(rows):
    """The colour of every inexact series of results.csv, keyed as grouped() keys it: figures 2 and 4 share it."""
    return series_colours(list(grouped([r for r in rows if not is_exact(r)]).keys()))


def p_min_of(value):
    return None if value in ("", None) else round(float(value), 9)


def calibration_series(calibration, rows):
    """{(mesh, series key): the series' bins by bin_low}, in first-appearance order. The key is results.csv's
    (hierarchy, label), found by (mesh, hierarchy, strategy, p_min, budget), so a series has the colour and
    name it has in the other figures; a calibrated series (calibration.csv's "calibrated" column) is its raw
    series' key with " calibrated" after the label, drawn next to it."""
    labels = {(r["mesh"], r["hierarchy"], r["strategy"], p_min_of(r["p_min"]), r["budget"]): r
              for r in rows if not is_exact(r)}
    out = {}
    for b in calibration:
        row = labels.get((b["mesh"], b["hierarchy"], b["strategy"], p_min_of(b["p_min"]), b["budget"]))
        key = series_key(row) if row else series_key(b)
        if is_calibrated(b):
            key = (key[0], key[1] + " calibrated" if isinstance(key[1], str) else (*key[1], "calibrated"))
        out.setdefault((b["mesh"], key), []).append(b)
    for bins in out.values():
        bins.sort(key=lambda b: num(b["bin_low"]))
    return out


def is_calibrated(b):
    return str(b.get("calibrated", "0")).lower() in ("1", "true")


def raw_series_key(key):
    """The key of the raw series a calibrated series key was made from (calibration_series)."""
    hierarchy, label = key
    if isinstance(label, str) and label.endswith(" calibrated"):
        return hierarchy, label[:-len(" calibrated")]
    if isinstance(label, tuple) and label and label[-1] == "calibrated":
        return hierarchy, label[:-1]
    return key


def calibration_line(bins):
    """The x and y of a series' line through its bins (sorted by bin_low): NaN at an empty bin, and between bins
    that do not touch, so that the line breaks there instead of bridging the gap."""
    xs, ys = [], []
    previous_high = None
    for b in bins:
        if previous_high is not None and abs(num(b["bin_low"]) - previous_high) > 1e-9:
            xs.append(math.nan)
            ys.append(math.nan)
        empty = int(b["count"]) == 0
        xs.append(math.nan if empty else num(b["mean_probability"]))
        ys.append(math.nan if empty else num(b["collision_frequency"]))
        previous_high = num(b["bin_high"])
    return xs, ys


def calibration_gap(bins, min_answers=None):
    """(largest |reported - observed| over the bins holding at least min_answers, how many bins that is); the
    gap is None when no bin qualifies. The README's calibration table applies the same rule."""
    min_answers = CALIBRATION_MIN_ANSWERS if min_answers is None else min_answers
    gaps = [abs(num(b["mean_probability"]) - num(b["collision_frequency"])) for b in bins
            if int(b["count"]) >= max(1, min_answers)]
    return (max(gaps) if gaps else None), len(gaps)


def compact_count(n):
    return f"{n}" if n < 1000 else f"{n / 1000:.0f}k" if n >= 10000 else f"{n / 1000:.1f}k"


def draw_calibration_panel(ax, bins, colour):
    ax.fill_between([0, 1], [-CALIBRATION_TOLERANCE, 1 - CALIBRATION_TOLERANCE],
                    [CALIBRATION_TOLERANCE, 1 + CALIBRATION_TOLERANCE], color="grey", alpha=0.15, linewidth=0)
    ax.plot([0, 1], [0, 1], "--", color="grey", linewidth=1)
    xs, ys = calibration_line(bins)
    ax.plot(xs, ys, "-", color=colour, linewidth=1.2, alpha=0.7)
    used = [b for b in bins if int(b["count"]) > 0]
    most = max([int(b["count"]) for b in used], default=1)
    for judged in (True, False):
        picked = [b for b in used if (int(b["count"]) >= CALIBRATION_MIN_ANSWERS) == judged]
        if picked:
            ax.scatter([num(b["mean_probability"]) for b in picked], [num(b["collision_frequency"]) for b in picked],
                       s=[14 + 70 * math.sqrt(int(b["count"]) / most) for b in picked],
                       facecolors=colour if judged else "none", edgecolors=colour, linewidths=1.2, zorder=3)
    for b in used:
        ax.annotate(compact_count(int(b["count"])), (num(b["mean_probability"]), num(b["collision_frequency"])),
                    textcoords="offset points", xytext=(5, -9), fontsize=6, color="dimgrey")
    gap, judged = calibration_gap(bins)
    verdict = ("no decile holds enough answers" if gap is None else
               f"largest gap {gap:.3f} over {judged} decile{'s' if judged != 1 else ''}: "
               + ("within" if gap <= CALIBRATION_TOLERANCE else "beyond") + f" {CALIBRATION_TOLERANCE:g}")
    # Above the axes, under the title: inside, it would hide points.
    ax.text(0.5, 1.015, verdict, transform=ax.transAxes, ha="center", va="bottom", fontsize=7)


def calibration_legend(fig):
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    handles = [Line2D([], [], linestyle="--", color="grey", label="perfect calibration"),
               Patch(color="grey", alpha=0.15, label=f"within {CALIBRATION_TOLERANCE:g} (the target)"),
               Line2D([], [], linestyle="none", marker="o", color="black",
                      label=f"decile with at least {CALIBRATION_MIN_ANSWERS} answers (judged)"),
               Line2D([], [], linestyle="none", marker="o", markerfacecolor="none", color="black",
                      label=f"decile with fewer than {CALIBRATION_MIN_ANSWERS} answers (not judged)")]
    fig.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, 0.0), ncol=2, fontsize=9, frameon=False)


def draw_calibration(calibration, rows, columns=4, size=3.1):
    """Small multiples: per mesh, one panel per inexact series, in the colour figure 2 gives it. Returns the
    figure and {(mesh, series key): its axes}."""
    colours = inexact_colours(rows)
    series = calibration_series(calibration, rows)
    meshes = list(dict.fromkeys(mesh for mesh, _ in series))
    per_mesh = {m: [k for k in series if k[0] == m] for m in meshes}
    columns = max(1, min(columns, max([len(v) for v in per_mesh.values()], default=1)))
    mesh_rows = [max(1, math.ceil(len(per_mesh[m]) / columns)) for m in meshes] or [1]
    fig, grid = plt.subplots(sum(mesh_rows), columns, figsize=(size * columns, size * sum(mesh_rows)),
                             squeeze=False, sharex=True, sharey=True, constrained_layout=True)
    axes_of, first_row = {}, 0
    for mesh, n_rows in zip(meshes, mesh_rows):
        for i, key in enumerate(per_mesh[mesh]):
            ax = grid[first_row + i // columns][i % columns]
            axes_of[key] = ax
            hierarchy, label = key[1]
            colour = colours.get(raw_series_key(key[1]), "black")
            draw_calibration_panel(ax, series[key], colour)
            name = series_label({"label": label}) if isinstance(label, str) else " ".join(label)
            ax.set_title(f"{mesh} · {hierarchy}\n{name}", fontsize=8, color=colour, pad=12)
        for i in range(len(per_mesh[mesh]), n_rows * columns):
            grid[first_row + i // columns][i % columns].set_visible(False)
        first_row += n_rows
    for ax in grid.flat:
        ax.set_xlim(-0.02, 1.02)
        ax.set_ylim(-0.02, 1.02)
        ax.set_aspect("equal")
        ax.grid(True, alpha=0.3)
    for ax in grid[:, 0]:
        ax.set_ylabel("observed collision frequency", fontsize=8)
    for ax in grid[-1, :]:
        ax.set_xlabel("reported probability (decile mean)", fontsize=8)
    if not series:
        grid[0][0].text(0.5, 0.5, "no inexact strategy", ha="center", transform=grid[0][0].transAxes)
    calibration_legend(fig)
    fig.suptitle("Calibration over all distances, deciles of the reported probability: numbers are the answers "
                 "in each decile (marker area grows with them); the line breaks at an empty decile", fontsize=9)
    return fig, axes_of


def figure_calibration(calibration, rows, out):
    fig, _ = draw_calibration(calibration, rows)
    fig.savefig(out, dpi=110, bbox_inches="tight")
    plt.close(fig)


def figure_time_vs_size(rows, args, out):
    fig, axes, panels = exact_and_operating_panels(rows, args)
    for ax, mesh, shown in panels:
        for i, (series, (colour, _, marker), label) in enumerate(shown):
            agg = aggregate(series, -1e300, 1e300)
            if agg is None or not math.isfinite(agg["bytes"]):
                continue
            ax.plot([agg["bytes"]], [agg["time"]], marker, color=colour, linestyle="none", label=label, **layered(i))
            annotate_work(ax, agg["bytes"], agg["time"], agg["bv"], colour)
        log_axis(ax)
        ax.set_title(f"{mesh}: time vs model size (all distances)")
        ax.set_xlabel("model size (bytes per triangle, without polygons)")
        ax.set_ylabel(TIME_LABEL)
        ax.grid(True, which="both", alpha=0.3)
        ax.margins(x=0.15)
    legend_below(fig, axes)
    fig.savefig(out, dpi=110, bbox_inches="tight")
    plt.close(fig)


def add_options(parser):
    parser.add_argument("--quality-min", type=float, default=-1e300)
    parser.add_argument("--quality-max", type=float, default=1e300)
    parser.add_argument("--quality-text", default="the quality distances")
    parser.add_argument("--band", action="append", default=[],
                        help="MESH=TEXT: the summary band of one mesh pair, for figure 3's title")
    parser.add_argument("--distance-label", default=DEFAULT_DISTANCE_LABEL)
    parser.add_argument("--operating-strategy", default="")
    parser.add_argument("--operating-hierarchy", default="")
    parser.add_argument("--operating-p-min", type=float, default=-1)


def draw(args, rows, calibration):
    out = lambda name: os.path.join(args.report_dir, name)  # noqa: E731
    # The calibration panels take about half of the drawing time: first, beside the other four.
    draw_each([(figure_calibration, calibration, rows, out("fig4_calibration.png")),
               (figure_time_vs_distance, rows, args, out("fig1_time_vs_distance.png")),
               (figure_errors_vs_distance, rows, args, out("fig2_errors_vs_distance.png")),
               (figure_error_vs_time, rows, args, out("fig3_error_vs_time.png")),
               (figure_time_vs_size, rows, args, out("fig5_time_vs_size.png"))])


def main(argv=None):
    report_main(__file__, __doc__, ["results.csv"], draw, optional=["calibration.csv"], add_options=add_options,
                refusal="has no rows", argv=argv)


if __name__ == "__main__":
    main()
