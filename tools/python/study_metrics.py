"""The errors of a run against a reference run, for `dhpd study` (tools/python/study.py).

Crack angle and initiation (summary.json), tip-path distance (cracks.csv), damage-field and L2
displacement differences (last frames), and the adaptive-run checks of issue 12: broken bonds,
first branching time, damage where the reference has none, momentum drift.
"""
import math
import os

import numpy as np
from scipy.spatial import cKDTree  # nearest reference particle

import run_folder
import stress_check

# A particle of a crack (the crack measure's tip threshold, docs/scenes.md `measure`).
CRACK_DAMAGE = 0.35
# A particle the reference counts as damaged when asking whether a variant's crack is "where the
# reference has damage": lower than CRACK_DAMAGE, so the edge of a reference crack counts.
REFERENCE_DAMAGE = 0.1


def last_frame(out_dir):
    """Reference positions, volumes, displacement, velocity, damage, material and spacing of the
    run's last frame (None without frames)."""
    f = run_folder.last_frame(out_dir)
    if f is None:
        return None
    # A frame's points are the reference positions (tools/output/frame_fields.cpp).
    return {"x": f["points"], "u": f["displacement"], "v": f.get("velocity"), "volume": f.get("volume"),
            "damage": f.get("damage"), "material": f.get("material"), "spacing": f.get("spacing")}


def tip_paths(out_dir):
    """Tip positions per tip name from cracks.csv (empty when the scene measures nothing)."""
    paths = {}
    for row in run_folder.read_records(os.path.join(out_dir, "cracks.csv")) or []:
        paths.setdefault(row["tip"], []).append([float(row[k]) for k in ("x", "y", "z")])
    return {k: np.array(v) for k, v in paths.items()}


def crack_errors(summary, ref_summary):
    """Largest angle difference (deg) and relative initiation-time difference over the tips."""
    ref = {c["name"]: c for c in ref_summary.get("cracks", [])}
    angle, initiation = None, None
    for crack in summary.get("cracks", []):
        r = ref.get(crack["name"])
        if r is None:
            continue
        if crack.get("angle_deg") is not None and r.get("angle_deg") is not None:
            angle = max(angle or 0.0, abs(crack["angle_deg"] - r["angle_deg"]))
        t, tr = crack.get("initiation_time"), r.get("initiation_time")
        if t is not None and tr:
            initiation = max(initiation or 0.0, abs(t - tr) / tr)
    return angle, initiation


def branching_error(summary, ref_summary):
    """Largest |t_B1 − t_B1,ref| / t_B1,ref over the tips (first branching); infinite when one run
    branches and the other does not; 0 when neither branches (they agree); None without tips."""
    ref = {c["name"]: c for c in ref_summary.get("cracks", [])}
    worst = None
    for crack in summary.get("cracks", []):
        r = ref.get(crack["name"])
        if r is None:
            continue
        mine, theirs = crack.get("branch_times") or [], r.get("branch_times") or []
        error = (0.0 if not mine and not theirs else
                 abs(mine[0] - theirs[0]) / theirs[0] if mine and theirs else math.inf)
        worst = max(worst or 0.0, error)
    return worst


def distance_to_polyline(points, line):
    """Distance of each point to the polyline through `line` (consecutive tip positions)."""
    if len(line) == 1:
        return np.linalg.norm(points - line[0], axis=1)
    a, b = line[:-1], line[1:]
    ab = b - a
    length2 = np.maximum(np.sum(ab * ab, axis=1), 1e-300)
    best = np.full(len(points), np.inf)
    for k in range(len(a)):
        t = np.clip((points - a[k]) @ ab[k] / length2[k], 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(points - (a[k] + t[:, None] * ab[k]), axis=1))
    return best


def path_distance(paths, ref_paths, both_ways=False):
    """Largest distance from a variant's tip positions to the reference tip path (the polyline of
    its tip positions), over the tips both runs measure; with `both_ways` also from the
    reference's tip positions to the variant's path (a crack that stops short counts)."""
    worst = None
    for name, points in paths.items():
        ref = ref_paths.get(name)
        if ref is None or len(points) == 0 or len(ref) == 0:
            continue
        d = float(distance_to_polyline(points, ref).max())
        if both_ways:
            d = max(d, float(distance_to_polyline(ref, points).max()))
        worst = max(worst or 0.0, d)
    return worst


def field_errors(frame, ref):
    """Damage-field difference and L2 displacement error against the reference's nearest
    particle (the reference is the finest run, so each particle finds a close partner)."""
    if frame is None or ref is None or frame["volume"] is None:
        return None, None
    _, nearest = cKDTree(ref["x"]).query(frame["x"])
    v = frame["volume"]
    damage = None
    if frame["damage"] is not None and ref["damage"] is not None:
        ref_total = float(np.sum(ref["damage"] * ref["volume"])) if ref["volume"] is not None else 0
        if ref_total > 0:
            damage = float(np.sum(np.abs(frame["damage"] - ref["damage"][nearest]) * v)) / ref_total
    du = frame["u"] - ref["u"][nearest]
    norm_ref = math.sqrt(float(np.sum(np.sum(ref["u"][nearest] ** 2, axis=1) * v)))
    l2 = math.sqrt(float(np.sum(np.sum(du**2, axis=1) * v))) / norm_ref if norm_ref > 0 else None
    return damage, l2


def spurious_damage(frame, ref, reach):
    """The variant's cracked volume (φ ≥ CRACK_DAMAGE) farther than `reach` from every particle
    the reference has damaged (φ ≥ REFERENCE_DAMAGE), over its whole cracked volume: 0 when every
    crack of the variant lies where the reference has one."""
    if frame is None or ref is None or frame["damage"] is None or ref["damage"] is None:
        return None
    cracked = frame["damage"] >= CRACK_DAMAGE
    total = float(np.sum(frame["volume"][cracked]))
    if total == 0.0:
        return 0.0
    damaged = ref["x"][ref["damage"] >= REFERENCE_DAMAGE]
    if len(damaged) == 0:
        return 1.0
    distance, _ = cKDTree(damaged).query(frame["x"][cracked])
    return float(np.sum(frame["volume"][cracked][distance > reach])) / total


def crack_distance(frame, ref):
    """The symmetric Hausdorff distance between the two runs' cracked particles (φ ≥
    CRACK_DAMAGE, reference positions): every crack of each run lies within it of a crack of the
    other. Unlike the tip path it does not depend on which branch a tip follows."""
    if frame is None or ref is None or frame["damage"] is None or ref["damage"] is None:
        return None
    a, b = frame["x"][frame["damage"] >= CRACK_DAMAGE], ref["x"][ref["damage"] >= CRACK_DAMAGE]
    if len(a) == 0 or len(b) == 0:
        return None if len(a) == len(b) else math.inf
    return float(max(cKDTree(b).query(a)[0].max(), cKDTree(a).query(b)[0].max()))


def broken_bonds_error(out_dir, ref_dir):
    """|B − B_ref| / B_ref of the broken bonds at the end of the runs."""
    b = run_folder.run_columns(out_dir, "history.csv").get("broken_bonds")
    br = run_folder.run_columns(ref_dir, "history.csv").get("broken_bonds")
    if b is None or br is None or len(b) == 0 or len(br) == 0 or br[-1] == 0:
        return None
    return abs(float(b[-1]) - float(br[-1])) / float(br[-1])


def momentum_drift(out_dir, frame):
    """Largest |P_a(t) − P_a(0)| over the history rows and axes, over Σ m|v| of the last frame."""
    h = stress_check.history_columns(out_dir)
    if frame is None or frame["v"] is None or not h:
        return None
    rho = run_folder.densities(out_dir)
    mass = rho[frame["material"].astype(int)] * frame["volume"]
    scale = float(np.sum(mass * np.linalg.norm(np.atleast_2d(frame["v"].T).T, axis=1)))
    return stress_check.momentum_drift(h, scale, ["x", "y", "z"]) if scale > 0 else None


def is_3d(frame):
    return frame is not None and float(np.ptp(frame["x"][:, 2])) > 0.0


def compare(row, summary, ref_row, ref_summary, ref_frame, ref_paths, reach=None):
    """Fills the row's error metrics against the reference (tools/python/study.py METRICS). `reach` is
    spurious_damage's "near the reference's damage" (default: two of the row's coarsest
    spacings); it is stored in row["spurious_reach"]."""
    row["angle_deg"], row["initiation"] = crack_errors(summary, ref_summary)
    row["branching"] = branching_error(summary, ref_summary)
    row["broken_bonds"] = broken_bonds_error(row["out"], ref_row["out"])
    frame = last_frame(row["out"])
    row["momentum"] = momentum_drift(row["out"], frame)
    if is_3d(frame) != is_3d(ref_frame):
        return  # positions of another dimension: only the crack numbers compare
    paths = tip_paths(row["out"])
    row["tip_path"] = path_distance(paths, ref_paths)
    row["path_both_ways"] = path_distance(paths, ref_paths, both_ways=True)
    row["damage"], row["l2_displacement"] = field_errors(frame, ref_frame)
    row["crack_distance"] = crack_distance(frame, ref_frame)
    if frame is not None and frame["spacing"] is not None:
        # "Where the reference has damage": within two of the variant's coarsest spacings.
        row["spurious_reach"] = reach or 2.0 * float(np.max(frame["spacing"]))
        row["spurious_damage"] = spurious_damage(frame, ref_frame, row["spurious_reach"])


def check_mirror(path, mirror, fail):
    """Calls fail(message) when `mirror` is not {tips: [A, B], axis: 0|1|2, at: NUMBER}."""
    ok = (isinstance(mirror, dict) and set(mirror) <= {"tips", "axis", "at"}
          and isinstance(mirror.get("tips"), list) and len(mirror["tips"]) == 2
          and all(isinstance(t, str) for t in mirror["tips"])
          and mirror.get("axis") in (0, 1, 2)
          and isinstance(mirror.get("at", 0.0), (int, float))
          and not isinstance(mirror.get("at", 0.0), bool)
          and not isinstance(mirror.get("axis"), bool))
    if not ok:
        fail(f"{path}: mirror must be {{tips: [TIP, TIP], axis: 0|1|2, at: NUMBER}}, "
             f"not {mirror!r}")


def mirror_spread(paths, mirror):
    """Largest distance between one mirror tip's path and the reflected path of the other (both
    ways); None when the run lacks either tip."""
    a, b = (paths.get(t) for t in mirror["tips"])
    if a is None or b is None or len(a) == 0 or len(b) == 0:
        return None
    axis, at = mirror["axis"], float(mirror.get("at", 0.0))
    a_m, b_m = a.copy(), b.copy()
    a_m[:, axis] = 2 * at - a_m[:, axis]
    b_m[:, axis] = 2 * at - b_m[:, axis]
    return float(max(distance_to_polyline(a, b_m).max(), distance_to_polyline(b, a_m).max()))
