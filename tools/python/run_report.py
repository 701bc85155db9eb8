"""The Markdown report of a run directory (`dhpd report`, through plot_run.py and run_data.py)."""
# The run and its provenance, what the folder lacks, the scene file's header, the measured numbers
# beside the published and LEFM ones (report_numbers.py), the crack branches traced through the
# damage, the refinement settings and events, and the pictures.
import glob
import os

import numpy as np

import crack_path
from report_numbers import measured_section, number, table
from run_data import US

PICTURE_ORDER = ("contact_sheet", "levels", "energies", "momentum", "particles_dt", "tip_speed",
                 "crack_path")
PROVENANCE = (("version", "dhpd version"), ("commit", "commit"),
              ("command_line", "command line"), ("threads", "threads"),
              ("peak_memory_mb", "peak memory (MiB)"))


def last(column):
    return column[-1] if column is not None and len(column) else None


def run_section(run):
    """The run in a two-column table (from summary.json, else from history.csv and frames)."""
    s, h = run.summary, run.history
    status = s.get("status", "not recorded (no summary.json)") + (
        f" ({s['message']})" if s.get("message") else "")
    scene = run.name + (f" (`{s['scene_file']}`)" if s.get("scene_file") else "")
    start = s.get("particles_start", h["particles"][0] if run.has_history else None)
    end = s.get("particles_end", last(h.get("particles")))
    end_time = s.get("end_time", last(h.get("time")) if run.has_history else (
        run.frames[-1][0] if run.frames else None))
    dt = f"{number(s.get('dt', last(h.get('dt'))), US)} µs"
    if "critical_dt" in s:
        dt += f" (stable: {number(s['critical_dt'], US)} µs)"
    broken = s.get("broken_bonds", last(h.get("broken_bonds")))
    bonds = s.get("bonds", last(h.get("bonds")))
    rows = [["scene", scene], ["status", status],
            ["wall time", f"{number(s['wall_seconds'])} s" if "wall_seconds" in s else
             "not recorded"],
            ["particles", f"{number(start)} → {number(end)}"],
            ["steps", number(s.get("steps", last(h.get("step"))))], ["dt", dt],
            ["end time", f"{number(end_time, US)} µs" if end_time is not None else "—"],
            ["refinement events", number(s.get("refinement_events", len(
                (run.refinement or {}).get("generation", [])) if run.refinement else None))],
            ["broken bonds", f"{number(broken)} of {number(bonds)}"],
            ["frames", str(len(run.frames))]]
    return [f"# {run.name}: run report", ""] + table(["", ""], rows) + [""]


def provenance_section(summary):
    """Version, commit, command line, threads (and peak memory): 'not recorded' when absent."""
    rows = []
    for key, label in PROVENANCE:
        value = summary.get(key)
        if isinstance(value, list):
            value = " ".join(str(v) for v in value)
        text = "not recorded" if value in (None, "") else (
            f"`{value}`" if key == "command_line" else number(value) if key in (
                "threads", "peak_memory_mb") else str(value))
        rows.append([label, text])
    warnings = summary.get("warnings") or []
    lines = ["## Provenance", ""] + table(["", ""], rows) + [""]
    return lines + ([f"Warnings of the run: {len(warnings)}", ""] +
                    [f"- {w}" for w in warnings] + [""] if warnings else [])


def state_section(run):
    """What the folder lacks, for a run that did not complete."""
    if not run.missing and run.summary.get("status") == "completed":
        return []
    return ["> **This run did not complete or its folder is incomplete.** " + run.notes[0] + ".",
            ""] if run.notes else []


def scene_header(run):
    """The comment lines the scene file starts with, when the file is still where the run read
    it (as given, or beside the run's folder); [] otherwise."""
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


def branches_section(run):
    """The branches traced through the last frame's damage and their branch points."""
    if run.cracks is None or not run.frames:
        return []
    branches, points = crack_path.branch_rows(crack_path.traced(run))
    lines = ["## Crack branches (traced through the last frame's damage, crack_path.png)", ""]
    if not branches:
        return lines + ["No crack to trace in the last frame.", ""]
    lines += table(["tip", "branch", "from (mm)", "to (mm)", "damaged (µs)"], branches) + [""]
    if points:
        lines += table(["tip", "branch point (mm)", "time (µs)"], points) + [""]
    return lines


def refinement_settings(scene):
    """The scene's effects.refinement as rows ('—' for what it leaves out)."""
    settings = ((scene or {}).get("effects") or {}).get("refinement")
    if not isinstance(settings, dict):
        return []
    rows = []
    for key, value in settings.items():
        if isinstance(value, dict):
            value = ", ".join(f"{k} {v}" for k, v in value.items())
        elif isinstance(value, list):
            value = f"{len(value)} region(s)"
        rows.append([key, str(value)])
    return rows


def event_rows(run):
    """Totals of refinement.csv: events, parents, children, particles before and after, time."""
    r = run.refinement
    before = r["particles"][0] - r["children"][0] + r["parents"][0] if "particles" in r else None
    seconds = r.get("seconds", np.zeros(1))
    rows = [["events", str(len(r["generation"]))],
            ["first, last event", f"{number(r['time'][0], US)}, {number(r['time'][-1], US)} µs"],
            ["parents split", number(r.get("parents", np.zeros(1)).sum())],
            ["children created", number(r.get("children", np.zeros(1)).sum())],
            ["particles before the first, after the last event",
             f"{number(before)} → {number(last(r.get('particles')))}"],
            ["time spent in events", f"{number(seconds.sum())} s (largest {number(seconds.max())} s"
             f", re-sorts {number(r.get('resort_seconds', np.zeros(1)).sum())} s)"]]
    if "mapping_energy" in r:
        rows.append(["energy the mappings added", f"{number(r['mapping_energy'].sum())} J"])
    if "started_broken" in r:
        rows.append(["new bonds started broken", number(r["started_broken"].sum())])
    return rows


def refinement_section(run):
    settings = refinement_settings(run.scene)
    if not settings and run.refinement is None:
        return []
    lines = ["## Refinement", ""]
    lines += (table(["setting", "value"], settings) if settings else
              ["No refinement settings (scene.resolved.yaml missing)."]) + [""]
    if run.refinement is None:
        return lines + ["No refinement.csv: no event was recorded.", ""]
    lines += table(["events (refinement.csv)", ""], event_rows(run)) + [""]
    if os.path.isfile(run.path("plots", "levels.png")):
        lines += ["![refinement levels](plots/levels.png)", ""]
    return lines


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
    lines = ["## Pictures", "", "Lengths in mm, times in µs.", ""]
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
    sections = (run_section(run) + state_section(run) + provenance_section(run.summary)
                + about_section(run) + measured_section(run) + branches_section(run)
                + refinement_section(run) + pictures_section(run))
    path = run.path("report.md")
    with open(path + ".tmp", "w") as f:
        f.write("\n".join(sections) + "\n")
    os.replace(path + ".tmp", path)
    print(f"wrote {path}")
