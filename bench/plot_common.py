"""What the report plot scripts (plot_report.py, plot_world.py, plot_deform.py, plot_points.py) share: reading
a report's CSV files and grouping their rows, the command line over REPORT_DIR with its refusal of empty input,
and saving a figure.

The scripts import it from their own folder (Python puts a script's folder first on sys.path), so it must stay
beside them wherever they are run from.
"""
import argparse
import csv
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_csv(path):
    """The rows of a CSV file as dicts by column; none when the file is not there (a report without that part)."""
    if not os.path.exists(path):
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def group_by(rows, key):
    """{key(row): [rows with that key]}, the rows in their order."""
    groups = defaultdict(list)
    for r in rows:
        groups[key(r)].append(r)
    return groups


def report_main(script, doc, required, draw, optional=(), add_options=None, refusal="is missing or empty",
                argv=None):
    """The command line of the script at path `script` (its __file__, which names it in usage and refusals):
    parses REPORT_DIR (and the script's own options, from add_options(parser)), reads the `required` CSV files
    and then the `optional` ones from it, exits naming the required files when any has no rows, and else calls
    draw(args, *tables), the tables in that order."""
    parser = argparse.ArgumentParser(prog=os.path.basename(script), description=doc,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("report_dir")
    if add_options:
        add_options(parser)
    args = parser.parse_args(argv)
    tables = [read_csv(os.path.join(args.report_dir, name)) for name in (*required, *optional)]
    if not all(tables[: len(required)]):
        sys.exit(f"{parser.prog}: {' or '.join(required)} {refusal}")
    draw(args, *tables)


def draw_each(jobs, workers=None):
    """Runs each job, a tuple (function, *arguments) that draws and saves one figure: on a machine of several
    cores in forked processes, one figure a process (matplotlib is not thread-safe), started in the order
    given (list the longest first), else one after another. A job's exception is raised here. Each job must
    only write its own file: nothing comes back from a process."""
    import concurrent.futures
    import multiprocessing

    workers = min(len(jobs), workers or os.cpu_count() or 1)
    if workers <= 1 or "fork" not in multiprocessing.get_all_start_methods():
        for function, *arguments in jobs:
            function(*arguments)
        return
    context = multiprocessing.get_context("fork")
    with concurrent.futures.ProcessPoolExecutor(workers, mp_context=context) as pool:
        for future in [pool.submit(function, *arguments) for function, *arguments in jobs]:
            future.result()


def save(fig, out, dpi, rect=(0, 0, 1, 1)):
    """Lays the figure out within `rect` (figure fractions: room left for a legend beside it), writes it to
    `out` and frees it (a report draws several in one process)."""
    fig.tight_layout(rect=rect)
    fig.savefig(out, dpi=dpi)
    plt.close(fig)
