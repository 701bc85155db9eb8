#!/usr/bin/python3
"""`dhpd report` (tools/python/run_report.py, report_numbers.py) on a short adaptive run of the
notched test plate: the measured crack numbers always, with the published and LEFM values and
their differences beside them; the refinement settings and an event summary; the provenance from
summary.json; and folders of runs that did not finish (summary.json gone, a history row cut
short, a frame missing; a run killed with SIGKILL), which still get pictures and a report that
say what is missing, with exit code 0."""
import csv
import os
import shutil
import signal
import subprocess
import sys
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import support  # noqa: E402

support.import_tools()
import report_numbers  # noqa: E402
import run_report  # noqa: E402
from run_data import load_run  # noqa: E402

WORK = RUN = None


def setUpModule():
    global WORK, RUN
    support.require_binary()
    WORK = support.Workdir("report")
    RUN = support.run_small(WORK.path)
    support.dhpd("report", RUN)


def tearDownModule():
    if WORK:
        WORK.cleanup()


def section(report, title):
    """The lines of a report's `## title` section."""
    start = report.index(f"## {title}")
    end = report.find("\n## ", start + 1)
    return report[start:end if end > 0 else None].splitlines()


def table_rows(lines):
    """{first cell: [cells]} of the Markdown table rows among `lines`."""
    rows = {}
    for line in lines:
        if line.startswith("| ") and not line.startswith("|---"):
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            rows.setdefault(cells[0], cells)
    return rows


def four(value):
    """A number as the report shows it (whole numbers in full, others to 4 digits)."""
    return str(int(value)) if float(value).is_integer() else f"{value:.4g}"


def percent(measured, reference):
    return f"{100.0 * (measured - reference) / abs(reference):+.2f} %"


def complete_history_rows(path):
    with open(path, newline="") as f:
        rows = [r for r in csv.reader(f) if r]
    header, good = rows[0], 0
    for row in rows[1:]:
        try:
            good += len(row) == len(header) and bool([float(c) for c in row])
        except ValueError:
            pass
    return good


class CompleteRun(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.report = support.read(os.path.join(RUN, "report.md"))
        cls.summary = support.summary(RUN)

    def test_measured_numbers_with_published_and_lefm_beside_them(self):
        lines = section(self.report, "Measured numbers")
        self.assertIn("| quantity | measured | published | difference | LEFM | difference |", lines)
        rows = table_rows(lines)
        crack = self.summary["cracks"][0]
        t_init = crack["initiation_time"] * 1e6
        self.assertEqual(rows["initiation time (µs)"],
                         ["initiation time (µs)", four(t_init), "5", percent(t_init, 5.0), "4",
                          percent(t_init, 4.0)])
        angle = crack["angle_deg"]
        self.assertEqual(rows["angle at the end (°)"],
                         ["angle at the end (°)", four(angle), "10", percent(angle, 10.0), "—",
                          "—"])
        speed = rows["max speed (m/s)"][1]
        self.assertEqual(speed, f"{four(crack['max_speed'])} "
                         f"({crack['max_speed'] / self.summary['rayleigh_speed']:.2f} c_R)")
        tip = crack["tip"]
        self.assertEqual(rows["tip at the end (mm)"][1],
                         "(" + ", ".join(four(1e3 * v) for v in tip) + ")")
        # A published top-level number is compared with the summary's own.
        end = self.summary["particles_end"]
        self.assertEqual(rows["particles_end"], ["particles_end", str(end), "1500",
                                                 percent(end, 1500.0)])
        self.assertIn(f"Rayleigh speed c_R = {four(self.summary['rayleigh_speed'])} m/s.", lines)
        self.assertFalse(any("No LEFM reference" in line for line in lines))

    def test_measured_numbers_without_references_are_still_shown(self):
        run = load_run(RUN)
        del run.summary["published"]
        lines = report_numbers.measured_section(run)
        self.assertIn("| quantity | measured |", lines)
        rows = table_rows(lines)
        self.assertEqual(rows["initiation time (µs)"][1],
                         four(self.summary["cracks"][0]["initiation_time"] * 1e6))
        self.assertIn("No published numbers: the scene has no `measure.published`.", lines)
        self.assertTrue(any(line.startswith("No LEFM reference recorded") for line in lines))

    def test_lefm_values_from_each_place_summary_json_may_hold_them(self):
        for summary in ({"published": {"tip": {"lefm_initiation_time": 4e-6}}},
                        {"published": {"lefm": {"tip": {"initiation_time": 4e-6}}}},
                        {"lefm": {"tip": {"initiation_time": 4e-6}}}):
            published, lefm = report_numbers.references(summary, "tip")
            self.assertEqual(lefm, {"initiation_time": 4e-6}, summary)
            self.assertNotIn("lefm_initiation_time", published)
        self.assertEqual(report_numbers.relative_difference(66.0, 65.7), "+0.46 %")
        self.assertEqual(report_numbers.relative_difference([2.0, 3.0], [1.0, 4.0]),
                         "(+100.00 %, -25.00 %)")
        self.assertEqual(report_numbers.relative_difference([3.0, 4.0], [0.0, 5.0], True),
                         "63.25 % (distance)")
        self.assertEqual(report_numbers.relative_difference(1.0, 0.0), "—")
        self.assertEqual(report_numbers.relative_difference(None, 1.0), "—")

    def test_refinement_settings_and_event_summary(self):
        lines = section(self.report, "Refinement")
        rows = table_rows(lines)
        self.assertEqual(rows["trigger"][1], "damage 0.05, energy 0.5, stretch 0.7")
        for key, value in (("buffer", "1"), ("max_level", "1"), ("check_every", "10"),
                           ("mapping", "linear")):
            self.assertEqual(rows[key][1], value, key)
        events = support.csv_rows(os.path.join(RUN, "refinement.csv"))
        self.assertEqual(len(events), self.summary["refinement_events"])
        self.assertEqual(rows["events"][1], str(len(events)))

        def total(key):
            return sum(float(e[key]) for e in events)
        self.assertEqual(rows["parents split"][1], four(total("parents")))
        self.assertEqual(rows["children created"][1], four(total("children")))
        self.assertEqual(rows["first, last event"][1],
                         f"{four(float(events[0]['time']) * 1e6)}, "
                         f"{four(float(events[-1]['time']) * 1e6)} µs")
        self.assertEqual(rows["particles before the first, after the last event"][1],
                         f"{self.summary['particles_start']} → {self.summary['particles_end']}")
        self.assertEqual(rows["energy the mappings added"][1], f"{four(total('mapping_energy'))} J")
        self.assertEqual(rows["new bonds started broken"][1], four(total("started_broken")))
        self.assertIn("![refinement levels](plots/levels.png)", lines)
        self.assertTrue(os.path.isfile(os.path.join(RUN, "plots", "levels.png")))

    def test_provenance_from_summary_json(self):
        rows = table_rows(section(self.report, "Provenance"))
        s = self.summary
        self.assertTrue(s["version"] and s["commit"] and s["command_line"])
        self.assertEqual(rows["dhpd version"][1], s["version"])
        self.assertEqual(rows["commit"][1], s["commit"])
        self.assertEqual(rows["command line"][1], f"`{s['command_line']}`")
        self.assertIn("small_notched.yaml", s["command_line"])
        self.assertEqual(rows["threads"][1], str(s["threads"]))
        self.assertEqual(rows["peak memory (MiB)"][1], four(s["peak_memory_mb"]))
        lines = run_report.provenance_section({"threads": 2, "warnings": ["a crack cuts no bond"]})
        rows = table_rows(lines)
        for label in ("dhpd version", "commit", "command line", "peak memory (MiB)"):
            self.assertEqual(rows[label][1], "not recorded", label)
        self.assertIn("- a crack cuts no bond", lines)

    def test_run_table_pictures_and_scene_header(self):
        rows = table_rows(self.report.split("## Provenance")[0].splitlines())
        s = self.summary
        self.assertEqual(rows["status"][1], "completed")
        self.assertEqual(rows["particles"][1], f"{s['particles_start']} → {s['particles_end']}")
        self.assertEqual(rows["steps"][1], str(s["steps"]))
        self.assertEqual(rows["refinement events"][1], str(s["refinement_events"]))
        self.assertEqual(rows["frames"][1], str(len(support.pvd_frames(RUN))))
        self.assertEqual(rows["end time"][1], f"{four(s['end_time'] * 1e6)} µs")
        self.assertNotIn("did not complete", self.report)
        pictures = sorted(os.listdir(os.path.join(RUN, "plots")))
        self.assertIn("levels.png", pictures)
        for name in pictures:
            self.assertIn(f"![{name[:-4]}](plots/{name})", self.report)
        self.assertIn("Lengths in mm, times in µs.", self.report)
        self.assertIn("> A small notched glass plate for the Python tooling's tests", self.report)


class IncompleteFolders(unittest.TestCase):
    def check_report_of_an_unfinished_run(self, folder, rows, frames):
        """plot and report exit 0; both say what is missing and what they are made from."""
        state = (f"no summary.json: the run did not finish; report from history.csv ({rows} "
                 f"rows) and {frames} frames")
        plot = support.dhpd("plot", folder)
        self.assertIn(f"note: {state}", plot.stdout)
        self.assertTrue(os.path.isfile(os.path.join(folder, "plots", "damage_0.png")))
        self.assertTrue(os.path.isfile(os.path.join(folder, "plots", "energies.png")))
        support.dhpd("report", folder)
        report = support.read(os.path.join(folder, "report.md"))
        self.assertIn(f"> **This run did not complete or its folder is incomplete.** {state}.",
                      report)
        run_rows = table_rows(report.split("## Provenance")[0].splitlines())
        self.assertEqual(run_rows["status"][1], "not recorded (no summary.json)")
        self.assertEqual(run_rows["frames"][1], str(frames))
        provenance = table_rows(section(report, "Provenance"))
        for label in ("dhpd version", "commit", "command line", "threads", "peak memory (MiB)"):
            self.assertEqual(provenance[label][1], "not recorded", label)
        self.assertIn("From cracks.csv (no summary.json: the run did not finish).", report)
        self.assertIn(f"- {state}", report)  # the notes under the pictures
        # The measured numbers come from cracks.csv (the first measurement away from the notch)
        # with the references of the resolved scene beside them.
        cracks = support.csv_rows(os.path.join(folder, "cracks.csv"))
        moved = next(c for c in cracks if c["distance"] and float(c["distance"]) > 0)
        t_init = float(moved["time"]) * 1e6
        measured = section(report, "Measured numbers")
        self.assertIn("Published and LEFM values from scene.resolved.yaml (`measure.published`).",
                      measured)
        self.assertNotIn("No published numbers: the scene has no `measure.published`.", measured)
        self.assertEqual(table_rows(measured)["initiation time (µs)"],
                         ["initiation time (µs)", four(t_init), "5", percent(t_init, 5.0), "4",
                          percent(t_init, 4.0)])
        return plot.stdout, report

    def test_summary_gone_a_history_row_cut_and_a_frame_missing(self):
        folder = WORK("incomplete")
        shutil.copytree(RUN, folder)
        shutil.rmtree(os.path.join(folder, "plots"))
        os.remove(os.path.join(folder, "report.md"))
        os.remove(os.path.join(folder, "summary.json"))
        history = os.path.join(folder, "history.csv")
        text = support.read(history)
        support.write(history, text + text.splitlines()[-1][:12])  # a row cut by the kill
        frames = support.pvd_frames(folder)
        os.remove(os.path.join(folder, frames[5][1]))
        rows = complete_history_rows(history)
        self.assertEqual(rows, len(text.splitlines()) - 1)
        out, report = self.check_report_of_an_unfinished_run(folder, rows, len(frames) - 1)
        for note in ("history.csv: 1 incomplete row(s) left out",
                     "1 frame(s) listed in small_notched.pvd are missing: left out"):
            self.assertIn(note, out)
            self.assertIn(note, report)
        self.assertIn("## Refinement", report)

    def test_a_run_killed_with_sigkill(self):
        folder = WORK("killed")
        scene = support.small_scene(WORK.path)
        proc = subprocess.Popen([support.BIN, "run", scene, "-o", folder, "-q", "--set",
                                 "time.end=2e-3", "--set", "output.frames=2000"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            deadline = time.monotonic() + 120
            while time.monotonic() < deadline and proc.poll() is None:
                pvd = os.path.join(folder, "small_notched.pvd")
                if os.path.isfile(pvd) and len(support.pvd_frames(folder)) >= 25:
                    break
                time.sleep(0.02)
            self.assertIsNone(proc.poll(), "the run ended before it could be killed")
        finally:
            if proc.poll() is None:
                proc.send_signal(signal.SIGKILL)
            proc.wait()
        self.assertEqual(proc.returncode, -signal.SIGKILL)
        self.assertFalse(os.path.exists(os.path.join(folder, "summary.json")))
        frames = [f for f in support.pvd_frames(folder)
                  if os.path.isfile(os.path.join(folder, f[1]))]
        rows = complete_history_rows(os.path.join(folder, "history.csv"))
        self.assertGreater(rows, 0)
        # Killed after 25 frames (25 µs): the crack had started (cracks.csv dates it).
        self.check_report_of_an_unfinished_run(folder, rows, len(frames))


if __name__ == "__main__":
    support.main()
