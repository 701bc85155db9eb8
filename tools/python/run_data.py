"""Reading a dhpd run directory for tools/python/plot_run.py and tools/python/run_report.py: summary.json,
history.csv, cracks.csv and the frames of the .pvd."""
import csv
import glob
import json
import os
import xml.etree.ElementTree as ElementTree
import dataclasses
from dataclasses import dataclass

import numpy as np

EXPECTED = "expected the output directory of a dhpd run, with summary.json and history.csv"
HISTORY_COLUMNS = ("time", "dt", "particles", "kinetic_energy", "strain_energy", "external_work",
                   "momentum_x", "momentum_y", "momentum_z")
CRACK_COLUMNS = ("time", "tip", "x", "y", "speed")
US = 1e6  # seconds to microseconds


class InputError(Exception):
    """A problem with the input directory or arguments: one message, exit code 2."""


def read_csv(path):
    """The columns of a CSV file with a header: name -> array (float, or str if not numeric)."""
    with open(path, newline="") as f:
        rows = [row for row in csv.reader(f) if row]
    if not rows:
        raise InputError(f"{path}: empty (expected a header line and rows)")
    columns = {}
    for k, name in enumerate(rows[0]):
        cells = [row[k] if k < len(row) else "" for row in rows[1:]]
        try:
            columns[name] = np.array([float(c) for c in cells])
        except ValueError:
            columns[name] = np.array(cells)
    return columns


def require_columns(table, names, path):
    missing = [n for n in names if n not in table]
    if missing:
        raise InputError(f"{path}: no column {', '.join(missing)} (columns: {', '.join(table)})")


def read_pvd(path):
    """[(time, frame path)] of a ParaView collection, in file order."""
    try:
        root = ElementTree.parse(path).getroot()
    except ElementTree.ParseError as error:
        raise InputError(f"{path}: not a readable .pvd collection ({error})")
    base = os.path.dirname(path)
    return [(float(d.get("timestep")), os.path.join(base, d.get("file")))
            for d in root.iter("DataSet")]


@dataclass
class Run:
    """What a run directory holds. Optional inputs are empty, with a note saying why."""
    directory: str
    summary: dict
    history: dict
    frames: list = dataclasses.field(default_factory=list)  # [(time, .vtu path)]
    cracks: dict = None  # cracks.csv columns
    notes: list = dataclasses.field(default_factory=list)

    @property
    def name(self):
        return self.summary.get("scene", os.path.basename(os.path.abspath(self.directory)))

    def path(self, *parts):
        return os.path.join(self.directory, *parts)


def read_summary(directory):
    path = os.path.join(directory, "summary.json")
    if not os.path.isdir(directory):
        raise InputError(f"{directory}: no such directory; {EXPECTED}")
    if not os.path.isfile(path):
        raise InputError(f"{path}: missing; {EXPECTED}")
    try:
        with open(path) as f:
            return json.load(f)
    except json.JSONDecodeError as error:
        raise InputError(f"{path}: not valid JSON ({error})")


def find_frames(run):
    """The frames of the run's .pvd (named after the scene, else the only .pvd), or a note."""
    pvd = run.path(f"{run.name}.pvd")
    if not os.path.isfile(pvd):
        found = sorted(glob.glob(run.path("*.pvd")))
        if len(found) != 1:
            run.notes.append(f"no frames: {'no' if not found else 'more than one'} .pvd file in "
                             f"{run.directory}, so no field pictures")
            return
        pvd = found[0]
    run.frames = read_pvd(pvd)
    if not run.frames:
        run.notes.append(f"no frames: {pvd} lists none")


def load_run(directory):
    """Reads summary.json and history.csv (required), the frames and cracks.csv (optional)."""
    run = Run(directory, read_summary(directory), {})
    history = run.path("history.csv")
    if not os.path.isfile(history):
        raise InputError(f"{history}: missing; {EXPECTED}")
    run.history = read_csv(history)
    require_columns(run.history, HISTORY_COLUMNS, history)
    find_frames(run)
    cracks = run.path("cracks.csv")
    if os.path.isfile(cracks):
        run.cracks = read_csv(cracks)
        require_columns(run.cracks, CRACK_COLUMNS, cracks)
        if not isinstance(run.summary.get("rayleigh_speed"), (int, float)):
            run.notes.append("summary.json has no rayleigh_speed: no c_R line in tip_speed.png")
    else:
        run.notes.append(f"no cracks.csv in {run.directory}: no tip_speed.png or crack_path.png")
    return run
