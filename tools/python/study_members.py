"""The reference of `dhpd study` as a set of runs (tools/python/study.py `reference_spread`).

A fracture run can settle into one of several crack patterns, and which one it settles into can
turn on a change that should not matter, such as a slightly different time step (the edge-crack
plate's uniform fine run breaks 6,700 or 9,000 bonds and branches at 15.3 or 12.5 µs for time
steps 0.3-0.6 of the stable one, docs/verification.md). A variant compared with one reference run
then passes or fails by the luck of which pattern each run fell into. With `reference_spread` the
reference also runs under each of those changes, and a variant is measured against every member:
it passes when it meets every criterion against one of them, that is, when its crack is one the
reference's discretisation also gives. The variant runs under the same changes too, and passes
when all but a quarter of its runs do: a crack pattern the fine run never shows, met by one run
in four, is a rare flip; met by most, a defect of the variant.
"""
from study_metrics import compare, last_frame, tip_paths
from study_report import criteria_failures, group_verdicts  # noqa: F401 (re-exported)


def member(label, row, summary):
    """A reference member: its row and summary, last frame and tip paths."""
    return {"label": label, "row": row, "summary": summary, "frame": last_frame(row["out"]),
            "paths": tip_paths(row["out"])}


def compare_with_members(row, summary, members, study, reach=None):
    """Fills `row`'s metrics against the member it matches best: the first (in order, the
    reference first) against which it meets every criterion, else the one it misses fewest
    criteria against; row["matched"] names it."""
    best, best_misses = None, None
    for m in members:
        candidate = dict(row)
        compare(candidate, summary, m["row"], m["summary"], m["frame"], m["paths"], reach)
        misses = len(criteria_failures(study, [candidate]))
        if best is None or misses < best_misses:
            best, best_misses = candidate, misses
            best["matched"] = m["label"]
        if misses == 0:
            break
    row.clear()
    row.update(best)
    return row


def control_failures(study, rows):
    """Lines for every variant marked `expect: miss` (a control the criteria must reject) that
    meets every criterion against some member: then the criteria cannot tell variants apart."""
    return [f"{r['label']}: meets every criterion (against {r.get('matched')}), but it is a "
            "control that must miss one: the criteria cannot tell variants apart"
            for r in rows if r.get("expect") == "miss" and not criteria_failures(study, [r])]

