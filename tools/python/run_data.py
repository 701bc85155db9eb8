"""A run directory as plot and report see it: required inputs, optional ones, notes on the rest."""
import dataclasses
import os
from dataclasses import dataclass

from run_folder import EXPECTED, InputError, read_columns, read_pvd, read_summary, pvd_candidates

__all__ = ["US", "InputError", "Run", "load_run"]

HISTORY_COLUMNS = ("time", "dt", "particles", "kinetic_energy", "strain_energy", "external_work",
                   "momentum_x", "momentum_y", "momentum_z")
CRACK_COLUMNS = ("time", "tip", "x", "y", "speed")
US = 1e6  # seconds to microseconds


def require_columns(table, names, path):
    missing = [n for n in names if n not in table]
    if missing:
        raise InputError(f"{path}: no column {', '.join(missing)} (columns: {', '.join(table)})")


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


def find_frames(run):
    """The frames of the run's .pvd (named after the scene, else the only .pvd), or a note."""
    found = pvd_candidates(run.directory, run.name)
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
    run.history = read_columns(history)
    require_columns(run.history, HISTORY_COLUMNS, history)
    find_frames(run)
    cracks = run.path("cracks.csv")
    if os.path.isfile(cracks):
        run.cracks = read_columns(cracks)
        require_columns(run.cracks, CRACK_COLUMNS, cracks)
        if not isinstance(run.summary.get("rayleigh_speed"), (int, float)):
            run.notes.append("summary.json has no rayleigh_speed: no c_R line in tip_speed.png")
    else:
        run.notes.append(f"no cracks.csv in {run.directory}: no tip_speed.png or crack_path.png")
    return run
