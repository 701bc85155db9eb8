"""The Markdown report of a run directory (`dhpd report`, through plot_run.py and run_data.py).

The run, the scene file's header, the pictures and a table of measured against published numbers
(summary.json "published")."""
import glob
import os

import numpy as np

from run_data import US

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


def missing_plots(run, wanted):
    """Of `wanted` (the default pictures the run's inputs allow), those plots/ does not hold."""
    missing = [png for png in wanted if not os.path.isfile(run.path("plots", png))]
    if run.frames and not glob.glob(run.path("plots", "damage_*.png")):
        missing.append("damage_<k>.png")
    return missing


def report(run, make_plots, wanted):
    """OUT/report.md, after make_plots(run) when some of the `wanted` pictures are missing."""
    if missing_plots(run, wanted):
        make_plots(run)
    text = "\n".join(run_section(run) + [""] + about_section(run) + pictures_section(run) +
                     comparison_section(run.summary)) + "\n"
    path = run.path("report.md")
    with open(path + ".tmp", "w") as f:
        f.write(text)
    os.replace(path + ".tmp", path)
    print(f"wrote {path}")
