#!/usr/bin/python3
"""Crack branches (tools/python/crack_branches.py, crack_path.py) on damage built by hand: a
Y-shaped crack from one notch tip (a 20 mm stem, two 20 mm arms at ±35°) and a straight crack
from a second tip. The tracer must find all three branches of the Y and its branch point, one
branch of the straight crack, date each branch by the frames in which its damage appears, and
the report and crack_path.png must show them (in mm and µs)."""
import json
import os
import re
import sys
import unittest
import warnings

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import support  # noqa: E402

support.import_tools()
import numpy as np  # noqa: E402

import crack_branches  # noqa: E402
import crack_path  # noqa: E402
from run_data import load_run  # noqa: E402

H = 1e-3  # lattice spacing, m
HORIZON = 3.015 * H
NOTCH, BRANCH = np.array([0.02, 0.02]), np.array([0.04, 0.02])
ARM, ANGLE = 0.02, np.radians(35.0)
ARM_UP = BRANCH + ARM * np.array([np.cos(ANGLE), np.sin(ANGLE)])
ARM_DOWN = BRANCH + ARM * np.array([np.cos(ANGLE), -np.sin(ANGLE)])
UPPER, UPPER_END = np.array([0.02, 0.035]), np.array([0.035, 0.035])
T1, T2, T3 = 1e-5, 2e-5, 3e-5
TIPS = [{"name": "notch", "at": [0.02, 0.02]}, {"name": "upper", "at": [0.02, 0.035]}]


def lattice():
    """The particles of an 80 mm x 40 mm plate at 1 mm (cell centres), x-y in m."""
    xs, ys = np.arange(0.5 * H, 0.08, H), np.arange(0.5 * H, 0.04, H)
    x, y = np.meshgrid(xs, ys)
    return np.column_stack([x.ravel(), y.ravel()])


def near_segment(points, a, b, width=0.8 * H):
    ab = b - a
    t = np.clip(((points - a) @ ab) / (ab @ ab), 0.0, 1.0)
    return np.linalg.norm(points - (a + t[:, None] * ab), axis=1) <= width


POINTS = lattice()
STEM = near_segment(POINTS, NOTCH, BRANCH)
UP = near_segment(POINTS, BRANCH, ARM_UP) & ~STEM
DOWN = near_segment(POINTS, BRANCH, ARM_DOWN) & ~STEM
STRAIGHT = near_segment(POINTS, UPPER, UPPER_END)


def damaged(mask):
    """(x-y points, spacing, horizon) of the particles in `mask`."""
    n = int(mask.sum())
    return POINTS[mask], np.full(n, H), np.full(n, HORIZON)


def traced_y():
    points, spacing, horizon = damaged(STEM | UP | DOWN | STRAIGHT)
    return crack_branches.trace(points, spacing, horizon, TIPS[0], 2.0)


class Tracer(unittest.TestCase):
    def test_y_crack_has_three_branches_and_one_branch_point(self):
        crack = traced_y()
        lines, nodes = crack_branches.branches(crack)
        self.assertEqual(len(lines), 3)
        self.assertEqual(len(nodes), 1)
        stem, *arms = lines
        self.assertEqual(stem[0], -1)  # from the notch tip
        np.testing.assert_allclose(crack_branches.position(crack, -1), NOTCH)
        point = crack_branches.position(crack, nodes[0])
        # The branch point is where the arms part: past the geometric fork by less than the
        # two horizons within which groups are merged, on the symmetry line.
        self.assertAlmostEqual(point[1], 0.02, delta=0.2 * H)
        self.assertTrue(BRANCH[0] <= point[0] <= BRANCH[0] + 2 * HORIZON, point)
        self.assertEqual(stem[-1], nodes[0])
        self.assertEqual({arm[0] for arm in arms}, {nodes[0]})
        ends = sorted((crack_branches.position(crack, arm[-1]) for arm in arms),
                      key=lambda p: p[1])
        np.testing.assert_allclose(ends[0], ARM_DOWN, atol=HORIZON)
        np.testing.assert_allclose(ends[1], ARM_UP, atol=HORIZON)
        # Each arm keeps to its side of the stem's line.
        for arm, sign in zip(sorted(arms, key=lambda a: crack_branches.position(crack, a[-1])[1]),
                             (-1, 1)):
            ys = [crack_branches.position(crack, n)[1] - 0.02 for n in arm[1:]]
            self.assertTrue(all(sign * y > 0 for y in ys), ys)

    def test_a_separate_straight_crack_is_one_branch_of_its_own_tip(self):
        points, spacing, horizon = damaged(STEM | UP | DOWN | STRAIGHT)
        crack = crack_branches.trace(points, spacing, horizon, TIPS[1], 2.0)
        lines, nodes = crack_branches.branches(crack)
        self.assertEqual((len(lines), nodes), (1, []))
        centroids = np.array(crack.centroids)
        np.testing.assert_allclose(centroids[:, 1], 0.035, atol=0.1 * H)  # none of the Y
        np.testing.assert_allclose(crack_branches.position(crack, lines[0][-1]), UPPER_END,
                                   atol=HORIZON)

    def test_branch_times_are_when_the_damage_appeared(self):
        crack = traced_y()
        # The stem breaks by T1, the upper arm by T2, the lower arm by T3.
        frames = [(0.0,) + damaged(np.zeros(len(POINTS), bool))[:2],
                  (T1,) + damaged(STEM)[:2], (T2,) + damaged(STEM | UP)[:2],
                  (T3,) + damaged(STEM | UP | DOWN)[:2]]
        crack_branches.set_times(crack, frames)
        lines, nodes = crack_branches.branches(crack)
        stem, *arms = lines
        self.assertEqual(crack.times[stem[1]], T1)
        by_side = {np.sign(crack_branches.position(crack, arm[-1])[1] - 0.02): arm for arm in arms}
        self.assertEqual({crack.times[n] for n in by_side[1][2:]}, {T2})
        self.assertEqual({crack.times[n] for n in by_side[-1][2:]}, {T3})
        # A branch point's time: when its last branch appeared.
        self.assertEqual(crack_branches.branch_time(crack, nodes[0]), T3)

    def test_short_side_growths_are_not_branches(self):
        def chain(parents):
            crack = crack_branches.Crack("t", np.zeros(2))
            for k, parent in enumerate(parents):
                crack.parents.append(parent)
                crack.centroids.append(np.array([float(k), 0.0]))
                crack.bins.append(k)
                crack.times.append(np.nan)
            return crack
        # 0-1-2-3-4 with a one-node side growth 5 off node 1: one branch, no branch point.
        lines, nodes = crack_branches.branches(chain([-1, 0, 1, 2, 3, 1]))
        self.assertEqual((lines, nodes), ([[-1, 0, 1, 2, 3, 4]], []))
        # The side growth two nodes long (5-6) is a branch: node 1 is a branch point.
        lines, nodes = crack_branches.branches(chain([-1, 0, 1, 2, 3, 1, 5]))
        self.assertEqual(nodes, [1])
        self.assertEqual(sorted(lines), [[-1, 0, 1], [1, 2, 3, 4], [1, 5, 6]])

    def test_damage_another_tip_cracked_is_left_out_quietly(self):
        # The straight crack is not linked to the notch: its particles are never reached (an
        # infinite path distance), which must not make numpy warn on every plot of a two-tip run.
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            crack = traced_y()
        on_straight = near_segment(np.array(crack.centroids), UPPER, UPPER_END, 2 * H)
        self.assertFalse(on_straight.any())

    def test_no_damage_no_branches(self):
        crack = crack_branches.trace(np.zeros((0, 2)), np.zeros(0), np.zeros(0), TIPS[0])
        self.assertEqual(crack_branches.branches(crack), ([], []))
        # Damage far from the notch tip is not its crack.
        points, spacing, horizon = damaged(STRAIGHT)
        crack = crack_branches.trace(points, spacing, horizon, TIPS[0])
        self.assertEqual(crack.centroids, [])


def write_frame(path, time, step, mask):
    """A .vtu frame of the plate with damage 1 on `mask`, as dhpd writes them."""
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonCore import vtkDoubleArray, vtkPoints
    from vtkmodules.vtkCommonDataModel import VTK_VERTEX, vtkUnstructuredGrid
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridWriter

    n = len(POINTS)
    grid = vtkUnstructuredGrid()
    points = vtkPoints()
    points.SetData(numpy_to_vtk(np.column_stack([POINTS, np.zeros(n)]), deep=True))
    grid.SetPoints(points)
    grid.Allocate(n)
    for k in range(n):
        grid.InsertNextCell(VTK_VERTEX, 1, [k])
    fields = {"damage": mask.astype(float), "spacing": np.full(n, H),
              "horizon": np.full(n, HORIZON), "level": np.zeros(n, np.int32),
              "displacement": np.zeros((n, 3))}
    for name, values in fields.items():
        array = numpy_to_vtk(values, deep=True)
        array.SetName(name)
        grid.GetPointData().AddArray(array)
    for name, value in (("TimeValue", time), ("Step", float(step))):
        array = vtkDoubleArray()
        array.SetName(name)
        array.InsertNextValue(value)
        grid.GetFieldData().AddArray(array)
    writer = vtkXMLUnstructuredGridWriter()
    writer.SetFileName(path)
    writer.SetInputData(grid)
    writer.Write()


def fake_run(directory):
    """A run folder written by hand: frames at 0, T1, T2, T3, the scene, history, cracks."""
    os.makedirs(directory)
    masks = [np.zeros(len(POINTS), bool), STEM | near_segment(POINTS, UPPER, (UPPER + UPPER_END)
                                                              / 2),
             STEM | UP | STRAIGHT, STEM | UP | DOWN | STRAIGHT]
    entries = []
    for k, (t, mask) in enumerate(zip((0.0, T1, T2, T3), masks)):
        name = f"synthetic_{k:06d}.vtu"
        write_frame(os.path.join(directory, name), t, 100 * k, mask)
        entries.append(f'    <DataSet timestep="{t!r}" group="" part="0" file="{name}"/>')
    support.write(os.path.join(directory, "synthetic.pvd"),
                  '<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n'
                  "  <Collection>\n" + "\n".join(entries) + "\n  </Collection>\n</VTKFile>\n")
    support.write(os.path.join(directory, "scene.resolved.yaml"), json.dumps({
        "name": "synthetic", "dimension": 2,
        "body": [{"shape": "box", "min": [0, 0], "max": [0.08, 0.04], "spacing": H}],
        "measure": {"damage_threshold": 0.35, "branch_separation": 2, "tips": [
            {"name": "notch", "at": [0.02, 0.02], "direction": [1, 0]},
            {"name": "upper", "at": [0.02, 0.035], "direction": [1, 0]}]}}) + "\n")
    history = ["step,time,dt,particles,bonds,broken_bonds,kinetic_energy,strain_energy,"
               "external_work,momentum_x,momentum_y,momentum_z"]
    history += [f"{100 * k},{t!r},1e-7,{len(POINTS)},10000,{int(m.sum())},0,0,0,0,0,0"
                for k, (t, m) in enumerate(zip((0.0, T1, T2, T3), masks))]
    support.write(os.path.join(directory, "history.csv"), "\n".join(history) + "\n")
    cracks = ["step,time,tip,x,y,z,distance,path_length,speed,angle_deg,branches"]
    for k, (t, x, branches) in enumerate(((0.0, 0.02, 0), (T1, 0.04, 1), (T2, 0.05, 2),
                                          (T3, 0.056, 2))):
        cracks.append(f"{100 * k},{t!r},notch,{x},0.02,0,{x - 0.02},{x - 0.02},1000,0,{branches}")
        cracks.append(f"{100 * k},{t!r},upper,{min(x, 0.035)},0.035,0,0,0,500,0,{min(branches, 1)}")
    support.write(os.path.join(directory, "cracks.csv"), "\n".join(cracks) + "\n")
    support.write(os.path.join(directory, "summary.json"),
                  json.dumps({"scene": "synthetic", "status": "completed"}) + "\n")
    return directory


def mm_pair(text):
    x, y = re.fullmatch(r"\(([-\d.]+), ([-\d.]+)\)", text.strip()).groups()
    return np.array([float(x), float(y)])


class FromARunFolder(unittest.TestCase):
    """The same cracks as frames of a run folder: crack_path and `dhpd report`."""

    @classmethod
    def setUpClass(cls):
        support.require_binary()
        cls.work = support.Workdir("branches")
        cls.dir = fake_run(cls.work("synthetic"))

    @classmethod
    def tearDownClass(cls):
        cls.work.cleanup()

    def test_report_lists_every_branch_and_branch_point_in_mm_and_us(self):
        proc = support.dhpd("report", self.dir)
        self.assertNotIn("Warning", proc.stderr)
        report = support.read(os.path.join(self.dir, "report.md"))
        section = report.split("## Crack branches")[1].split("\n## ")[0]
        rows = [[c.strip() for c in line.strip("|").split("|")] for line in section.splitlines()
                if line.startswith("| notch") or line.startswith("| upper")]
        branches = [r for r in rows if len(r) == 5]
        points = [r for r in rows if len(r) == 3]
        self.assertEqual([(r[0], r[1]) for r in branches],
                         [("notch", "1"), ("notch", "2"), ("notch", "3"), ("upper", "1")])
        notch = branches[:3]
        np.testing.assert_allclose(mm_pair(notch[0][2]), NOTCH * 1e3)
        self.assertEqual(notch[0][4], "10 – 20")  # the stem: damaged from T1, its end by T2
        ends = sorted((mm_pair(r[3]) for r in notch[1:]), key=lambda p: p[1])
        np.testing.assert_allclose(ends[0], ARM_DOWN * 1e3, atol=HORIZON * 1e3)
        np.testing.assert_allclose(ends[1], ARM_UP * 1e3, atol=HORIZON * 1e3)
        self.assertEqual(sorted(r[4] for r in notch[1:]), ["20 – 20", "30 – 30"])
        self.assertEqual(len(points), 1)
        tip, where, time = points[0]
        self.assertEqual((tip, time), ("notch", "30"))
        self.assertAlmostEqual(mm_pair(where)[1], 20.0, delta=0.2)
        self.assertTrue(40.0 <= mm_pair(where)[0] <= 40.0 + 2 * HORIZON * 1e3, where)
        upper = branches[3]
        np.testing.assert_allclose(mm_pair(upper[2]), UPPER * 1e3)
        np.testing.assert_allclose(mm_pair(upper[3]), UPPER_END * 1e3, atol=HORIZON * 1e3)
        self.assertEqual(upper[4], "10 – 20")
        self.assertTrue(os.path.isfile(os.path.join(self.dir, "plots", "crack_path.png")))

    def test_crack_path_png_marks_branches_branch_points_and_measured_branchings(self):
        run = load_run(self.dir)
        with support.captured_figures() as figures:
            cracks = crack_path.plot_crack_path(run, self.work("crack_path.png"))
            ax = figures[0].axes[0]
            labels = [line.get_label() for line in ax.lines]
            self.assertEqual(sum(" branch " in label for label in labels), 4)
            self.assertEqual([line.get_marker() for line in ax.lines].count("D"), 1)
            diamond = next(line for line in ax.lines if line.get_marker() == "D")
            self.assertAlmostEqual(float(diamond.get_ydata()[0]), 20.0, delta=0.2)
            notes = [t.get_text() for t in ax.texts]
            self.assertIn("30 µs", notes)  # the branch point's time
            self.assertIn("20 µs → 2", notes)  # cracks.csv's branch count rose to 2 at T2
            self.assertEqual((ax.get_xlabel(), ax.get_ylabel()), ("x (mm)", "y (mm)"))
        self.assertEqual([c.tip for c in cracks], ["notch", "upper"])


if __name__ == "__main__":
    support.main()
