"""What the tests of the report plot scripts share: bench/ on the path (the scripts and plot_common.py), and the
checks every script owes: its figures drawn from a report folder, its refusals, and running by path from any
folder, as `bvhlab report` runs it.

Plain unittest, so it needs nothing beyond matplotlib; ctest sets BVHLAB_SOURCE_DIR.
"""
import csv
import os
import subprocess
import sys
import tempfile

SOURCE_DIR = os.environ.get("BVHLAB_SOURCE_DIR", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
BENCH_DIR = os.path.join(SOURCE_DIR, "bench")
sys.path.insert(0, BENCH_DIR)


def write_tables(folder, tables):
    """Writes each of `tables` ({CSV file name: rows as dicts}) into `folder`, the columns those of its first row."""
    for name, rows in tables.items():
        with open(os.path.join(folder, name), "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)


class ReportScriptChecks:
    """Mixed into a unittest.TestCase that sets `script` (the imported module), `required` (the CSV files it
    refuses to draw without) and `figures` (the files it draws)."""

    def assertDrawsItsFigures(self, tables):
        """main() on a folder holding `tables` writes every one of the script's figures, each of some substance."""
        with tempfile.TemporaryDirectory() as d:
            write_tables(d, tables)
            self.script.main([d])
            for name in self.figures:
                path = os.path.join(d, name)
                self.assertTrue(os.path.isfile(path), f"{name} was not drawn")
                self.assertGreater(os.path.getsize(path), 1000, name)

    def assertRefusesWithoutEachRequiredTable(self, tables):
        """main() exits naming the file when a required table is missing or has a header and no rows, and draws
        nothing."""
        for name in self.required:
            for rows in (None, []):
                with self.subTest(table=name, header_only=rows is not None), tempfile.TemporaryDirectory() as d:
                    write_tables(d, {n: r for n, r in tables.items() if n != name})
                    if rows is not None:
                        with open(os.path.join(d, name), "w") as f:
                            f.write(",".join(tables[name][0]) + "\n")
                    with self.assertRaises(SystemExit) as refusal:
                        self.script.main([d])
                    self.assertIn(name, str(refusal.exception.code))
                    self.assertTrue(str(refusal.exception.code).startswith(os.path.basename(self.script.__file__)))
                    self.assertEqual([f for f in os.listdir(d) if f.endswith(".png")], [])

    def test_runs_by_path_from_another_folder(self):
        """As `bvhlab report` runs it: by its path, from the report's folder; it must find plot_common.py itself."""
        with tempfile.TemporaryDirectory() as d:
            env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
            done = subprocess.run([sys.executable, os.path.abspath(self.script.__file__), d], cwd=d, env=env,
                                  capture_output=True, text=True, timeout=60)
            self.assertEqual(done.returncode, 1, done.stderr)
            self.assertNotIn("Traceback", done.stderr)
            self.assertIn(self.required[0], done.stderr)
