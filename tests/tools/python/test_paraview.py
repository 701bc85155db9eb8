#!/usr/bin/python3
"""The shipped ParaView script (tools/python/paraview_frames.py) on a short adaptive run of the
branching plate (cases/branching_plate_adaptive.yaml to 30 µs), headless through
pvbatch on an Xvfb server of its own: the damage and level pictures of the first and the last frame exist, are
pictures of the plate (not one colour), and the last frame shows the crack and the refined zone
the first does not. Skipped (exit 77) without pvbatch or Xvfb on the PATH, when pvbatch finds no ParaView Python
modules (docs/outputs.md: python3-paraview, installed or unpacked), or when three Xvfb servers in
a row can't be reached (a machine without a usable X socket: the script's own errors fail).

The server is started here with -displayfd, which reports its display number once it accepts
connections: `xvfb-run -a` picks the number from lock files and waits on a signal, which raced
on a loaded CI machine (pvbatch: "bad X server connection. DISPLAY=:99")."""
import os
import shutil
import subprocess
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import support  # noqa: E402

SCRIPT = os.path.join(support.TOOLS, "paraview_frames.py")
CASE = os.path.join(support.SOURCE, "cases", "branching_plate_adaptive.yaml")
LEVEL_1 = (1.0, 0.5, 0.05)  # the script's colour of refinement level 1
WORK = RUN = RENDER = None


def body(picture):
    """The part of a picture where the plate is: left of the colour bar, below the caption."""
    height, width, _ = picture.shape
    return picture[int(0.1 * height):, :int(0.8 * width)]


def damaged_pixels(picture):
    """Pixels coloured as damage of about 0.5 or more on the Viridis 0-1 scale (green to
    yellow: bright and saturated; the greys of the caption's edges aside)."""
    import numpy as np
    saturation = picture.max(axis=2) - picture.min(axis=2)
    return int(np.sum((picture[..., 1] > 0.45) & (saturation > 0.3)))


X_UNREACHABLE = "bad X server connection"


def render_headless():
    """pvbatch SCRIPT RUN on a fresh Xvfb server; the completed process of pvbatch (a server
    that does not start reads as an unreachable one)."""
    read_end, write_end = os.pipe()
    server = subprocess.Popen(["Xvfb", "-displayfd", str(write_end), "-screen", "0", "1280x1024x24",
                               "-nolisten", "tcp"], pass_fds=(write_end,),
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(write_end)
    try:
        with os.fdopen(read_end) as announced:
            display = announced.readline().strip()
        if not display.isdigit():
            return subprocess.CompletedProcess([], 1, "", f"{X_UNREACHABLE}: Xvfb did not start")
        env = dict(os.environ, DISPLAY=f":{display}")
        env.pop("XAUTHORITY", None)
        return subprocess.run(["pvbatch", SCRIPT, RUN], capture_output=True, text=True,
                              timeout=300, env=env)
    finally:
        server.terminate()
        try:
            server.wait(timeout=10)
        except subprocess.TimeoutExpired:
            server.kill()
            server.wait()


def setUpModule():
    global WORK, RUN, RENDER
    support.require_binary()
    WORK = support.Workdir("paraview")
    RUN = WORK("run")
    support.dhpd("run", CASE, "-o", RUN, "-q", "--set", "time.end=3e-5", "--set",
                 "output.frames=6")
    for _ in range(3):
        RENDER = render_headless()
        if X_UNREACHABLE not in RENDER.stderr:
            break
    else:
        WORK.cleanup()
        support.skip("three Xvfb servers in a row could not be reached: " + RENDER.stderr[-500:])
    if "ParaView's Python modules are missing" in RENDER.stderr:
        WORK.cleanup()
        support.skip("pvbatch finds no ParaView Python modules (python3-paraview): "
                     + RENDER.stderr.strip())


def tearDownModule():
    if WORK:
        WORK.cleanup()


class Render(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if RENDER.returncode != 0:
            raise AssertionError(f"paraview_frames.py exited {RENDER.returncode}:\n"
                                 f"{RENDER.stdout}\n{RENDER.stderr}")
        cls.frames = support.pvd_frames(RUN, "branching_plate_adaptive")
        cls.last = len(cls.frames) - 1
        cls.pictures = {}
        for kind in ("damage", "level"):
            for index in (0, cls.last):
                path = os.path.join(RUN, "paraview", f"{kind}_{index:06d}.png")
                cls.pictures[kind, index] = support.png(path) if os.path.isfile(path) else None

    def test_first_and_last_frame_pictures_are_written(self):
        self.assertEqual(sorted(os.listdir(os.path.join(RUN, "paraview"))),
                         sorted(f"{kind}_{index:06d}.png" for kind in ("damage", "level")
                                for index in (0, self.last)))
        for index in (0, self.last):
            self.assertIn(f"damage_{index:06d}.png: t = {self.frames[index][0] * 1e6:.4g} µs",
                          RENDER.stdout)

    def test_pictures_are_not_blank(self):
        import numpy as np
        for key, picture in self.pictures.items():
            self.assertIsNotNone(picture, key)
            self.assertEqual(picture.shape[1], 1600, key)  # --width default
            self.assertGreater(support.distinct_colours(picture), 20, key)
            plate = body(picture)
            not_white = np.any(plate < 0.9, axis=2).mean()
            self.assertGreater(not_white, 0.3, key)  # the plate fills most of the view

    def test_the_last_damage_frame_shows_the_crack_the_first_does_not(self):
        import numpy as np
        first, last = self.pictures["damage", 0], self.pictures["damage", self.last]
        self.assertEqual(damaged_pixels(body(first)), 0)
        self.assertGreater(damaged_pixels(body(last)), 500)
        self.assertGreater(float(np.mean(np.any(np.abs(first - last) > 0.1, axis=2))), 0.005)

    def test_the_last_level_frame_shows_the_refined_zone(self):
        first, last = self.pictures["level", 0], self.pictures["level", self.last]
        self.assertEqual(support.colour_pixels(body(first), LEVEL_1, 0.05), 0)
        self.assertGreater(support.colour_pixels(body(last), LEVEL_1, 0.05), 5000)


class Refusals(unittest.TestCase):
    """Bad options and folders exit 2 before ParaView is needed."""

    def script(self, *args):
        return subprocess.run([support.PYTHON, SCRIPT, *args], capture_output=True, text=True)

    def test_a_frame_index_past_the_end(self):
        proc = self.script(RUN, "--frames", "first,99")
        self.assertEqual(proc.returncode, 2)
        self.assertIn("--frames: '99' is not first, last, all or a frame index", proc.stderr)

    def test_a_folder_without_frames(self):
        os.makedirs(WORK("empty"))
        proc = self.script(WORK("empty"))
        self.assertEqual(proc.returncode, 2)
        self.assertIn("no .pvd file", proc.stderr)


if __name__ == "__main__":
    for tool in ("pvbatch", "Xvfb"):
        if shutil.which(tool) is None:
            support.skip(f"{tool} is not on the PATH (docs/outputs.md: apt-get install paraview "
                         "xvfb)")
    support.main()
