"""Several Pareto fronts in one study: every variant run once per value of one scene key.

Study file:
    fronts: {key: time.multirate, values: [false, true], labels: [one global step, multi-rate]}

Each variant (and each of its reference_spread runs) then runs once per value with `key: value`
added to its overrides; its label and group get " · LABEL", and the row's "front" names the value's
label. pareto.png draws one front per value and study.md says, per front, which variants are on
it and the cheapest within the budget, so a user sees what the setting buys (issue 16).
"""


def check(fronts):
    """An error message for a malformed `fronts` entry, or None."""
    ok = (isinstance(fronts, dict) and set(fronts) <= {"key", "values", "labels"}
          and isinstance(fronts.get("key"), str) and fronts["key"]
          and isinstance(fronts.get("values"), list) and len(fronts["values"]) >= 2)
    labels = fronts.get("labels") if isinstance(fronts, dict) else None
    if ok and labels is not None:
        ok = (isinstance(labels, list) and len(labels) == len(fronts["values"])
              and all(isinstance(x, str) and x for x in labels) and len(set(labels)) == len(labels))
    if ok:
        return None
    return ("fronts must be {key: KEY, values: [VALUE, VALUE, ...], labels: [TEXT, ...]} "
            f"(two values or more; labels optional, one per value, distinct), not {fronts!r}")


def labels_of(fronts):
    return fronts.get("labels") or [f"{fronts['key'].split('.')[-1]}={v}" for v in fronts["values"]]


def expand(fronts, runs):
    """The runs (label, case, overrides, expect, group) once per value: (…, group, front)."""
    if not fronts:
        return [run + (None,) for run in runs]
    out = []
    for value, name in zip(fronts["values"], labels_of(fronts)):
        for label, case, overrides, expect, group in runs:
            out.append((f"{label} · {name}", case, {**overrides, fronts["key"]: value}, expect,
                        f"{group} · {name}", name))
    return out


def groups(rows):
    """{front label: [row indices]} in first-seen order; {None: all} when the study has none."""
    out = {}
    for i, r in enumerate(rows):
        out.setdefault(r.get("front"), []).append(i)
    return out


def lines(rows, ref_row, fronts_by_name, cheapest):
    """study.md lines: per front, the variants on it and the cheapest within the budget."""
    if list(fronts_by_name) == [None]:
        return []
    out = ["Fronts (one Pareto front per value; pareto.png):", ""]
    for name, front in fronts_by_name.items():
        on = ", ".join(rows[i]["label"] for i in front) or "none"
        best = cheapest([rows[i] for i in groups(rows)[name]])
        what = (f"cheapest within the budget **{best['label']}**, {best['wall_s']:.2f} s "
                f"({ref_row['wall_s'] / best['wall_s']:.1f}× faster than the reference)"
                if best else "no variant within the budget")
        out.append(f"- **{name}**: {what}; on the front: {on}.")
    return out + [""]
