#!/usr/bin/python3
"""Pictures and a Markdown report of a dhpd run directory (what `dhpd plot` and `dhpd report` run).

    /usr/bin/python3 tools/python/plot_run.py plot OUT [--times T1,T2,...] [--field damage]
    /usr/bin/python3 tools/python/plot_run.py report OUT

`plot` writes OUT/plots/:
  <field>_<k>.png   a frame field (default damage, fixed 0-1 scale), k = 0, 1, ...: 4 frames spread
                    evenly over the .pvd, or the frames nearest the --times (in s); 3D frames show
                    the particles of the mid-thickness slice; pre-cracks, notches, loaded and
                    fixed regions drawn over them (run_overlay.py); x, y in mm, t in µs
  contact_sheet.png up to 12 damage frames spread over the run in one grid
  levels.png        refined runs: the last frame coloured by refinement level (one colour each)
  energies.png      kinetic, strain, external work and kinetic + strain - external vs time
  momentum.png      |P| vs time (log scale when positive)
  particles_dt.png  particle count and time step vs time
  tip_speed.png     with cracks.csv: speed of each crack tip vs time, with the Rayleigh speed
  crack_path.png    with cracks.csv: every branch traced through the last frame's damage, branch
                    points and times, the tip positions of cracks.csv (crack_path.py)
`report` makes the plots when they are missing and writes OUT/report.md: the run, its provenance,
what is missing, the pictures, the measured numbers beside the published and LEFM ones, the
branches, the refinement settings and events (run_report.py).

Any run folder with history.csv rows or frames is read, whatever its status (killed: no
summary.json; interrupted, unstable, io_error); what is missing is said in a note. Optional inputs
(frames, cracks.csv, the Rayleigh speed) are skipped with a note. Exit code 2 for a folder with
neither history rows nor frames and for a missing Python module (named with its Debian package:
python3-matplotlib, python3-numpy, python3-scipy, python3-yaml, python3-vtk9).
"""
import argparse
import importlib
import math
import os
import re
import sys


def require(module, package):
    """Imports `module`, or stops with exit code 2 naming the Debian package that provides it."""
    try:
        return importlib.import_module(module)
    except ImportError as error:
        print(f"dhpd: error: the Python module '{module}' is missing ({error}); install the "
              f"Debian package {package}: sudo apt-get install {package}", file=sys.stderr)
        sys.exit(2)


np = require("numpy", "python3-numpy")
require("matplotlib", "python3-matplotlib").use("Agg")
plt = require("matplotlib.pyplot", "python3-matplotlib")
require("vtkmodules.vtkIOXML", "python3-vtk9")
require("vtkmodules.util.numpy_support", "python3-vtk9")
require("scipy.spatial", "python3-scipy")
require("yaml", "python3-yaml")

# The rest of the tool, beside this file (imported once the modules above are known to exist).
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import crack_path  # noqa: E402
import run_report  # noqa: E402
import run_sheets  # noqa: E402
from run_data import US, InputError, load_run  # noqa: E402
from run_frames import plot_frames, save  # noqa: E402

# ---- history and cracks -------------------------------------------------------------------------


def time_axes(run, ylabel, title):
    """A figure with time in µs on x; returns it, its axes and the history times in µs."""
    fig, ax = plt.subplots(figsize=(8, 5))
    ax.set_xlabel("time (µs)")
    ax.set_ylabel(ylabel)
    ax.set_title(f"{run.name}: {title}")
    ax.grid(alpha=0.3)
    return fig, ax, run.history["time"] * US if run.has_history else None


def plot_energies(run, png):
    h = run.history
    fig, ax, t = time_axes(run, "energy (J)", "energies")
    ax.plot(t, h["kinetic_energy"], label="kinetic")
    ax.plot(t, h["strain_energy"], label="strain")
    ax.plot(t, h["external_work"], label="external work")
    balance = h["kinetic_energy"] + h["strain_energy"] - h["external_work"]
    ax.plot(t, balance, "k--", label="kinetic + strain − external work")
    ax.legend()
    save(fig, png)


def plot_momentum(run, png):
    h = run.history
    magnitude = np.sqrt(h["momentum_x"] ** 2 + h["momentum_y"] ** 2 + h["momentum_z"] ** 2)
    fig, ax, t = time_axes(run, "|P| (kg m/s)", "total momentum")
    positive = magnitude > 0
    if positive.any():  # a log scale shows round-off; zeros cannot be drawn on it
        ax.set_yscale("log")
        hidden = int((~positive).sum())
        label = "|P|" + (f" ({hidden} zero values not shown)" if hidden else "")
        ax.plot(t[positive], magnitude[positive], ".-", label=label)
    else:
        ax.plot(t, magnitude, ".-", label="|P| (all zero)")
    ax.legend()
    save(fig, png)


def plot_particles_dt(run, png):
    """Particles on the left axis (blue), dt on the right (orange, dashed)."""
    h = run.history
    fig, ax, t = time_axes(run, "particles", "particle count and time step")
    ax.plot(t, h["particles"], color="tab:blue", drawstyle="steps-post")
    ax.yaxis.label.set_color("tab:blue")
    ax.tick_params(axis="y", colors="tab:blue")
    right = ax.twinx()
    right.plot(t, h["dt"] * US, "--", color="tab:orange", drawstyle="steps-post")
    right.set_ylabel("dt (µs)", color="tab:orange")
    right.tick_params(axis="y", colors="tab:orange")
    save(fig, png)


def tips(cracks):
    """cracks.csv split by tip, in order of first appearance: [(tip, row mask)]."""
    names = [str(v) for v in cracks["tip"]]
    return [(tip, np.array([n == tip for n in names])) for tip in dict.fromkeys(names)]


def tip_label(tip):
    return f"tip {tip[:-2] if tip.endswith('.0') else tip}"


def plot_tip_speed(run, png):
    fig, ax, _ = time_axes(run, "tip speed (m/s)", "crack tip speed")
    time, speed = run.cracks["time"] * US, run.cracks["speed"]
    for tip, rows in tips(run.cracks):
        ax.plot(time[rows], speed[rows], ".-", label=tip_label(tip))
    rayleigh = run.summary.get("rayleigh_speed")
    if isinstance(rayleigh, (int, float)):
        ax.axhline(rayleigh, color="k", ls="--", label=f"Rayleigh speed c_R = {rayleigh:.4g} m/s")
    ax.legend()
    save(fig, png)


def force_columns(history):
    """history.csv's reactions (bcK_Rx, ...) and sectional forces (NAME_Fx, ...) that are not all
    zero (a static run, fictitious layers or output.sections)."""
    return [c for c in history if re.fullmatch(r"(bc\d+_R|.+_F)[xyz]", c)
            and np.any(np.asarray(history[c]) != 0)]


def plot_forces(run, png):
    """The reactions and sectional forces of history.csv: against the load factor in a static run
    (the load–displacement curve), else against time."""
    h = run.history
    static = "load_factor" in h
    fig, ax = plt.subplots(figsize=(8, 5))
    x = h["load_factor"] if static else h["time"] * US
    ax.set_xlabel("load factor" if static else "time (µs)")
    ax.set_ylabel("force (N)")
    ax.set_title(f"{run.name}: reactions and sectional forces")
    ax.grid(alpha=0.3)
    for column in force_columns(h):
        ax.plot(x, h[column], ".-", label=column)
    ax.legend()
    save(fig, png)


HISTORY_PLOTS = (("energies.png", plot_energies), ("momentum.png", plot_momentum),
                 ("particles_dt.png", plot_particles_dt))
CRACK_PLOTS = (("tip_speed.png", plot_tip_speed), ("crack_path.png", crack_path.plot_crack_path))


def refined(run):
    """Whether the run split particles (refinement.csv has children)."""
    children = (run.refinement or {}).get("children")
    return children is not None and float(children.sum()) > 0


def plot_sheets(run):
    """contact_sheet.png (frames) and levels.png (refined runs)."""
    if not run.frames:
        return
    png = run.path("plots", "contact_sheet.png")
    shown = run_sheets.save_contact_sheet(run, png)
    if shown:
        print(f"wrote {png}: {shown} damage frames")
    if refined(run):
        png = run.path("plots", "levels.png")
        top = run_sheets.save_level_png(run, png)
        if top is None:
            run.notes.append("no levels.png: the frames have no `level` field")
        else:
            print(f"wrote {png}: refinement levels 0 to {top} of the last frame")


def plot(run, name="damage", times=None):
    """Every picture the run's inputs allow, in OUT/plots/; notes for what was skipped."""
    os.makedirs(run.path("plots"), exist_ok=True)
    plot_frames(run, name, times)
    plot_sheets(run)
    plots = (HISTORY_PLOTS if run.has_history else ()) + (
        CRACK_PLOTS if run.cracks is not None else ())
    if run.has_history and force_columns(run.history):
        plots += (("forces.png", plot_forces),)
    for png, draw in plots:
        draw(run, run.path("plots", png))
        print(f"wrote {run.path('plots', png)}")
    for note in run.notes:
        print(f"note: {note}")


def default_pictures(run):
    """The pictures `plot` makes by default for what the run holds (the report wants them)."""
    wanted = [png for png, _ in HISTORY_PLOTS] if run.has_history else []
    if run.has_history and force_columns(run.history):
        wanted.append("forces.png")
    if run.cracks is not None:
        wanted += [png for png, _ in CRACK_PLOTS]
    if run.frames and int((run.scene or {}).get("dimension", 2)) >= 2:
        wanted.append("contact_sheet.png")  # 1D frames get none
    if refined(run):
        wanted.append("levels.png")
    return wanted


# ---- command line -------------------------------------------------------------------------------


def parse_times(text):
    """T1,T2,... in seconds."""
    try:
        times = [float(t) for t in text.split(",") if t.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected times in s separated by commas, got '{text}'")
    if not times or not all(math.isfinite(t) for t in times):
        raise argparse.ArgumentTypeError(f"expected finite times in s, got '{text}'")
    return times


def parse_arguments(argv):
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    commands = parser.add_subparsers(dest="command", required=True)
    plot_parser = commands.add_parser("plot", help="pictures in OUT/plots/")
    plot_parser.add_argument("directory", help="a run's output directory")
    plot_parser.add_argument("--times", type=parse_times,
                             help="plot the frames nearest these times, s: T1,T2,...")
    plot_parser.add_argument("--field", default="damage", help="frame field (default damage)")
    report_parser = commands.add_parser("report", help="OUT/report.md")
    report_parser.add_argument("directory", help="a run's output directory")
    return parser.parse_args(argv)


def main(argv=None):
    args = parse_arguments(argv)
    try:
        run = load_run(args.directory)
        if args.command == "plot":
            plot(run, args.field, args.times)
        else:
            run_report.report(run, plot, default_pictures(run))
    except InputError as error:
        print(f"dhpd: error: {error}", file=sys.stderr)
        return 2
    except OSError as error:  # e.g. plots/ cannot be written
        print(f"dhpd: error: {error}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
