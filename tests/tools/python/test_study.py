#!/usr/bin/python3
"""`dhpd study` (tools/python/study.py, study_report.py, launch.py) on the 1D bar with a spacing
jump (a reference and two variants, tens of milliseconds each): the peak memory of each variant is
the engine process's own (summary.json peak_memory_mb), not the Python driver's, even when the
driver holds 300 MiB; study.csv and study.md are written as the variants finish; a second study
into the same folder reuses every completed run (no engine started) and runs again exactly those
whose study_variant.json or summary.json no longer match; pareto.png carries the budget line."""
import json
import math
import os
import shutil
import subprocess
import sys
import threading
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import support  # noqa: E402

support.import_tools()
import numpy as np  # noqa: E402

import launch  # noqa: E402
import study as study_tool  # noqa: E402
import study_fronts  # noqa: E402
import study_report  # noqa: E402

BALLAST_MIB = 300
STUDY = """\
name: bar
case: {case}
reference: {{label: quarter, set: {{body.0.spacing: 0.0104166666666666667,
                                   body.1.spacing: 0.00104166666666666667}}}}
variants:
  - {{label: case spacing}}
  - {{label: half, set: {{body.0.spacing: 0.0208333333333333333,
                         body.1.spacing: 0.00208333333333333333}}}}
error: l2_displacement
budget: {{l2_displacement: 0.8}}
"""
LABELS = ["quarter", "case spacing", "half"]
FOLDERS = ["run-reference", "run-00", "run-01"]
# A driver that holds BALLAST_MIB of its own before it runs study.py as `dhpd study` would.
DRIVER = """\
import os, runpy, sys
ballast = b"x" * ({ballast} << 20)
sys.path.insert(0, {tools!r})
sys.argv = [{script!r}] + sys.argv[1:]
runpy.run_path({script!r}, run_name="__main__")
"""
# A `dhpd` that records, before it becomes the engine (exec), what the study folder held and the
# driver's own peak memory: $4 is the run's --out folder, inside the study's.
WRAPPER = """\
#!/bin/sh
n=$(ls "$WRAP_LOG" | wc -l)
mkdir "$WRAP_LOG/call$n"
study=$(dirname "$4")
for f in study.csv study.md pareto.png; do
  [ -f "$study/$f" ] && cp "$study/$f" "$WRAP_LOG/call$n/"
done
grep VmHWM "/proc/$PPID/status" > "$WRAP_LOG/call$n/driver"
echo "$4" > "$WRAP_LOG/call$n/out"
exec "$REAL_DHPD" "$@"
"""
WORK = STUDY_FILE = None


def setUpModule():
    global WORK, STUDY_FILE
    support.require_binary()
    WORK = support.Workdir("study")
    case = os.path.join(support.SOURCE, "cases", "wave_bar_1d.yaml")
    STUDY_FILE = support.write(WORK("bar.yaml"), STUDY.format(case=case))
    support.write(WORK("driver.py"), DRIVER.format(
        ballast=BALLAST_MIB, tools=support.TOOLS, script=os.path.join(support.TOOLS, "study.py")))
    os.makedirs(WORK("bin"))
    support.write(WORK("bin", "dhpd"), WRAPPER)
    os.chmod(WORK("bin", "dhpd"), 0o755)


def tearDownModule():
    if WORK:
        WORK.cleanup()


def study(out, log):
    """study.py on the bar study into `out` through the recording wrapper, from a driver holding
    BALLAST_MIB; returns the CompletedProcess; `log` gets one folder per engine started."""
    os.makedirs(log, exist_ok=True)
    env = dict(os.environ, WRAP_LOG=log, REAL_DHPD=support.BIN)
    proc = subprocess.run([support.PYTHON, WORK("driver.py"), STUDY_FILE, "--dhpd",
                           WORK("bin", "dhpd"), "--out", out], capture_output=True, text=True,
                          env=env, timeout=300)
    if proc.returncode != 0:
        raise AssertionError(f"study exited {proc.returncode}:\n{proc.stdout}\n{proc.stderr}")
    return proc


def calls(log):
    """The engine runs the wrapper saw, in order: [(call folder, the run's out folder)]."""
    folders = sorted(os.listdir(log), key=lambda n: int(n[4:]))
    return [(os.path.join(log, f), support.read(os.path.join(log, f, "out")).strip())
            for f in folders]


def study_rows(path):
    return support.csv_rows(path)


def mtimes(out):
    return {f: os.stat(os.path.join(out, f, "summary.json")).st_mtime_ns for f in FOLDERS}


class FirstStudy(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.out, cls.log = WORK("first"), WORK("first-log")
        cls.proc = study(cls.out, cls.log)
        cls.rows = study_rows(os.path.join(cls.out, "study.csv"))

    def test_peak_memory_is_each_engine_process_s_own(self):
        self.assertEqual([r["label"] for r in self.rows], LABELS)
        # The driver did hold the ballast while the engines ran ...
        for call, _ in calls(self.log):
            driver_kib = int(support.read(os.path.join(call, "driver")).split()[1])
            self.assertGreater(driver_kib / 1024.0, BALLAST_MIB)
        # ... and each row has its engine's own high-water mark, far below it.
        for row, folder in zip(self.rows, FOLDERS):
            engine = support.summary(os.path.join(self.out, folder))["peak_memory_mb"]
            self.assertEqual(row["peak_source"], "summary.json peak_memory_mb")
            self.assertAlmostEqual(float(row["peak_mib"]), engine, places=6)
            self.assertLess(float(row["peak_mib"]), BALLAST_MIB / 2)
            record = json.loads(support.read(os.path.join(self.out, folder,
                                                          "study_variant.json")))
            self.assertAlmostEqual(record["result"]["peak_mib"], engine, places=6)
        md = support.read(os.path.join(self.out, "study.md"))
        self.assertIn("Peak memory: each engine process's own (summary.json peak_memory_mb: 3 "
                      "run(s)).", md)
        for row in self.rows[1:]:
            self.assertIn(f"| {float(row['peak_mib']):.0f} |", md)

    def test_study_csv_and_md_are_written_as_the_variants_finish(self):
        seen = calls(self.log)
        self.assertEqual([os.path.basename(out) for _, out in seen], FOLDERS)
        reference, first, second = (call for call, _ in seen)
        self.assertEqual(sorted(os.listdir(reference)), ["driver", "out"])  # nothing written yet
        for call, done in ((first, 0), (second, 1)):
            rows = study_rows(os.path.join(call, "study.csv"))
            self.assertEqual([r["label"] for r in rows], LABELS[:done + 1])
            md = support.read(os.path.join(call, "study.md"))
            self.assertIn(f"**In progress: {done} of 2 variants done.**", md)
            self.assertTrue(os.path.isfile(os.path.join(call, "pareto.png")))
        self.assertNotIn("In progress", support.read(os.path.join(self.out, "study.md")))
        # A variant's row as it was written then is the row of the final table.
        early = study_rows(os.path.join(second, "study.csv"))[1]
        self.assertEqual(early, self.rows[1])

    def test_pareto_png_has_the_budget_line(self):
        picture = support.png(os.path.join(self.out, "pareto.png"))
        green = support.colour_pixels(picture, (0.173, 0.627, 0.173), 0.05)  # tab:green
        self.assertGreater(green, 200)
        self.assertIn("Cheapest within the budget (l2_displacement ≤ 0.8): **half**",
                      support.read(os.path.join(self.out, "study.md")))


class Resume(unittest.TestCase):
    """A second study into the folder of the first (a copy of it, timestamps kept)."""

    @classmethod
    def setUpClass(cls):
        cls.first = WORK("resume-first")
        study(cls.first, WORK("resume-first-log"))

    def copy(self, name):
        out = WORK(name)
        shutil.copytree(self.first, out)
        return out

    def test_a_second_study_reuses_every_completed_run(self):
        out, log = self.copy("again"), WORK("again-log")
        before, rows_before = mtimes(out), study_rows(os.path.join(out, "study.csv"))
        proc = study(out, log)
        self.assertEqual(calls(log), [])  # no engine started
        for label, folder in zip(LABELS, FOLDERS):
            self.assertIn(f"dhpd study: {label}: reused {out}/{folder} (its summary.json is "
                          "completed, with the same overrides)", proc.stdout)
        self.assertEqual(mtimes(out), before)
        rows = study_rows(os.path.join(out, "study.csv"))
        for old, new in zip(rows_before, rows):
            self.assertEqual((new["wall_s"], new["peak_mib"]), (old["wall_s"], old["peak_mib"]))
            self.assertEqual(new["l2_displacement"], old["l2_displacement"])  # measured again
        self.assertIn("Reused from an earlier study run (completed, same overrides): quarter, "
                      "case spacing, half.", support.read(os.path.join(out, "study.md")))

    def test_runs_that_no_longer_match_are_run_again(self):
        out, log = self.copy("partly"), WORK("partly-log")
        before = mtimes(out)
        os.remove(os.path.join(out, "run-01", "study_variant.json"))  # half: forced again
        summary = os.path.join(out, "run-00", "summary.json")  # case spacing: stopped
        data = json.loads(support.read(summary))
        data["status"] = "interrupted"
        support.write(summary, json.dumps(data))
        before["run-00"] = os.stat(summary).st_mtime_ns
        proc = study(out, log)
        self.assertEqual([os.path.basename(o) for _, o in calls(log)], ["run-00", "run-01"])
        self.assertIn("dhpd study: quarter: reused", proc.stdout)
        self.assertNotIn("case spacing: reused", proc.stdout)
        self.assertNotIn("half: reused", proc.stdout)
        after = mtimes(out)
        self.assertEqual(after["run-reference"], before["run-reference"])
        self.assertNotEqual(after["run-00"], before["run-00"])
        self.assertNotEqual(after["run-01"], before["run-01"])
        self.assertEqual(support.summary(os.path.join(out, "run-00"))["status"], "completed")
        self.assertTrue(os.path.isfile(os.path.join(out, "run-01", "study_variant.json")))
        self.assertIn("Reused from an earlier study run (completed, same overrides): quarter.",
                      support.read(os.path.join(out, "study.md")))

    def test_other_overrides_or_threads_are_not_reused(self):
        out, log = self.copy("changed"), WORK("changed-log")
        record = os.path.join(out, "run-reference", "study_variant.json")
        data = json.loads(support.read(record))
        data["threads"] = 1  # the study asks for dhpd's default (null)
        support.write(record, json.dumps(data))
        study(out, log)
        self.assertEqual([os.path.basename(o) for _, o in calls(log)], ["run-reference"])

    def test_an_edited_scene_or_a_rebuilt_engine_is_not_reused(self):
        out, log = self.copy("rebuilt"), WORK("rebuilt-log")
        for folder, key in (("run-reference", "scene_sha256"), ("run-01", "dhpd_sha256")):
            record = os.path.join(out, folder, "study_variant.json")
            data = json.loads(support.read(record))
            self.assertEqual(len(data[key]), 64)  # recorded when the run was made
            data[key] = "0" * 64
            support.write(record, json.dumps(data))
        study(out, log)
        self.assertEqual(sorted(os.path.basename(o) for _, o in calls(log)),
                         ["run-01", "run-reference"])

    def test_the_record_follows_the_scene_files_content(self):
        scene = WORK("record-scene.yaml")
        support.write(scene, "name: a\n")
        first = study_tool.variant_record(scene, {}, None, sys.executable)
        support.write(scene, "name: b\n")
        second = study_tool.variant_record(scene, {}, None, sys.executable)
        self.assertNotEqual(first["scene_sha256"], second["scene_sha256"])
        self.assertEqual(first["dhpd_sha256"], second["dhpd_sha256"])


def row(label, wall, **metrics):
    r = {"label": label, "case": "bar.yaml", "wall_s": wall, "particle_steps": 1000.0,
         "peak_mib": 20.0, "peak_source": launch.SOURCE_SUMMARY, "particles_end": 100,
         "overrides": {}}
    r.update({m: None for m in study_report.METRICS})
    r.update(metrics)
    return r


class Pareto(unittest.TestCase):
    ROWS = [row("a", 1.0, tip_path=0.001), row("b", 2.0, tip_path=0.0005),
            row("c", 3.0, tip_path=0.002), row("unmeasured", 0.5)]
    REFERENCE = row("ref", 10.0)

    def draw(self, budget, metric="tip_path"):
        front = study_report.pareto_front(self.ROWS, metric)
        with support.captured_figures() as figures:
            study_report.plot_pareto(self.ROWS, metric, front, self.REFERENCE,
                                     WORK("pareto.png"), budget, "bar")
            ax = figures[0].axes[0]
            return front, ax, {line.get_label(): line for line in ax.lines}

    def test_budget_line_in_the_error_s_unit(self):
        front, ax, lines = self.draw({"tip_path": 0.0015, "angle_deg": 3.0})
        self.assertEqual(front, [0, 1])
        budget = lines["budget: tip_path ≤ 1.5 mm"]
        np.testing.assert_allclose(budget.get_ydata(), [1.5, 1.5])
        self.assertEqual(budget.get_linestyle(), ":")
        self.assertEqual(budget.get_color(), "tab:green")
        reference = lines["reference (ref, 10 s)"]
        np.testing.assert_allclose(reference.get_xdata(), [10.0, 10.0])
        self.assertEqual(reference.get_linestyle(), "--")
        pareto = lines["Pareto front"]
        np.testing.assert_allclose(pareto.get_xdata(), [1.0, 2.0])
        np.testing.assert_allclose(pareto.get_ydata(), [1.0, 0.5])  # mm
        self.assertEqual(ax.get_xlabel(), "wall time (s)")
        self.assertEqual(ax.get_xscale(), "log")
        self.assertEqual(ax.get_ylabel(),
                         "tip path error, largest distance to the reference path (mm)")
        self.assertEqual(len(ax.collections[0].get_offsets()), 3)  # the unmeasured one left out
        self.assertEqual(study_report.cheapest_within(self.ROWS, {"tip_path": 0.0015})["label"],
                         "a")

    def test_no_budget_line_without_a_budget_of_the_plotted_error(self):
        _, _, lines = self.draw({"angle_deg": 3.0})
        self.assertFalse(any(label.startswith("budget") for label in lines))
        _, _, lines = self.draw({"initiation": 0.1}, "initiation")  # dimensionless: no unit
        self.assertIn("budget: initiation ≤ 0.1", lines)

    def test_write_outputs_passes_the_study_s_budget_to_the_picture(self):
        out = WORK("outputs")
        os.makedirs(out)
        study = {"name": "bar", "error": "tip_path", "budget": {"tip_path": 0.0015}}
        with support.captured_figures() as figures:
            best = study_report.write_outputs(study, self.ROWS, self.REFERENCE, out,
                                              progress=(2, 4, ()))
            labels = [line.get_label() for line in figures[0].axes[0].lines]
        self.assertIn("budget: tip_path ≤ 1.5 mm", labels)
        self.assertEqual(best["label"], "a")
        md = support.read(os.path.join(out, "study.md"))
        self.assertIn("**In progress: 2 of 4 variants done.**", md)
        self.assertEqual(len(study_rows(os.path.join(out, "study.csv"))), 5)


class Verdicts(unittest.TestCase):
    """The criteria, the quarter rule over a variant's runs and the controls (study_members.py)."""
    STUDY = {"criteria": {"crack_distance": 0.0008, "broken_bonds": 0.25}}

    @staticmethod
    def run_row(label, distance, bonds=0.1, group=None, expect=None):
        r = {"label": label, "crack_distance": distance, "broken_bonds": bonds}
        if group:
            r["group"] = group
        if expect:
            r["expect"] = expect
        return r

    def test_a_value_at_the_limit_up_to_round_off_is_within_it(self):
        at_limit = self.run_row("a", math.nextafter(0.0008, 1.0))  # 4 spacings of 0.2 mm + an ulp
        self.assertEqual(study_report.criteria_failures(self.STUDY, [at_limit]), [])
        past = self.run_row("b", 0.0008 * (1 + 1e-6))
        self.assertEqual(study_report.criteria_failures(self.STUDY, [past]),
                         [("b", "crack_distance", past["crack_distance"], 0.0008)])
        unmeasured = self.run_row("c", None)
        self.assertEqual(len(study_report.criteria_failures(self.STUDY, [unmeasured])), 1)

    def test_a_variant_passes_when_at_most_a_quarter_of_its_runs_miss(self):
        rows = [self.run_row(f"v{k}", 0.001 if k < misses else 0.0005, group="v")
                for misses in (1, 2) for k in range(4)]
        one_miss = study_report.group_verdicts(self.STUDY, rows[:4])
        two_misses = study_report.group_verdicts(self.STUDY, rows[4:])
        self.assertEqual(one_miss, [("v", True, 3, 4)])
        self.assertEqual(two_misses, [("v", False, 2, 4)])
        alone = study_report.group_verdicts(self.STUDY, [self.run_row("w", 0.001)])
        self.assertEqual(alone, [("w", False, 0, 1)])

    def test_a_control_that_meets_every_criterion_is_reported(self):
        import study_members
        rows = [self.run_row("coarse", 0.0011, expect="miss"),
                self.run_row("too good", 0.0002, expect="miss")]
        rows[1]["matched"] = "uniform fine"
        lines = study_members.control_failures(self.STUDY, rows)
        self.assertEqual(len(lines), 1)
        self.assertTrue(lines[0].startswith("too good: meets every criterion (against uniform "
                                            "fine)"))


class PolledPeak(unittest.TestCase):
    """launch.py's fallback when a run writes no peak_memory_mb: /proc VmHWM of the engine."""

    def test_the_driver_s_own_memory_never_counts(self):
        ballast = b"x" * (BALLAST_MIB << 20)  # noqa: F841 (held while polling)
        self.assertIsNone(launch.high_water_mib(os.getpid(), "dhpd"))
        self.assertEqual(launch.peak_memory({"peak_memory_mb": 42.5}, 300.0),
                         (42.5, launch.SOURCE_SUMMARY))
        self.assertEqual(launch.peak_memory({}, 12.0), (12.0, launch.SOURCE_PROC))
        self.assertEqual(launch.peak_memory({"peak_memory_mb": 0}, None), (None, "unknown"))
        self.assertEqual(launch.peak_memory(None, None), (None, "unknown"))

    def test_polled_high_water_mark_is_the_engine_s(self):
        ballast = b"x" * (BALLAST_MIB << 20)  # noqa: F841 (held while the engine runs)
        scene = support.small_scene(WORK.path)
        out = WORK("polled")
        proc = subprocess.Popen([support.BIN, "run", scene, "-o", out, "-q"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        done, peak = threading.Event(), [None]
        watcher = threading.Thread(target=launch.watch_memory,
                                   args=(proc.pid, os.path.basename(support.BIN), done, peak))
        watcher.start()
        proc.wait()
        done.set()
        watcher.join()
        self.assertEqual(proc.returncode, 0)
        engine = support.summary(out)["peak_memory_mb"]
        self.assertIsNotNone(peak[0])
        self.assertLessEqual(peak[0], engine * 1.01)
        self.assertGreater(peak[0], 0.5 * engine)
        self.assertLess(peak[0], BALLAST_MIB / 2)


class Fronts(unittest.TestCase):
    """`fronts`: every variant once per value of a key, one Pareto front per value."""
    FRONTS = {"key": "time.multirate", "values": [False, True], "labels": ["one step", "levels"]}

    def test_every_run_runs_once_per_value_with_the_key_set(self):
        runs = [("a", "x.yaml", {"k": 1}, None, "a"), ("b", "x.yaml", {}, "miss", "b")]
        out = study_fronts.expand(self.FRONTS, runs)
        self.assertEqual([r[0] for r in out], ["a · one step", "b · one step", "a · levels",
                                               "b · levels"])
        self.assertEqual(out[2][2], {"k": 1, "time.multirate": True})
        self.assertEqual(out[1][3:], ("miss", "b · one step", "one step"))
        self.assertEqual(study_fronts.expand(None, runs)[0][5], None)

    def test_malformed_fronts_are_refused(self):
        self.assertIsNone(study_fronts.check(self.FRONTS))
        for bad in ({"key": "a", "values": [1]}, {"values": [1, 2]},
                    {"key": "a", "values": [1, 2], "labels": ["x"]},
                    {"key": "a", "values": [1, 2], "labels": ["x", "x"]},
                    {"key": "a", "values": [1, 2], "colour": "red"}):
            self.assertIsNotNone(study_fronts.check(bad), bad)

    def test_each_value_gets_its_own_front_in_the_picture_and_the_text(self):
        rows = [row("a · one step", 1.0, tip_path=0.001), row("b · one step", 2.0, tip_path=0.0005),
                row("a · levels", 0.5, tip_path=0.001), row("b · levels", 1.5, tip_path=0.002)]
        for r, front in zip(rows, ["one step", "one step", "levels", "levels"]):
            r["front"] = front
        out = WORK("fronts")
        os.makedirs(out)
        study = {"name": "bar", "error": "tip_path", "budget": {"tip_path": 0.0015}}
        with support.captured_figures() as figures:
            study_report.write_outputs(study, rows, row("ref", 10.0), out)
            lines = {line.get_label(): line for line in figures[0].axes[0].lines}
        np.testing.assert_allclose(lines["Pareto front: one step"].get_xdata(), [1.0, 2.0])
        # b · levels is slower and worse than a · levels: only a is on that front.
        np.testing.assert_allclose(lines["Pareto front: levels"].get_xdata(), [0.5])
        md = support.read(os.path.join(out, "study.md"))
        self.assertIn("- **one step**: cheapest within the budget **a · one step**, 1.00 s", md)
        self.assertIn("- **levels**: cheapest within the budget **a · levels**, 0.50 s (20.0×", md)
        self.assertIn("on the front: a · levels.", md)


if __name__ == "__main__":
    support.main()
