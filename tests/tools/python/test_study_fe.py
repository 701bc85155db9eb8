#!/usr/bin/python3
"""`dhpd study` against a finite-element reference (tools/python/study_fe.py; the horizon-size
study of issue 18), on the vibrating plate at Δx = 0.05 m (440 particles, a fraction of a second
a run; the plate in tension at its own 0.01 m, 2 s): each run's fe_ux / fe_uy are fe_compare.py's errors of its own folder and fe_u the larger;
study.md names the run with the smallest fe_u of each variant next to the `published` text; a
static run that does not converge is a row that says so (no errors, the study goes on); a
malformed fe_reference is refused with exit 2."""
import os
import subprocess
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import support  # noqa: E402

support.import_tools()
import fe_compare  # noqa: E402
import study as study_tool  # noqa: E402

DATA = os.path.join(support.SOURCE, "tests", "data", "fe")
VIBRATION = """\
name: coarse_vibration
case: {case}
reference: {{label: OSB 3dx, set: {{body.0.spacing: 0.05, body.1.spacing: 0.05}}}}
variants:
  - {{label: OSB, set: {{body.0.spacing: 0.05, body.1.spacing: 0.05}},
     grid: {{horizon.factor: [2, 3, 4]}}}}
  - {{label: NOSB, set: {{body.0.spacing: 0.05, body.1.spacing: 0.05,
                        model.family: correspondence}}, grid: {{horizon.factor: [1, 2]}}}}
fe_reference: {{file: {reference}, kind: probe, probe: P}}
error: fe_u
published: the paper's words
"""
TENSION = """\
name: coarse_tension
case: {case}
reference: {{label: converged}}
variants:
  - {{label: cut short, set: {{solver.max_iterations: 5}}}}
fe_reference: {{file: {reference}, kind: field}}
error: fe_u
"""
WORK = None


def setUpModule():
    global WORK
    support.require_binary()
    WORK = support.Workdir("study_fe")


def tearDownModule():
    if WORK:
        WORK.cleanup()


def study(text, name, **values):
    path = support.write(WORK(f"{name}.yaml"), text.format(**values))
    return subprocess.run([support.PYTHON, os.path.join(support.TOOLS, "study.py"), path,
                           "--dhpd", support.BIN, "--out", WORK(name)], capture_output=True,
                          text=True, timeout=600)


class AgainstFiniteElements(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.proc = study(VIBRATION, "vibration",
                         case=os.path.join(support.SOURCE, "cases", "plate_vibration.yaml"),
                         reference=os.path.join(DATA, "plate_vibration.csv"))
        cls.rows = support.csv_rows(WORK("vibration", "study.csv"))
        cls.md = support.read(WORK("vibration", "study.md"))

    def test_the_study_completes(self):
        self.assertEqual(self.proc.returncode, 0, self.proc.stdout + self.proc.stderr)
        self.assertEqual(len(self.rows), 6)

    def test_each_run_s_errors_are_its_own_folder_s(self):
        folders = ["run-reference"] + [f"run-{k:02d}" for k in range(5)]
        for row, folder in zip(self.rows, folders):
            own = fe_compare.probe_errors(WORK("vibration", folder),
                                          os.path.join(DATA, "plate_vibration.csv"), "P")
            self.assertAlmostEqual(float(row["fe_ux"]), own["ux"], places=12, msg=row["label"])
            self.assertAlmostEqual(float(row["fe_uy"]), own["uy"], places=12, msg=row["label"])
            self.assertEqual(float(row["fe_u"]), max(own["ux"], own["uy"]), row["label"])
            self.assertGreater(own["ux"], 0.0)

    def test_study_md_names_the_best_of_each_variant_and_the_published_text(self):
        for variant in ("OSB", "NOSB"):
            runs = [r for r in self.rows if r["label"].startswith(variant + " (")]
            best = min(runs, key=lambda r: float(r["fe_u"]))
            self.assertIn(f"- {variant}: **{best['label']}**", self.md)
        self.assertIn("Published: the paper's words", self.md)
        self.assertIn("| fe_u | fe_ux | fe_uy |", self.md)
        self.assertNotIn("| angle_deg |", self.md)  # metrics no run measured are left out


class AStaticRunThatStops(unittest.TestCase):
    def test_is_a_row_that_says_so_and_the_study_goes_on(self):
        proc = study(TENSION, "tension",
                     case=os.path.join(support.SOURCE, "cases", "plate_tension.yaml"),
                     reference=os.path.join(DATA, "plate_tension.csv"))
        self.assertEqual(proc.returncode, 0, proc.stdout + proc.stderr)
        self.assertIn("did not converge", proc.stdout)
        rows = support.csv_rows(WORK("tension", "study.csv"))
        self.assertGreater(float(rows[0]["fe_u"]), 0.0)
        self.assertEqual(rows[1]["fe_u"], "")
        md = support.read(WORK("tension", "study.md"))
        self.assertIn("| cut short | – | – | – | did not complete (unstable) |", md)
        self.assertIn("- cut short: no run completed; 1 of 1 runs did not complete", md)


class ShippedStudies(unittest.TestCase):
    def test_the_horizon_size_studies_are_valid_and_name_their_reference(self):
        folder = os.path.join(support.SOURCE, "cases", "studies", "horizon_size")
        for name in ("plate_vibration.yaml", "plate_tension.yaml"):
            loaded = study_tool.load_study(os.path.join(folder, name))  # exits 2 when not
            self.assertEqual(loaded["error"], "fe_u")
            self.assertTrue(os.path.isfile(os.path.join(folder, loaded["fe_reference"]["file"])))
            grids = [v["grid"]["horizon.factor"] for v in loaded["variants"]]
            self.assertEqual(grids, [[1, 2, 3, 4, 5]] * 4)

    def test_the_multi_horizon_bar_studies_are_valid(self):
        folder = os.path.join(support.SOURCE, "cases", "studies")
        loaded = study_tool.load_study(os.path.join(folder, "multi_horizon_bar.yaml"))
        models = [v.get("set", {}).get("model", "dual-horizon") for v in loaded["variants"]]
        self.assertEqual(models[:3], ["dual-horizon", "multi-horizon", "classical-variable"])
        loaded = study_tool.load_study(os.path.join(folder, "multi_horizon_bar_state.yaml"))
        horizons = [v["set"]["model"]["horizon"] for v in loaded["variants"]]
        self.assertEqual(horizons[:3], ["dual-horizon", "multi-horizon", "classical-variable"])
        self.assertTrue(all(v["set"]["model"]["family"] == "ordinary-state"
                            for v in loaded["variants"]))


class MalformedReference(unittest.TestCase):
    def test_is_refused_with_exit_two(self):
        case = os.path.join(support.SOURCE, "cases", "plate_vibration.yaml")
        for reference, expected in (("no_such.csv", "fe_reference.file: cannot read"),):
            proc = study(VIBRATION, "bad", case=case, reference=reference)
            self.assertEqual(proc.returncode, 2, proc.stderr)
            self.assertIn(expected, proc.stderr)
        text = VIBRATION.replace("kind: probe", "kind: curve")
        proc = study(text, "bad_kind", case=case, reference=os.path.join(DATA, "x.csv"))
        self.assertEqual(proc.returncode, 2, proc.stderr)
        self.assertIn("fe_reference.kind must be one of ['probe', 'field'], not 'curve'",
                      proc.stderr)


if __name__ == "__main__":
    support.main()
