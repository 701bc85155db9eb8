"""Shared helpers of the Python tooling's tests (tests/tools/python/test_*.py).

Each test script is run by ctest with Debian's /usr/bin/python3 and finds the engine in $DHPD_BIN
and the source tree in $DHPD_SOURCE_DIR (both default to this checkout and its build/dhpd); it
exits 77 to be counted as skipped. The scripts share a small scene (a notched glass plate with a
pre-crack, a pulled and a held edge, adaptive refinement and crack measurements with published
and LEFM numbers) that runs in about a second.
"""
import contextlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ElementTree

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.abspath(os.environ.get("DHPD_SOURCE_DIR") or os.path.join(HERE, "..", "..", ".."))
BIN = os.path.abspath(os.environ.get("DHPD_BIN") or os.path.join(SOURCE, "build", "dhpd"))
TOOLS = os.path.join(SOURCE, "tools", "python")
PYTHON = "/usr/bin/python3"
SKIP = 77

# The test scene: 40 mm x 20 mm at 1 mm (800 particles), a 15 mm pre-crack from the left edge at
# mid-height, 20 MPa on the top edge, the bottom edge held. Refinement splits the particles where
# the crack runs (800 -> about 2,500), the crack measure follows the notch tip. `published` holds
# made-up reference numbers (the tests compare the report's differences with their own).
SMALL_SCENE = """\
# A small notched glass plate for the Python tooling's tests: 40 mm x 20 mm at 1 mm, a 15 mm
# pre-crack from the left edge, the top edge pulled, the bottom edge held, refined where it cracks.
name: small_notched
dimension: 2
plane: stress
thickness: 0.001
materials:
  glass: {E: 72.0e9, rho: 2440, G0: 135.0}
body:
  - {shape: box, min: [0.0, 0.0], max: [0.04, 0.02], spacing: 0.001, material: glass}
horizon: {factor: 3.015}
model: dual-horizon
cracks:
  - [[0.0, 0.01], [0.015, 0.01]]
no_fail:
  - {shape: box, min: [0.0, 0.0], max: [0.04, 0.002]}
  - {shape: box, min: [0.0, 0.018], max: [0.04, 0.02]}
boundary_conditions:
  - region: {shape: box, min: [0.0, 0.0185], max: [0.04, 0.02]}
    traction: [0.0, 20.0e6]
    normal: y
  - region: {shape: box, min: [0.0, 0.0], max: [0.04, 0.0015]}
    fixed: true
effects:
  fracture: true
  refinement:
    trigger: {damage: 0.05, energy: 0.5, stretch: 0.7}
    buffer: 1.0
    max_level: 1
    check_every: 10
    mapping: linear
time: {end: 2.0e-5, safety: 0.8}
output: {frames: 12, history_every: 10}
measure:
  every: 1
  smoothing: 20
  tips:
    - {name: notch, at: [0.015, 0.01], direction: [1, 0]}
  published: {notch: {initiation_time: 5.0e-6, angle_deg: 10.0, lefm_initiation_time: 4.0e-6},
              particles_end: 1500}
"""
# The scene's geometry in mm, as the pictures must show it.
PRE_CRACK_MM = [(0.0, 10.0), (15.0, 10.0)]
NOTCH_TIP_MM = (15.0, 10.0)
TRACTION_BOX_MM = ((0.0, 18.5), (40.0, 20.0))
FIXED_BOX_MM = ((0.0, 0.0), (40.0, 1.5))
BODY_BOX_MM = ((0.0, 0.0), (40.0, 20.0))


def skip(message):
    print(f"SKIPPED: {message}")
    sys.stdout.flush()
    sys.exit(SKIP)


def require_binary():
    if not os.access(BIN, os.X_OK):
        raise AssertionError(f"no dhpd binary at {BIN} (set DHPD_BIN)")


def import_tools():
    """Puts tools/python on sys.path (matplotlib without a display) so its modules import."""
    import matplotlib
    matplotlib.use("Agg")
    if TOOLS not in sys.path:
        sys.path.insert(0, TOOLS)


class Workdir:
    """A temporary directory removed at exit (set DHPD_KEEP_TEST_DIRS=1 to keep it)."""

    def __init__(self, prefix):
        self.path = tempfile.mkdtemp(prefix=f"dhpd-{prefix}-")

    def __call__(self, *parts):
        return os.path.join(self.path, *parts)

    def cleanup(self):
        if os.environ.get("DHPD_KEEP_TEST_DIRS"):
            print(f"kept {self.path}")
        else:
            shutil.rmtree(self.path, ignore_errors=True)


def dhpd(*args, cwd=None, check=True, timeout=300):
    """Runs the engine binary; returns the CompletedProcess (stdout, stderr as text)."""
    proc = subprocess.run([BIN, *map(str, args)], cwd=cwd, capture_output=True, text=True,
                          timeout=timeout)
    if check and proc.returncode != 0:
        raise AssertionError(f"dhpd {' '.join(map(str, args))} exited {proc.returncode}:\n"
                             f"{proc.stdout}\n{proc.stderr}")
    return proc


def write(path, text):
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    with open(path, "w") as f:
        f.write(text)
    return path


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def small_scene(directory):
    """Writes the test scene as DIR/small_notched.yaml; returns its path."""
    return write(os.path.join(directory, "small_notched.yaml"), SMALL_SCENE)


def run_small(directory, out="run", *sets):
    """Runs the test scene into DIR/OUT (`sets`: extra --set KEY=VALUE); returns OUT's path."""
    scene = small_scene(directory)
    args = ["run", scene, "-o", os.path.join(directory, out), "-q"]
    for s in sets:
        args += ["--set", s]
    dhpd(*args)
    return os.path.join(directory, out)


def summary(run_dir):
    with open(os.path.join(run_dir, "summary.json")) as f:
        return json.load(f)


def pvd_frames(run_dir, name="small_notched"):
    """[(time, file name)] of the run's .pvd."""
    root = ElementTree.parse(os.path.join(run_dir, f"{name}.pvd")).getroot()
    return [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]


def csv_rows(path):
    """A CSV file as {column: text} maps."""
    import csv
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


@contextlib.contextmanager
def captured_figures():
    """Every figure the tools close (they close each after saving it) is kept in the yielded
    list, open, so its axes can be inspected; all are closed at the end."""
    import matplotlib.pyplot as plt
    real_close = plt.close
    kept = []

    def keep(fig=None):
        if fig is not None and not isinstance(fig, str):
            kept.append(fig)
        else:
            real_close(fig)
    plt.close = keep
    try:
        yield kept
    finally:
        plt.close = real_close
        for fig in kept:
            real_close(fig)


def png(path):
    """A PNG as an H x W x 3 float array in [0, 1] (alpha dropped)."""
    import matplotlib.image as image
    data = image.imread(path)
    assert data.ndim == 3 and data.shape[2] in (3, 4), f"{path}: not an RGB(A) picture"
    return data[:, :, :3]


def colour_pixels(picture, rgb, tolerance=0.06):
    """How many pixels are within `tolerance` (each channel) of the colour rgb."""
    import numpy as np
    return int(np.all(np.abs(picture - np.asarray(rgb, float)) <= tolerance, axis=2).sum())


def distinct_colours(picture):
    import numpy as np
    return len(np.unique((picture * 255).round().astype(np.uint8).reshape(-1, 3), axis=0))


def main():
    """unittest.main for a test script: exit 0 when every test passes, 1 otherwise."""
    import unittest
    unittest.main(module="__main__", verbosity=2)
