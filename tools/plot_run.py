#!/usr/bin/python3
"""Pictures and a Markdown report of a dhpd run directory (what `dhpd plot` and `dhpd report` run).

    /usr/bin/python3 tools/plot_run.py plot OUT [--times T1,T2,...] [--field damage]
    /usr/bin/python3 tools/plot_run.py report OUT

`plot` writes OUT/plots/:
  <field>_<k>.png   a frame field (default damage, fixed 0-1 scale), k = 0, 1, ...: 4 frames spread
                    evenly over the .pvd, or the frames nearest the --times (in s); 3D frames show
                    the particles of the mid-thickness slice
  energies.png      kinetic, strain, external work and kinetic + strain - external vs time
  momentum.png      |P| vs time (log scale when positive)
  particles_dt.png  particle count and time step vs time
  tip_speed.png     with cracks.csv: speed of each crack tip vs time, with the Rayleigh speed
  crack_path.png    with cracks.csv: the tip positions over the last damage frame
`report` makes the plots when they are missing and writes OUT/report.md: the run, the pictures and
a table of measured against published numbers (summary.json "published").

Optional inputs (frames, cracks.csv, the Rayleigh speed) are skipped with a note. Exit code 2 for a
missing or incomplete run directory and for a missing Python module (named with its Debian
package: python3-matplotlib, python3-numpy, python3-vtk9).
"""
import argparse
import csv
import dataclasses
import glob
import importlib
import json
import math
import os
import re
import sys
import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass


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
vtk_xml = require("vtkmodules.vtkIOXML", "python3-vtk9")
vtk_numpy = require("vtkmodules.util.numpy_support", "python3-vtk9")

EXPECTED = "expected the output directory of a dhpd run, with summary.json and history.csv"
HISTORY_COLUMNS = ("time", "dt", "particles", "kinetic_energy", "strain_energy", "external_work",
                   "momentum_x", "momentum_y", "momentum_z")
CRACK_COLUMNS = ("time", "tip", "x", "y", "speed")
US = 1e6  # seconds to microseconds


class InputError(Exception):
    """A problem with the input directory or arguments: one message, exit code 2."""


# ---- reading a run ------------------------------------------------------------------------------


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


# ---- frames -------------------------------------------------------------------------------------


@dataclass
class Frame:
    """One .vtu frame: reference positions and one field (vectors as magnitudes) per particle."""
    path: str
    field: str
    points: "np.ndarray"
    values: "np.ndarray"
    spacing: "np.ndarray"
    time: float
    step: int
    vector: bool = False
    slice_note: str = ""

    @property
    def dimension(self):
        extent = np.ptp(self.points, axis=0)
        return 3 if extent[2] > 0 else (2 if extent[1] > 0 else 1)

    @property
    def label(self):
        return f"|{self.field}|" if self.vector else self.field


def field_data(grid, name, default):
    array = grid.GetFieldData().GetArray(name)
    return array.GetValue(0) if array is not None and array.GetNumberOfTuples() else default


def estimated_spacing(points):
    """For frames without a `spacing` field: the spacing of a lattice filling the bounding box."""
    extent = np.ptp(points, axis=0)
    extent = extent[extent > 0]
    cell = np.prod(extent) / len(points) if extent.size else 1.0
    return np.full(len(points), cell ** (1.0 / max(extent.size, 1)))


def read_frame(path, name):
    """The positions, field `name`, spacing, time and step of a .vtu frame."""
    if not os.path.isfile(path):
        raise InputError(f"{path}: no such frame file")
    reader = vtk_xml.vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    grid = reader.GetOutput()
    data = grid.GetPointData()
    if data.GetArray(name) is None:
        names = [data.GetArrayName(k) for k in range(data.GetNumberOfArrays())]
        raise InputError(f"{path}: no point field '{name}' (fields: {', '.join(names)})")
    points = vtk_numpy.vtk_to_numpy(grid.GetPoints().GetData())
    values = vtk_numpy.vtk_to_numpy(data.GetArray(name))
    vector = values.ndim == 2
    if vector:
        values = np.linalg.norm(values, axis=1)
    spacing = data.GetArray("spacing")
    spacing = vtk_numpy.vtk_to_numpy(spacing) if spacing is not None else estimated_spacing(points)
    return Frame(path, name, points, values, spacing, field_data(grid, "TimeValue", float("nan")),
                 int(field_data(grid, "Step", -1)), vector)


def mid_slice(frame):
    """A 3D frame cut to the particles within half a spacing of the mid-thickness plane."""
    if frame.dimension < 3:
        return frame
    z = frame.points[:, 2]
    mid = 0.5 * (z.min() + z.max())
    keep = np.abs(z - mid) <= 0.5 * frame.spacing.max()
    note = f"mid-thickness slice z ≈ {mid:.4g} m ({keep.sum()} of {len(z)} particles)"
    return dataclasses.replace(frame, points=frame.points[keep], values=frame.values[keep],
                               spacing=frame.spacing[keep], slice_note=note)


def particles_figure(frame):
    """A figure and equal axes framing the x-y extent of the particles."""
    pad = frame.spacing.max()
    low, high = frame.points[:, :2].min(axis=0) - pad, frame.points[:, :2].max(axis=0) + pad
    width, height = high - low
    fig, ax = plt.subplots(figsize=(8, max(1.5, 8 * height / width) + 0.8))
    ax.set_xlim(low[0], high[0])
    ax.set_ylim(low[1], high[1])
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    return fig, ax


def draw_particles(fig, ax, frame, **style):
    """The particles as squares as wide as their spacing, coloured by the frame's values."""
    fig.canvas.draw()  # the axes' final size, to turn metres into points
    points_per_metre = ax.get_window_extent().width * 72.0 / fig.dpi / np.diff(ax.get_xlim())[0]
    size = (1.05 * frame.spacing * points_per_metre) ** 2  # scatter sizes are points squared
    return ax.scatter(frame.points[:, 0], frame.points[:, 1], c=frame.values, s=size, marker="s",
                      linewidths=0, **style)


def colour_range(frame):
    """Damage has the fixed scale 0-1, so frames compare; other fields their own range."""
    if frame.field == "damage":
        return 0.0, 1.0
    return float(frame.values.min()), float(frame.values.max())


def frame_title(frame, what):
    title = f"{what} at t = {frame.time * US:.4g} µs (step {frame.step})"
    return title + (f"\n{frame.slice_note}" if frame.slice_note else "")


def save(fig, path):
    """Saves and closes a figure; a temporary name and a rename, so no half-written picture."""
    temporary = path + ".tmp.png"
    fig.savefig(temporary, dpi=110, bbox_inches="tight")
    plt.close(fig)
    os.replace(temporary, path)


def save_field_png(frame, png, title):
    """A picture of the frame's field: x-y particles (1D: the field along x)."""
    vmin, vmax = colour_range(frame)
    if frame.dimension == 1:
        fig, ax = plt.subplots(figsize=(8, 4))
        ax.plot(frame.points[:, 0], frame.values, ".", ms=3)
        ax.set_xlabel("x (m)")
        ax.set_ylabel(frame.label)
        ax.set_ylim(vmin, vmax if vmax > vmin else vmin + 1.0)
    else:
        frame = mid_slice(frame)
        fig, ax = particles_figure(frame)
        artist = draw_particles(fig, ax, frame, cmap="viridis", vmin=vmin, vmax=vmax)
        fig.colorbar(artist, ax=ax, label=frame.label)
    ax.set_title(frame_title(frame, f"{title}: {frame.label}"))
    save(fig, png)
    return frame


def choose_frames(frames, times=None, count=4):
    """Indices into `frames`: the nearest to each time, or `count` spread evenly over them."""
    if times:
        frame_times = np.array([t for t, _ in frames])
        nearest = (int(np.argmin(np.abs(frame_times - t))) for t in times)
        return list(dict.fromkeys(nearest))
    spread = np.linspace(0, len(frames) - 1, min(count, len(frames)))
    return list(dict.fromkeys(int(round(k)) for k in spread))


def plot_frames(run, name="damage", times=None):
    """<name>_<k>.png for the chosen frames; earlier pictures of the field are removed first."""
    if not run.frames:
        return []
    for old in glob.glob(run.path("plots", f"{name}_*.png")):
        if re.fullmatch(rf"{re.escape(name)}_\d+\.png", os.path.basename(old)):
            os.remove(old)
    written = []
    for k, index in enumerate(choose_frames(run.frames, times)):
        png = run.path("plots", f"{name}_{k}.png")
        frame = save_field_png(read_frame(run.frames[index][1], name), png, run.name)
        print(f"wrote {png}: {os.path.basename(frame.path)}, t = {frame.time * US:.4g} µs"
              + (f", {frame.slice_note}" if frame.slice_note else ""))
        written.append(png)
    return written


# ---- history and cracks -------------------------------------------------------------------------


def time_axes(run, ylabel, title):
    """A figure with time in µs on x; returns it, its axes and the history times in µs."""
    fig, ax = plt.subplots(figsize=(8, 5))
    ax.set_xlabel("time (µs)")
    ax.set_ylabel(ylabel)
    ax.set_title(f"{run.name}: {title}")
    ax.grid(alpha=0.3)
    return fig, ax, run.history["time"] * US


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
    right.plot(t, h["dt"], "--", color="tab:orange", drawstyle="steps-post")
    right.set_ylabel("dt (s)", color="tab:orange")
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


def plot_crack_path(run, png):
    """The tip positions of cracks.csv over the damage of the last frame (when there is one)."""
    if run.frames:
        frame = mid_slice(read_frame(run.frames[-1][1], "damage"))
        fig, ax = particles_figure(frame)
        draw_particles(fig, ax, frame, cmap="Greys", vmin=0.0, vmax=1.0, alpha=0.6)
        title = frame_title(frame, f"{run.name}: crack tips over the damage")
    else:
        fig, ax = plt.subplots(figsize=(8, 6))
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        title = f"{run.name}: crack tips (no frame to draw under them)"
    for tip, rows in tips(run.cracks):
        ax.plot(run.cracks["x"][rows], run.cracks["y"][rows], "o-", ms=3, label=tip_label(tip))
    ax.set_title(title)
    ax.legend()
    save(fig, png)


HISTORY_PLOTS = (("energies.png", plot_energies), ("momentum.png", plot_momentum),
                 ("particles_dt.png", plot_particles_dt))
CRACK_PLOTS = (("tip_speed.png", plot_tip_speed), ("crack_path.png", plot_crack_path))


def plot(run, name="damage", times=None):
    """Every picture the run's inputs allow, in OUT/plots/; notes for what was skipped."""
    os.makedirs(run.path("plots"), exist_ok=True)
    plot_frames(run, name, times)
    for png, draw in HISTORY_PLOTS + (CRACK_PLOTS if run.cracks is not None else ()):
        draw(run, run.path("plots", png))
        print(f"wrote {run.path('plots', png)}")
    for note in run.notes:
        print(f"note: {note}")


# ---- report -------------------------------------------------------------------------------------

PER_EVENT_LISTS = ("branch_times", "branch_positions")  # compared by their first element
UNITS = {"initiation_time": "s", "angle_deg": "°", "max_speed": "m/s", "mean_speed": "m/s",
         "branch_times": "s", "branch_positions": "m", "tip": "m", "rayleigh_speed": "m/s"}
PICTURE_ORDER = ("energies", "momentum", "particles_dt", "tip_speed", "crack_path")


def number(value):
    """A value for a table: whole numbers in full, others to 4 digits, points as (x, y, z)."""
    if value is None:
        return "—"
    if isinstance(value, (bool, str, int)):
        return str(value)
    if isinstance(value, (list, tuple)):
        return "(" + ", ".join(number(v) for v in value) + ")"
    if float(value).is_integer() and abs(value) < 1e15:
        return str(int(value))
    return f"{value:.4g}"


def quantity(key, label=None):
    unit = UNITS.get(key)
    name = (label or key) + (" (first)" if key in PER_EVENT_LISTS else "")
    return f"{name} ({unit})" if unit else name


def compared(key, value):
    """The value a comparison uses: the first element of a per-event list, else the value."""
    if key in PER_EVENT_LISTS and isinstance(value, list):
        return value[0] if value else None
    return value


def relative_difference(measured, published):
    """(measured − published) / |published| as a signed percentage; for points the distance
    over the published point's length. "—" when either is missing or the published one is 0."""
    try:
        m, p = np.asarray(measured, dtype=float), np.asarray(published, dtype=float)
    except (TypeError, ValueError):
        return "—"
    if measured is None or published is None or m.shape != p.shape or not np.any(p):
        return "—"
    if m.ndim == 0:
        return f"{100.0 * (m - p) / abs(p):+.2f} %"
    return f"{100.0 * np.linalg.norm(m - p) / np.linalg.norm(p):.2f} % (distance)"


def published_rows(summary):
    """[quantity, measured, published, difference] for each key of summary["published"]: maps
    are matched to the crack of that name, other keys to summary's own top-level value."""
    cracks = {c.get("name"): c for c in summary.get("cracks", [])}
    rows = []
    for key, published in summary["published"].items():
        if isinstance(published, dict):
            crack = cracks.get(key, {})
            pairs = [(sub, f"{key}: {sub}", crack.get(sub), value)
                     for sub, value in published.items()]
        else:
            pairs = [(key, key, summary.get(key), published)]
        for sub, label, measured, value in pairs:
            m, p = compared(sub, measured), compared(sub, value)
            rows.append([quantity(sub, label), number(m), number(p), relative_difference(m, p)])
    return rows


def measured_rows(summary):
    """[quantity, measured] of each crack of summary["cracks"] and the Rayleigh speed."""
    rows = []
    for crack in summary.get("cracks", []):
        name = crack.get("name", "?")
        for key in ("initiation_time", "angle_deg", "max_speed", "mean_speed", "branch_times",
                    "tip"):
            if key in crack:
                rows.append([quantity(key, f"{name}: {key}"), number(compared(key, crack[key]))])
        if "branch_times" in crack:
            rows.append([f"{name}: branches", str(len(crack["branch_times"]))])
    if "rayleigh_speed" in summary:
        rows.append([quantity("rayleigh_speed"), number(summary["rayleigh_speed"])])
    return rows


def table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    return lines + ["| " + " | ".join(row) + " |" for row in rows]


def comparison_section(summary):
    """Measured against published numbers, or the measured crack numbers alone."""
    lines = ["## Measured vs published", ""]
    if isinstance(summary.get("published"), dict) and summary["published"]:
        header = ["quantity", "measured", "published", "relative difference"]
        return lines + table(header, published_rows(summary))
    rows = measured_rows(summary)
    if not rows:
        return lines + ["summary.json has no crack measurements (`cracks`) and no `published` "
                        "numbers."]
    lines += ["summary.json has no `published` numbers; the measured crack numbers:", ""]
    return lines + table(["quantity", "measured"], rows)


def run_section(run):
    """The run in a two-column table: scene, status, wall time, particles, steps, dt, events."""
    s = run.summary
    status = s.get("status", "?") + (f" ({s['message']})" if s.get("message") else "")
    scene = run.name + (f" (`{s['scene_file']}`)" if s.get("scene_file") else "")
    dt = f"{number(s.get('dt'))} s (stable: {number(s.get('critical_dt'))} s)"
    particles = f"{number(s.get('particles_start'))} → {number(s.get('particles_end'))}"
    end = s.get("end_time")
    rows = [["scene", scene], ["status", status],
            ["wall time", f"{number(s.get('wall_seconds'))} s"],
            ["particles", particles],
            ["steps", number(s.get("steps"))], ["dt", dt],
            ["end time", f"{end * US:.4g} µs" if isinstance(end, (int, float)) else "—"],
            ["refinement events", number(s.get("refinement_events"))],
            ["broken bonds", f"{number(s.get('broken_bonds'))} of {number(s.get('bonds'))}"]]
    return [f"# {run.name}: run report", ""] + table(["", ""], rows)


def scene_header(run):
    """The comment lines the scene file starts with (its source, what it shows, the numbers to
    expect), when the file is still where the run read it (as given, or beside the run's
    folder); [] otherwise."""
    name = run.summary.get("scene_file")
    if not isinstance(name, str) or not name:
        return []
    candidates = [name, os.path.join(run.directory, os.pardir, name)]
    path = next((c for c in candidates if os.path.isfile(c)), None)
    if path is None:
        return []
    lines = []
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            if not line.startswith("#"):
                break
            lines.append(line[1:].rstrip("\n").strip())
    return lines


def about_section(run):
    """The scene file's header as a quote, so the report says what the case is and expects."""
    header = scene_header(run)
    if not header:
        return []
    return ["## About this case (the scene file's header)", ""] + \
        [f"> {line}" if line else ">" for line in header] + [""]


def picture_key(name):
    """Frames first (by field, then k), then the fixed pictures in PICTURE_ORDER."""
    stem = os.path.splitext(name)[0]
    if stem in PICTURE_ORDER:
        return (1, PICTURE_ORDER.index(stem), "", 0)
    field_name, _, k = stem.rpartition("_")
    return (0, 0, field_name, int(k)) if k.isdigit() else (2, 0, stem, 0)


def pictures_section(run):
    names = sorted((os.path.basename(p) for p in glob.glob(run.path("plots", "*.png"))),
                   key=picture_key)
    lines = ["## Pictures", ""]
    lines += [f"![{os.path.splitext(n)[0]}](plots/{n})\n" for n in names]
    return lines + [f"- {note}" for note in run.notes] + [""]


def missing_plots(run):
    """The default pictures the run's inputs allow that plots/ does not hold."""
    wanted = [png for png, _ in HISTORY_PLOTS]
    if run.cracks is not None:
        wanted += [png for png, _ in CRACK_PLOTS]
    missing = [png for png in wanted if not os.path.isfile(run.path("plots", png))]
    if run.frames and not glob.glob(run.path("plots", "damage_*.png")):
        missing.append("damage_<k>.png")
    return missing


def report(run):
    """OUT/report.md, after making the pictures when some are missing."""
    if missing_plots(run):
        plot(run)
    text = "\n".join(run_section(run) + [""] + about_section(run) + pictures_section(run) +
                     comparison_section(run.summary)) + "\n"
    path = run.path("report.md")
    with open(path + ".tmp", "w") as f:
        f.write(text)
    os.replace(path + ".tmp", path)
    print(f"wrote {path}")


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
            report(run)
    except InputError as error:
        print(f"dhpd: error: {error}", file=sys.stderr)
        return 2
    except OSError as error:  # e.g. plots/ cannot be written
        print(f"dhpd: error: {error}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
