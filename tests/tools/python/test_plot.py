#!/usr/bin/python3
"""`dhpd plot` (tools/python/plot_run.py, run_frames.py, run_overlay.py, run_sheets.py,
crack_path.py) on a short adaptive run of the notched test plate: the pictures it writes, the scene
drawn over the damage frames (pre-crack, notch tip, pulled and held edges, in mm), the level map
and the contact sheet, lengths in mm and times in µs on every axis, and `--times` outside the
frames' span; and a static run's reactions and sectional force against the load factor."""
import os
import re
import shutil
import subprocess
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import support  # noqa: E402

support.import_tools()
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import crack_path  # noqa: E402
import plot_run  # noqa: E402
import run_folder  # noqa: E402
import run_frames  # noqa: E402
import run_overlay  # noqa: E402
import run_sheets  # noqa: E402
from run_data import load_run  # noqa: E402

WORK = RUN = PLOT = None
MAGENTA = (1.0, 0.0, 1.0)
TAB_BLUE, TAB_ORANGE = (0.12, 0.467, 0.706), (1.0, 0.498, 0.055)


def setUpModule():
    global WORK, RUN, PLOT
    support.require_binary()
    WORK = support.Workdir("plot")
    RUN = support.run_small(WORK.path)
    PLOT = support.dhpd("plot", RUN)


def tearDownModule():
    if WORK:
        WORK.cleanup()


def box_of(xy):
    """((x0, y0), (x1, y1)) of a polygon's vertices, rounded to µm (in the units given)."""
    xy = np.asarray(xy)
    return (tuple(np.round(xy.min(axis=0), 3)), tuple(np.round(xy.max(axis=0), 3)))


def labelled(ax):
    """{legend label: artist} of an axes' lines and patches."""
    artists = list(ax.lines) + list(ax.patches)
    return {a.get_label(): a for a in artists if a.get_label() and not a.get_label().startswith("_")}


class PlotCommand(unittest.TestCase):
    def test_writes_the_default_pictures_of_an_adaptive_crack_run(self):
        frames = support.pvd_frames(RUN)
        out = PLOT.stdout
        for name in ("damage_0", "damage_1", "damage_2", "damage_3", "contact_sheet", "levels",
                     "energies", "momentum", "particles_dt", "tip_speed", "crack_path"):
            path = os.path.join(RUN, "plots", f"{name}.png")
            with open(path, "rb") as f:
                self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n", path)
            self.assertIn(f"wrote {path}", out)
        self.assertFalse(os.path.exists(os.path.join(RUN, "plots", "damage_4.png")))
        # 4 frames spread over the .pvd: the first and the last among them.
        self.assertRegex(out, rf"damage_0\.png: {frames[0][1]}, t = 0 µs")
        self.assertRegex(out, rf"damage_3\.png: {frames[-1][1]}, t = {frames[-1][0] * 1e6:.4g} µs")
        self.assertIn(f"contact_sheet.png: {min(12, len(frames))} damage frames", out)
        self.assertIn("levels.png: refinement levels 0 to 1 of the last frame", out)

    def test_damage_frames_show_the_pre_crack_and_regions(self):
        # The t = 0 frame has no damage: the magenta there is the pre-crack and notch tip.
        drawn = support.colour_pixels(support.png(os.path.join(RUN, "plots", "damage_0.png")),
                                      MAGENTA)
        self.assertGreater(drawn, 100)
        # The same frame drawn without the scene has none, and differs.
        run = load_run(RUN)
        frame = run_frames.read_frame(run.frames[0][1], "damage")
        bare, with_scene = WORK("bare.png"), WORK("with_scene.png")
        run_frames.save_field_png(frame, bare, run.name, None)
        with support.captured_figures() as figures:
            run_frames.save_field_png(frame, with_scene, run.name, run.scene)
        self.assertEqual(support.colour_pixels(support.png(bare), MAGENTA), 0)
        self.assertGreater(support.colour_pixels(support.png(with_scene), MAGENTA), 100)
        legend = figures[0].axes[0].get_legend()
        self.assertIsNotNone(legend)
        self.assertEqual({t.get_text() for t in legend.get_texts()},
                         {"body outline, holes and notches (dashed)", "traction [0, 20] MPa",
                          "fixed", "pre-crack", "notch tip (measure)"})


class Overlay(unittest.TestCase):
    """run_overlay.draw_scene on the run's resolved scene: everything at its place in mm."""

    def draw(self, scene, bounds=((0.0, 0.04), (0.0, 0.02)), z=0.0):
        fig, ax = plt.subplots()
        self.addCleanup(plt.close, fig)
        return run_overlay.draw_scene(ax, scene, bounds, z), ax

    def test_pre_crack_notch_tip_and_regions_of_the_run_in_mm(self):
        scene, _ = run_folder.load_scene(RUN)
        count, ax = self.draw(scene)
        self.assertEqual(count, 4)  # body, traction, fixed, one pre-crack
        items = labelled(ax)
        crack = items["pre-crack"]
        self.assertEqual(crack.get_color(), "magenta")
        np.testing.assert_allclose(np.column_stack(crack.get_data()), support.PRE_CRACK_MM,
                                   atol=1e-9)
        tip = items["notch tip (measure)"]
        self.assertEqual(tip.get_marker(), "x")
        np.testing.assert_allclose(np.ravel(tip.get_data()), support.NOTCH_TIP_MM, atol=1e-9)
        traction, fixed = items["traction [0, 20] MPa"], items["fixed"]
        self.assertEqual(box_of(traction.get_xy()), support.TRACTION_BOX_MM)
        self.assertEqual(box_of(fixed.get_xy()), support.FIXED_BOX_MM)
        self.assertTrue(traction.get_fill() and fixed.get_fill())
        np.testing.assert_allclose(traction.get_facecolor()[:3], plt.matplotlib.colors.to_rgb(
            "tab:red"))
        np.testing.assert_allclose(fixed.get_facecolor()[:3], plt.matplotlib.colors.to_rgb(
            "tab:blue"))
        body = items["body outline, holes and notches (dashed)"]
        self.assertFalse(body.get_fill())
        self.assertEqual(box_of(body.get_xy()), support.BODY_BOX_MM)

    def test_holes_half_spaces_3d_cracks_and_other_conditions(self):
        scene = {"dimension": 3,
                 "body": [{"shape": "difference", "of": [
                     {"shape": "box", "min": [0, 0, 0], "max": [0.04, 0.02, 0.002]},
                     {"shape": "disk", "center": [0.03, 0.01], "radius": 0.004}]}],
                 "cracks": [[[0.01, 0.005, 0], [0.02, 0.005, 0], [0.02, 0.005, 0.002],
                             [0.01, 0.005, 0.002]]],
                 "boundary_conditions": [
                     {"region": {"shape": "half-space", "point": [0.035, 0, 0],
                                 "normal": [-1, 0, 0]}, "velocity": {"x": 1.5}},
                     {"region": {"shape": "random-disks", "min": [0, 0], "max": [0.005, 0.005]},
                      "fixed": True}],
                 "initial_conditions": [{"region": {"shape": "box", "min": [0, 0.015, 0],
                                                    "max": [0.01, 0.02, 0.002]},
                                         "velocity": [0, 2, 0]}]}
        count, ax = self.draw(scene, z=0.001)
        items = labelled(ax)
        hole = next(p for p in ax.patches if p.get_linestyle() == "--")
        (x0, y0), (x1, y1) = box_of(hole.get_xy())
        centre = np.array([(x0 + x1) / 2, (y0 + y1) / 2])
        np.testing.assert_allclose(centre, (30.0, 10.0), atol=1e-3)
        np.testing.assert_allclose(np.linalg.norm(hole.get_xy() - centre, axis=1), 4.0,
                                   atol=0.05)
        # The half-space x >= 35 mm cut to the picture (0..40 mm).
        self.assertEqual(box_of(items["velocity x = 1.5 m/s"].get_xy()),
                         ((35.0, 0.0), (40.0, 20.0)))
        self.assertEqual(items["fixed"].get_linestyle(), ":")  # random disks: their box, dotted
        self.assertIn("initial velocity [0, 2, 0] m/s", items)
        projected = items["pre-crack (projected)"]
        x, y = projected.get_data()
        self.assertEqual((x[0], y[0]), (x[-1], y[-1]))  # a closed polygon
        self.assertEqual((min(x), max(x)), (10.0, 20.0))
        self.assertEqual(count, 6)  # box, hole, half-space, random disks, initial, crack

    def test_a_1d_scene_gets_no_overlay(self):
        count, ax = self.draw({"dimension": 1, "cracks": [[[0.01], [0.02]]]})
        self.assertEqual(count, 0)
        self.assertEqual(len(ax.lines) + len(ax.patches), 0)


class Axes(unittest.TestCase):
    """Lengths in mm and times in µs, checked on the figures the tools draw."""

    @classmethod
    def setUpClass(cls):
        cls.folder = load_run(RUN)
        cls.summary = support.summary(RUN)

    def test_damage_frame_in_mm_with_its_time_in_us(self):
        time, path = self.folder.frames[-1]
        frame = run_frames.read_frame(path, "damage")
        with support.captured_figures() as figures:
            run_frames.save_field_png(frame, WORK("frame.png"), self.folder.name, self.folder.scene)
            ax = figures[0].axes[0]
            self.assertEqual((ax.get_xlabel(), ax.get_ylabel()), ("x (mm)", "y (mm)"))
            self.assertIn(f"t = {time * 1e6:.4g} µs", ax.get_title())
            x0, x1 = ax.get_xlim()
            y0, y1 = ax.get_ylim()
            self.assertTrue(-2.0 < x0 < 0.0 and 40.0 < x1 < 42.0, (x0, x1))
            self.assertTrue(-2.0 < y0 < 0.0 and 20.0 < y1 < 22.0, (y0, y1))
            offsets = ax.collections[0].get_offsets()
            self.assertAlmostEqual(float(offsets[:, 0].max()), 1e3 * frame.points[:, 0].max())
            self.assertEqual(ax.get_aspect(), 1.0)
            self.assertEqual(ax.collections[0].get_clim(), (0.0, 1.0))

    def test_history_plots_have_time_in_us(self):
        history = self.folder.history
        for draw in (plot_run.plot_energies, plot_run.plot_momentum, plot_run.plot_particles_dt):
            with support.captured_figures() as figures:
                draw(self.folder, WORK("history.png"))
                ax = figures[0].axes[0]
                self.assertEqual(ax.get_xlabel(), "time (µs)", draw.__name__)
                end = max(float(np.max(line.get_xdata())) for line in ax.lines)
                self.assertAlmostEqual(end, history["time"][-1] * 1e6, places=6)
                if draw is plot_run.plot_particles_dt:
                    right = figures[0].axes[1]
                    self.assertEqual(right.get_ylabel(), "dt (µs)")
                    np.testing.assert_allclose(right.lines[0].get_ydata(), history["dt"] * 1e6)
                    np.testing.assert_array_equal(ax.lines[0].get_ydata(), history["particles"])

    def test_tip_speed_in_us_with_the_rayleigh_speed(self):
        with support.captured_figures() as figures:
            plot_run.plot_tip_speed(self.folder, WORK("speed.png"))
            ax = figures[0].axes[0]
            self.assertEqual(ax.get_xlabel(), "time (µs)")
            tip = next(line for line in ax.lines if line.get_label() == "tip notch")
            self.assertAlmostEqual(float(tip.get_xdata()[-1]), self.folder.cracks["time"][-1] * 1e6)
            rayleigh = self.summary["rayleigh_speed"]
            line = next(line for line in ax.lines if line.get_label().startswith("Rayleigh"))
            self.assertAlmostEqual(float(line.get_ydata()[0]), rayleigh)
            self.assertIn(f"{rayleigh:.4g} m/s", line.get_label())

    def test_crack_path_in_mm_from_the_notch_tip(self):
        with support.captured_figures() as figures:
            cracks = crack_path.plot_crack_path(self.folder, WORK("path.png"))
            ax = figures[0].axes[0]
            self.assertEqual((ax.get_xlabel(), ax.get_ylabel()), ("x (mm)", "y (mm)"))
            branches = [line for line in ax.lines if " branch " in line.get_label()]
            self.assertGreaterEqual(len(branches), 1)
            first = np.column_stack(branches[0].get_data())
            np.testing.assert_allclose(first[0], support.NOTCH_TIP_MM)
            self.assertTrue(np.all((first >= -1.0) & (first <= [41.0, 21.0])), first)
            self.assertRegex(branches[0].get_label(), r"^notch branch 1: [\d.]+–[\d.]+ µs$")
            # The crack runs to the right: its far end is where cracks.csv puts the last tip.
            tip = (self.summary["cracks"][0]["tip"][0] * 1e3, self.summary["cracks"][0]["tip"][1]
                   * 1e3)
            ends = np.array([np.column_stack(b.get_data())[-1] for b in branches])
            self.assertLess(np.min(np.linalg.norm(ends - tip, axis=1)), 3 * 3.015)
        self.assertEqual([c.tip for c in cracks], ["notch"])


class Sheets(unittest.TestCase):
    """levels.png and contact_sheet.png."""

    @classmethod
    def setUpClass(cls):
        cls.folder = load_run(RUN)

    def test_level_map_counts_each_level_of_the_last_frame(self):
        arrays, _ = run_folder.read_vtu(self.folder.frames[-1][1])
        levels = arrays["level"].astype(int)
        n0, n1 = int(np.sum(levels == 0)), int(np.sum(levels == 1))
        self.assertGreater(n1, 0)
        self.assertEqual(n0 + n1, support.summary(RUN)["particles_end"])
        with support.captured_figures() as figures:
            top = run_sheets.save_level_png(self.folder, WORK("levels.png"))
            self.assertEqual(top, 1)
            ax = figures[0].axes[0]
            self.assertEqual((ax.get_xlabel(), ax.get_ylabel()), ("x (mm)", "y (mm)"))
            self.assertTrue(ax.get_title().endswith(
                f"level 0: {n0} particles (Δx 1 mm), level 1: {n1} particles (Δx 0.5 mm)"),
                ax.get_title())
            norm = ax.collections[0].norm
            np.testing.assert_allclose(norm.boundaries, [-0.5, 0.5, 1.5])  # a colour per level
            self.assertEqual(list(figures[0].axes[1].get_yticks()), [0.0, 1.0])
        picture = support.png(os.path.join(RUN, "plots", "levels.png"))
        self.assertGreater(support.colour_pixels(picture, TAB_BLUE), 1000)
        self.assertGreater(support.colour_pixels(picture, TAB_ORANGE), 1000)

    def test_only_runs_that_refined_get_a_level_map(self):
        self.assertTrue(plot_run.refined(self.folder))
        self.assertIn("levels.png", plot_run.default_pictures(self.folder))
        unrefined = load_run(RUN)
        unrefined.refinement = {"generation": np.array([1.0]), "children": np.array([0.0])}
        self.assertFalse(plot_run.refined(unrefined))
        self.assertNotIn("levels.png", plot_run.default_pictures(unrefined))

    def test_contact_sheet_shows_the_frames_spread_over_the_run(self):
        frames = self.folder.frames
        for count in (5, 12):
            with support.captured_figures() as figures:
                shown = run_sheets.save_contact_sheet(self.folder, WORK("sheet.png"), count=count)
                self.assertEqual(shown, min(count, len(frames)))
                fig = figures[0]
                panels = [ax for ax in fig.axes if ax.get_title().startswith("t = ")]
                self.assertEqual(len(panels), shown)
                expected = [frames[k][0] for k in run_frames.choose_frames(frames, None, count)]
                self.assertEqual(expected[0], frames[0][0])
                self.assertEqual(expected[-1], frames[-1][0])
                titles = [float(re.match(r"t = ([\d.e+-]+) µs", ax.get_title()).group(1))
                          for ax in panels]
                np.testing.assert_allclose(titles, np.array(expected) * 1e6, rtol=1e-3,
                                           atol=1e-9)
                for ax in panels:
                    self.assertEqual(ax.get_xlabel(), "x (mm)")
                    self.assertEqual(ax.collections[0].get_clim(), (0.0, 1.0))
                    self.assertTrue(any(line.get_color() == "magenta" for line in ax.lines))
                self.assertIn(f"damage, {shown} of {len(frames)} frames",
                              fig._suptitle.get_text())


class Times(unittest.TestCase):
    """`plot --times` outside the frames' span: a note, the nearest frame drawn, exit 0."""

    def test_times_past_the_end_draw_the_last_frame_with_a_note(self):
        copy = WORK("times")
        shutil.copytree(RUN, copy)
        frames = support.pvd_frames(copy)
        proc = support.dhpd("plot", copy, "--times", "1e-3,2e-3")
        self.assertIn(f"note: --times 0.001 s lies outside the frames (0 to {frames[-1][0]:.4g} "
                      "s): the nearest frame is drawn", proc.stdout)
        self.assertIn("note: --times 0.002 s lies outside", proc.stdout)
        # Both times are nearest the last frame: one picture, of it; the earlier four are gone.
        self.assertIn(f"damage_0.png: {frames[-1][1]}", proc.stdout)
        pictures = sorted(f for f in os.listdir(os.path.join(copy, "plots"))
                          if f.startswith("damage_"))
        self.assertEqual(pictures, ["damage_0.png"])

    def test_times_inside_the_span_get_no_note(self):
        frames = load_run(RUN).frames
        last = frames[-1][0]
        gap = last / (len(frames) - 1)
        self.assertEqual(run_frames.times_notes(frames, [0.0, 0.5 * last, last + 0.5 * gap]), [])
        self.assertEqual(len(run_frames.times_notes(frames, [-1e-3, last + 2 * gap])), 2)
        self.assertEqual(run_frames.choose_frames(frames, [1e-3, 2e-3]), [len(frames) - 1])
        self.assertEqual(run_frames.choose_frames(frames, [-1e-3]), [0])

    def test_times_that_are_not_numbers_are_refused(self):
        self.assertEqual(support.dhpd("plot", RUN, "--times", "abc", check=False).returncode, 2)
        script = os.path.join(support.TOOLS, "plot_run.py")
        proc = subprocess.run([support.PYTHON, script, "plot", RUN, "--times", "nan"],
                              capture_output=True, text=True)
        self.assertEqual(proc.returncode, 2)
        self.assertIn("expected finite times in s", proc.stderr)



class StaticForces(unittest.TestCase):
    """A static run's reactions and sectional force against the load factor (forces.png)."""

    def test_reactions_and_sections_are_drawn_against_the_load_factor(self):
        out = WORK("bar")
        support.dhpd("run", os.path.join(support.SOURCE, "cases", "bimaterial_bar.yaml"), "-o",
                     out, "-q", "--set", "time.steps=2")
        run = load_run(out)
        self.assertIn("forces.png", plot_run.default_pictures(run))
        with support.captured_figures() as figures:
            plot_run.plot_forces(run, WORK("forces.png"))
            ax = figures[0].axes[0]
            self.assertEqual(ax.get_xlabel(), "load factor")
            lines = labelled(ax)
            self.assertEqual(sorted(lines), ["S_Fx", "bc0_Rx", "bc1_Rx"])
            np.testing.assert_allclose(lines["S_Fx"].get_xdata(), [0.0, 0.5, 1.0])
            np.testing.assert_allclose(lines["S_Fx"].get_ydata(), run.history["S_Fx"])
            # The pull across the interface is the right support's, the left one's opposite.
            np.testing.assert_allclose(lines["S_Fx"].get_ydata(), lines["bc1_Rx"].get_ydata(),
                                       rtol=1e-5)
            np.testing.assert_allclose(lines["bc0_Rx"].get_ydata(), -lines["bc1_Rx"].get_ydata(),
                                       rtol=1e-5)

    def test_a_dynamic_run_without_reactions_gets_no_forces_picture(self):
        self.assertNotIn("forces.png", plot_run.default_pictures(load_run(RUN)))


if __name__ == "__main__":
    support.main()
