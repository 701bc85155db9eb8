"""A run directory as plot and report see it: what it holds, what is missing, notes on the rest."""
import dataclasses
import math
import os
from dataclasses import dataclass

from run_folder import (EXPECTED_ANY, InputError, columns_of, frame_files, load_scene,
                        load_summary, pvd_candidates, read_pvd, read_rows, read_vtu)

__all__ = ["US", "MM", "InputError", "Run", "load_run"]

HISTORY_COLUMNS = ("time", "dt", "particles", "kinetic_energy", "strain_energy", "external_work",
                   "momentum_x", "momentum_y", "momentum_z")
CRACK_COLUMNS = ("time", "tip", "x", "y", "speed")
US = 1e6  # seconds to microseconds
MM = 1e3  # metres to millimetres


def require_columns(table, names, path):
    missing = [n for n in names if n not in table]
    if missing:
        raise InputError(f"{path}: no column {', '.join(missing)} (columns: {', '.join(table)})")


@dataclass
class Run:
    """What a run directory holds. Optional inputs are empty, with a note saying why; `missing`
    says what a finished run would have and this one lacks."""
    directory: str
    summary: dict
    history: dict
    frames: list = dataclasses.field(default_factory=list)  # [(time, .vtu path)]
    cracks: dict = None  # cracks.csv columns
    refinement: dict = None  # refinement.csv columns
    scene: dict = None  # scene.resolved.yaml, first document
    derived: dict = dataclasses.field(default_factory=dict)
    notes: list = dataclasses.field(default_factory=list)
    missing: list = dataclasses.field(default_factory=list)

    @property
    def name(self):
        if self.summary.get("scene"):
            return self.summary["scene"]
        if self.scene and self.scene.get("name"):
            return str(self.scene["name"])
        return os.path.basename(os.path.abspath(self.directory))

    @property
    def has_history(self):
        return bool(self.history) and len(self.history["time"]) > 0

    def path(self, *parts):
        return os.path.join(self.directory, *parts)


def numeric_rows(header, rows):
    """The rows as wide as the header whose cells all read as numbers (the tip column aside)."""
    def whole(row):
        if len(row) != len(header):
            return False
        try:
            [float(c) for n, c in zip(header, row) if n != "tip"]
        except ValueError:
            return False
        return True
    return [row for row in rows if whole(row)]


def read_csv(run, name, required):
    """A CSV file of the run by column; {} when absent or without rows. Incomplete rows (a run
    stopped while writing one) are left out with a note; missing columns are an input error."""
    path = run.path(name)
    rows = [row for row in read_rows(path) or [] if row]
    if not rows:
        return {}
    header, body = rows[0], rows[1:]
    good = numeric_rows(header, body)
    if len(good) < len(body):
        run.notes.append(f"{name}: {len(body) - len(good)} incomplete row(s) left out (the run "
                         "was stopped while writing)")
    columns = columns_of(header, good)
    require_columns(columns, required, path)
    return columns if good else {}


def find_frames(run):
    """The frames of the run's .pvd (named after the scene, else the only .pvd) that exist; the
    frame files by name when there is no .pvd; a note for what is left out."""
    found = pvd_candidates(run.directory, run.name)
    if len(found) > 1:
        run.notes.append(f"no frames: more than one .pvd file in {run.directory}, so no field "
                         "pictures")
        return
    if found:
        listed = read_pvd(found[0])
        run.frames = [(t, p) for t, p in listed if os.path.isfile(p)]
        if len(run.frames) < len(listed):
            run.notes.append(f"{len(listed) - len(run.frames)} frame(s) listed in "
                             f"{os.path.basename(found[0])} are missing: left out")
        if not listed:
            run.notes.append(f"no frames: {found[0]} lists none")
        return
    names = frame_files(run.directory)
    if names:
        run.frames = [frame_by_name(run.path(n)) for n in names]
        run.frames = [f for f in run.frames if f is not None]
        run.missing.append(f"no .pvd: {len(run.frames)} readable frames of {len(names)} taken "
                           "by file name")
    else:
        run.notes.append(f"no frames in {run.directory}, so no field pictures")


def frame_by_name(path):
    """(time, path) of a frame file read for its TimeValue; None when it does not read."""
    try:
        arrays, fields = read_vtu(path)
    except (InputError, OSError, ValueError):
        return None
    if "points" not in arrays:
        return None
    return float(fields.get("TimeValue", math.nan)), path


def read_summary_or_note(run):
    try:
        run.summary = load_summary(run.directory) or {}
    except (ValueError, OSError) as error:
        run.summary = {}
        run.missing.append(f"summary.json does not read ({error})")
        return
    if not run.summary and not os.path.isfile(run.path("summary.json")):
        run.missing.append("no summary.json: the run did not finish")
    elif not isinstance(run.summary, dict):
        run.summary = {}
        run.missing.append("summary.json is not a JSON map")


def state_line(run):
    """What the report is made from, for a run that did not complete: '' when it did."""
    status = run.summary.get("status")
    if status == "completed" and not run.missing:
        return ""
    what = list(run.missing)
    if status and status != "completed":
        what.insert(0, f"status {status}" + (f" ({run.summary['message']})"
                                             if run.summary.get("message") else ""))
    sources = []
    if run.has_history:
        sources.append(f"history.csv ({len(run.history['time'])} rows)")
    if run.frames:
        sources.append(f"{len(run.frames)} frames")
    return "; ".join(what) + "; report from " + " and ".join(sources)


def load_run(directory):
    """Reads what the directory holds; InputError when it holds neither history rows nor
    frames (or a file has the wrong columns)."""
    if not os.path.isdir(directory):
        raise InputError(f"{directory}: no such directory; {EXPECTED_ANY}")
    run = Run(directory, {}, {})
    read_summary_or_note(run)
    run.scene, run.derived = load_scene(directory)
    run.history = read_csv(run, "history.csv", HISTORY_COLUMNS)
    find_frames(run)
    if not run.has_history and not run.frames:
        what = "no rows" if os.path.isfile(run.path("history.csv")) else "missing"
        raise InputError(f"{run.path('history.csv')}: {what}, and no frames; {EXPECTED_ANY}")
    if not run.has_history:
        run.missing.append("no history.csv rows: no energy, momentum or particle plots")
    if os.path.isfile(run.path("cracks.csv")):
        run.cracks = read_csv(run, "cracks.csv", CRACK_COLUMNS) or None
        if run.cracks is not None and not isinstance(run.summary.get("rayleigh_speed"),
                                                     (int, float)):
            run.notes.append("summary.json has no rayleigh_speed: no c_R line in tip_speed.png")
    else:
        run.notes.append(f"no cracks.csv in {run.directory}: no tip_speed.png or crack_path.png")
    if os.path.isfile(run.path("refinement.csv")):
        run.refinement = read_csv(run, "refinement.csv", ("generation", "time")) or None
    state = state_line(run)
    if state:
        run.notes.insert(0, state)
    return run
