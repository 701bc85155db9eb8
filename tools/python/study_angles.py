"""Crack angles of a study's runs (`angles:` in a study file, tools/python/study.py).

Per run and notch tip the early angle (the median chord angle, notch tip to crack tip, over the
measurements of cracks.csv at which the tip lies between half of `early_distance` and
`early_distance` from the notch tip: the direction the crack took over its first few horizons,
not thrown by one tip that jumps between neighbouring particles) and the final chord angle
(summary.json), written to angles.csv and as a table for study.md."""
import csv
import os
import statistics

import run_folder


def valid(angles):
    """`angles: {early_distance: NUMBER > 0}`."""
    distance = angles.get("early_distance") if isinstance(angles, dict) else None
    return (isinstance(angles, dict) and set(angles) == {"early_distance"}
            and not isinstance(distance, bool) and isinstance(distance, (int, float))
            and distance > 0)


def fmt(value, digits=3):
    return "–" if value is None else f"{value:.{digits}g}"


def crack_angles(out_dir, summary, early_distance):
    """Per tip of the run: initiation time, the early angle (median chord angle over the
    measurements with the tip between early_distance / 2 and early_distance from the notch tip;
    None when there is none), the final chord angle and distance, and the published angle."""
    rows = {}
    for row in run_folder.read_records(os.path.join(out_dir, "cracks.csv")) or []:
        tip = rows.setdefault(row["tip"], {"band": [], "distance": 0.0})
        tip["distance"] = float(row["distance"])
        if 0.5 * early_distance <= tip["distance"] <= early_distance:
            tip["band"].append(float(row["angle_deg"]))
    published = summary.get("published", {})
    out = []
    for crack in summary.get("cracks", []):
        name = crack["name"]
        tip = rows.get(name, {"band": [], "distance": 0.0})
        tip["early_angle_deg"] = statistics.median(tip["band"]) if tip["band"] else None
        given = published.get(name, {}) if isinstance(published, dict) else {}
        out.append({"tip": name, "initiation_time": crack.get("initiation_time"),
                    "early_angle_deg": tip["early_angle_deg"],
                    "angle_deg": crack.get("angle_deg"), "distance": tip["distance"],
                    "published_angle_deg": given.get("angle_deg")
                    if isinstance(given, dict) else None})
    return out


def report(distance, rows, out):
    """angles.csv (one row per run and tip) and the study.md table of crack angles."""
    columns = ["tip", "initiation_time", "early_angle_deg", "angle_deg", "distance",
               "published_angle_deg"]
    with open(os.path.join(out, "angles.csv"), "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["label"] + columns)
        for r in rows:
            for tip in r["angles"]:
                w.writerow([r["label"]] + ["" if tip[c] is None else tip[c] for c in columns])
    lines = ["", f"Crack angles to the notch (°): early = median chord angle, notch tip to "
             f"crack tip, while the tip lay {distance * 500:g} to {distance * 1e3:g} mm from the "
             "notch tip; final = chord to the last tip (its distance in mm); published from the "
             "scene's `measure.published`.", "",
             "| run | tip | initiation (µs) | early | final | final distance (mm) | published |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        for tip in r["angles"]:
            t = tip["initiation_time"]
            lines.append(f"| {r['label']} | {tip['tip']} | {fmt(t * 1e6 if t else None)} | "
                         f"{fmt(tip['early_angle_deg'])} | {fmt(tip['angle_deg'])} | "
                         f"{tip['distance'] * 1e3:.1f} | {fmt(tip['published_angle_deg'])} |")
    return lines
