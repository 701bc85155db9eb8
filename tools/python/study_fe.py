"""A study's errors against a finite-element reference (`fe_reference`; the horizon-size study of
issue 18): each run's displacement against the curves tools/python/fe_reference.py wrote, as
fe_compare.py measures it (RMS difference over the run, or over the reference's points, divided
by the reference's peak), and study.md's section naming the best run of each variant next to the
source's conclusion (`published`).

    fe_reference: {file: ../../../tests/data/fe/plate_vibration.csv, kind: probe, probe: P}
    published: "OSB δ = 3Δx, NOSB δ = 2Δx (horizon-size paper, conclusions)"

Metrics: fe_ux and fe_uy (u and v), fe_u the larger of the two. A run that did not complete
(a static run that did not converge stops with exit 3) has none and is named as such.
"""
import os
import re

import fe_compare

METRICS = ["fe_u", "fe_ux", "fe_uy"]
AXIS = {"fe_u": ("error against FE, larger of u and v (RMS / peak)", "%", 100.0),
        "fe_ux": ("u error against FE (RMS / peak)", "%", 100.0),
        "fe_uy": ("v error against FE (RMS / peak)", "%", 100.0)}
LOG_SCALE = set(METRICS)  # pareto.png draws these on a log axis
KINDS = ("probe", "field")


def check(entry, study_dir):
    """An error message for a malformed `fe_reference`, else None."""
    if not isinstance(entry, dict) or not set(entry) <= {"file", "kind", "probe"}:
        return f"fe_reference must be {{file: PATH, kind: probe|field, probe: NAME}}, not {entry!r}"
    if entry.get("kind") not in KINDS:
        return f"fe_reference.kind must be one of {list(KINDS)}, not {entry.get('kind')!r}"
    if not isinstance(entry.get("file"), str):
        return f"fe_reference.file must be a path, not {entry.get('file')!r}"
    if not os.path.isfile(os.path.join(study_dir, entry["file"])):
        return f"fe_reference.file: cannot read '{entry['file']}' (relative to the study file)"
    if not isinstance(entry.get("probe", "P"), str):
        return f"fe_reference.probe must be a probe's name, not {entry['probe']!r}"
    return None


def measure(row, study, study_dir):
    """Fills the row's fe_* metrics (left None when the study has no reference or the run did
    not complete); returns a message when the run cannot be compared with the reference (no
    probe of that name, reference points far from every particle), else None."""
    entry = study.get("fe_reference")
    if entry is None or row.get("status") != "completed":
        return None
    path = os.path.join(study_dir, entry["file"])
    try:
        if entry["kind"] == "probe":
            errors = fe_compare.probe_errors(row["out"], path, entry.get("probe", "P"))
        else:
            errors = fe_compare.field_errors(row["out"], path)
    except KeyError as e:
        return f"{row['label']}: history.csv has no column {e} (fe_reference.probe)"
    except SystemExit as e:  # fe_compare's own message
        return f"{row['label']}: {e.code}"
    row["fe_ux"], row["fe_uy"] = errors["ux"], errors["uy"]
    row["fe_u"] = max(errors["ux"], errors["uy"])
    return None


def percent(value):
    return "–" if value is None else f"{100.0 * value:.3g} %"


def variant_of(label):
    """A run's variant: its label without the grid point's " (key=value, ...)"."""
    return re.sub(r" \([^()]*\)$", "", label)


def best_of_groups(rows):
    """(variant, best row or None, rows) per variant (every grid point of a variant entry), in
    order: the run with the smallest fe_u."""
    groups = {}
    for r in rows:
        groups.setdefault(variant_of(r["label"]), []).append(r)
    out = []
    for group, members in groups.items():
        measured = [r for r in members if r.get("fe_u") is not None]
        out.append((group, min(measured, key=lambda r: r["fe_u"]) if measured else None, members))
    return out


def lines(study, rows, ref_row):
    """study.md's section on the finite-element reference: every run's u and v errors by
    variant, the best of each, and the source's conclusion."""
    entry = study.get("fe_reference")
    if entry is None:
        return []
    out = ["", f"## Against the finite-element reference ({entry['file']}, {entry['kind']})", "",
           "| run | u error | v error | larger | |", "|---|---|---|---|---|"]
    for r in [ref_row] + rows:
        status = "" if r.get("status") == "completed" else f"did not complete ({r.get('status')})"
        out.append(f"| {r['label']} | {percent(r.get('fe_ux'))} | {percent(r.get('fe_uy'))} | "
                   f"{percent(r.get('fe_u'))} | {status} |")
    out += ["", "Best of each variant (smallest larger error):", ""]
    for group, best, members in best_of_groups(rows):
        failed = sum(1 for r in members if r.get("status") != "completed")
        note = f"; {failed} of {len(members)} runs did not complete" if failed else ""
        out.append(f"- {group}: " + (f"**{best['label']}**, u {percent(best['fe_ux'])}, "
                                     f"v {percent(best['fe_uy'])}{note}"
                                     if best else f"no run completed{note}"))
    if study.get("published"):
        out += ["", f"Published: {study['published']}"]
    return out
