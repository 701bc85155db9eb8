"""The report's measured crack numbers beside the published and LEFM references when present."""
# References are read from what summary.json holds: `published` (the scene's measure.published,
# verbatim: a map per tip, e.g. {lower: {angle_deg: 65.7}}, and top-level keys such as
# particles_end), and LEFM values as `published.TIP.lefm_KEY`, `published.lefm.TIP.KEY` or a
# top-level `lefm.TIP.KEY`. Without summary.json (a killed run) the numbers come from cracks.csv.
import numpy as np

from run_data import MM, US

# (key of summary.json's crack, label, unit, scale to the unit shown)
QUANTITIES = (("initiation_time", "initiation time", "µs", US),
              ("initial_angle_deg", "angle three horizons out", "°", 1.0),
              ("angle_deg", "angle at the end", "°", 1.0),
              ("max_speed", "max speed", "m/s", 1.0),
              ("mean_speed", "mean speed", "m/s", 1.0),
              ("branchings", "branchings", "", 1.0),
              ("branch_time", "first branching", "µs", US),
              ("branch_times", "branch times", "µs", US),
              ("branch_speeds", "tip speed at each branching", "m/s", 1.0),
              ("tip", "tip at the end", "mm", MM))
HEADER = ["quantity", "measured", "published", "difference", "LEFM", "difference"]


def number(value, scale=1.0):
    """A value for a table: whole numbers in full, others to 4 digits, lists in brackets."""
    if value is None:
        return "—"
    if isinstance(value, (bool, str)):
        return str(value)
    if isinstance(value, (list, tuple)):
        return "(" + ", ".join(number(v, scale) for v in value) + ")"
    value = float(value) * scale
    if not np.isfinite(value):
        return str(value)
    return str(int(value)) if value.is_integer() and abs(value) < 1e15 else f"{value:.4g}"


def relative_difference(measured, reference, point=False):
    """(measured − reference) / |reference| as a signed percentage (element by element for
    lists); for a point the distance over the reference's length; "—" when either is missing,
    of other lengths, or the reference is 0."""
    if measured is None or reference is None:
        return "—"
    try:
        m, p = np.asarray(measured, dtype=float), np.asarray(reference, dtype=float)
    except (TypeError, ValueError):
        return "—"
    if m.shape != p.shape or not np.any(p) or not np.all(np.isfinite(m)):
        return "—"
    if m.ndim == 0:
        return f"{100.0 * (m - p) / abs(p):+.2f} %"
    if point:
        return f"{100.0 * np.linalg.norm(m - p) / np.linalg.norm(p):.2f} % (distance)"
    if not np.all(p):
        return "—"
    return "(" + ", ".join(f"{d:+.2f} %" for d in 100.0 * (m - p) / np.abs(p)) + ")"


def with_derived(values, count=True):
    """A crack's map with `branch_time` (the first) and with `count` `branchings` (how many: a
    reference's list may hold the first only) added."""
    out = dict(values or {})
    if isinstance(out.get("branch_times"), list):
        if count:
            out.setdefault("branchings", len(out["branch_times"]))
        if out["branch_times"]:
            out.setdefault("branch_time", out["branch_times"][0])
    return out


def references(summary, tip):
    """(published, LEFM) maps of a tip, read from what summary.json holds."""
    published = summary.get("published") if isinstance(summary.get("published"), dict) else {}
    mine = published.get(tip) if isinstance(published.get(tip), dict) else {}
    lefm = {k[5:]: v for k, v in mine.items() if k.startswith("lefm_")}
    for source in (published.get("lefm"), summary.get("lefm")):
        if isinstance(source, dict) and isinstance(source.get(tip), dict):
            lefm.update(source[tip])
    plain = {k: v for k, v in mine.items() if not k.startswith("lefm_")}
    return with_derived(plain, False), with_derived(lefm, False)


def row(label, measured, published, lefm, scale, point=False):
    return [label, number(measured, scale), number(published, scale),
            relative_difference(measured, published, point), number(lefm, scale),
            relative_difference(measured, lefm, point)]


def crack_rows(crack, published, lefm, rayleigh=None):
    """Every quantity measured or referenced for one tip."""
    measured = with_derived(crack)
    rows, known = [], set()
    for key, label, unit, scale in QUANTITIES:
        known.add(key)
        if key not in measured and key not in published and key not in lefm:
            continue
        text = f"{label} ({unit})" if unit else label
        rows.append(row(text, measured.get(key), published.get(key), lefm.get(key), scale,
                        key == "tip"))
        if key == "max_speed" and isinstance(rayleigh, (int, float)) and rayleigh > 0 and \
                isinstance(measured.get(key), (int, float)):
            rows[-1][1] += f" ({measured[key] / rayleigh:.2f} c_R)"
    for key in sorted((set(published) | set(lefm)) - known):
        rows.append(row(key, measured.get(key), published.get(key), lefm.get(key), 1.0))
    return rows


def trimmed(header, rows):
    """The table without the columns of a reference (published, LEFM) no row has a value of."""
    keep = [0, 1]
    for k in (2, 4):
        if any(r[k] != "—" for r in rows):
            keep += [k, k + 1]
    return [header[k] for k in keep], [[r[k] for k in keep] for r in rows]


def table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    return lines + ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]


def cracks_from_csv(cracks):
    """Crack numbers of cracks.csv for a run without summary.json: the first measurement away
    from the notch, the largest speed, the branchings, the last tip."""
    names = np.array([str(t) for t in cracks["tip"]])
    out = []
    for tip in dict.fromkeys(names):
        rows = names == tip
        t, distance = cracks["time"][rows], cracks.get("distance")
        moved = np.nonzero(distance[rows] > 0)[0] if distance is not None else []
        crack = {"name": tip, "max_speed": float(cracks["speed"][rows].max()),
                 "tip": [float(cracks["x"][rows][-1]), float(cracks["y"][rows][-1])]}
        if len(moved):
            crack["initiation_time"] = float(t[moved[0]])
        if "angle_deg" in cracks:
            crack["angle_deg"] = float(cracks["angle_deg"][rows][-1])
        if "branches" in cracks:
            count, most, times = cracks["branches"][rows], 1, []
            for k in range(len(count)):
                if count[k] > most:
                    most, times = count[k], times + [float(t[k])]
            crack["branch_times"] = times
        out.append(crack)
    return out


def top_level_rows(summary):
    """Published top-level numbers (e.g. particles_end) beside the summary's own value."""
    published = summary.get("published") if isinstance(summary.get("published"), dict) else {}
    tips = {c.get("name") for c in summary.get("cracks", [])}
    return [[key, number(summary.get(key)), number(value),
             relative_difference(summary.get(key), value)]
            for key, value in published.items()
            if key != "lefm" and key not in tips and not isinstance(value, dict)]


def as_numbers(value):
    """Numbers written as text back as floats, recursively: PyYAML reads YAML 1.1, in which
    scene.resolved.yaml's 5e-06 (no decimal point) is a string."""
    if isinstance(value, dict):
        return {k: as_numbers(v) for k, v in value.items()}
    if isinstance(value, list):
        return [as_numbers(v) for v in value]
    if isinstance(value, str):
        try:
            return float(value)
        except ValueError:
            return value
    return value


def measured_section(run):
    """## Measured numbers: a table per tip (measured, published, LEFM), the published
    top-level numbers, the Rayleigh speed."""
    summary = run.summary
    lines = ["## Measured numbers", ""]
    cracks = summary.get("cracks") or []
    if not cracks and run.cracks is not None and not summary:
        cracks = cracks_from_csv(run.cracks)
        lines += ["From cracks.csv (no summary.json: the run did not finish).", ""]
        # The references summary.json would have copied: the resolved scene's measure.published.
        published = ((run.scene or {}).get("measure") or {}).get("published")
        if isinstance(published, dict) and published:
            summary = {"published": as_numbers(published)}
            lines += ["Published and LEFM values from scene.resolved.yaml (`measure.published`).",
                      ""]
    if not cracks:
        lines += ["summary.json has no crack measurements (`cracks`)"
                  + (" and no `published` numbers." if not summary.get("published") else "."), ""]
    rayleigh = summary.get("rayleigh_speed")
    for crack in cracks:
        tip = crack.get("name", "?")
        published, lefm = references(summary, tip)
        header, rows = trimmed(HEADER, crack_rows(crack, published, lefm, rayleigh))
        lines += [f"**Tip `{tip}`**", ""] + table(header, rows) + [""]
    top = top_level_rows(summary)
    if top:
        lines += table(["quantity", "measured", "published", "difference"], top) + [""]
    if isinstance(rayleigh, (int, float)):
        lines += [f"Rayleigh speed c_R = {number(rayleigh)} m/s.", ""]
    if cracks and not summary.get("published"):
        lines += ["No published numbers: the scene has no `measure.published`.", ""]
    if cracks and all(not references(summary, c.get("name"))[1] for c in cracks):
        lines += ["No LEFM reference recorded (summary.json `published.TIP.lefm_KEY`, "
                  "`published.lefm.TIP.KEY` or `lefm.TIP.KEY`).", ""]
    return lines
