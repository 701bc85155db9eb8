#!/usr/bin/python3
"""The criteria of the stability suite (`dhpd stress`), checked from a run's outputs.

`check_run(dir_a, dir_b, criteria)` reads the outputs of one case run with 1 thread (dir_a) and,
optionally, with 2 threads (dir_b) and returns one measured value and a verdict per criterion:

- status:    summary.json "status" is "completed".
- finite:    every number of history.csv (and of cracks.csv / refinement.csv when present) and
             every component of every point array of every written frame is finite (cracks.csv
             angle_deg is nan by design while a crack has not left its notch: skipped there).
- energy:    max over history rows of (K + S - (E0 + W + W_map)) / scale, with K, S the kinetic and
             strain energy, W the external work of that row, W_map what refinement events added
             since the first row (refinement.csv's mapping_energy), E0 = K + S of the first row,
             and scale = max over rows of (E0 + |W| + |W_map|). Passes when <= energy_tolerance
             (0.01).
- momentum:  max over history rows and checked axes of |P_a - P_a(0)| / scale, with
             scale = max over the written frames of sum_i m_i |v_i| (m_i = rho of the particle's
             material x its volume). Passes when <= momentum_tolerance (1e-9).
- volume:    the smallest particle volume over every written frame; passes when > 0.
- reproducible: the two runs' history.csv, cracks.csv and refinement.csv are identical cell for
             cell (refinement.csv without its wall-time columns), they wrote the same number of
             frames, and every array of the last frames (points and point data) is equal exactly.
- energy_dip (reported, not a criterion): -min over rows of the same ratio: how far the total
             falls below the budget (fracture dissipation, Verlet's energy oscillation).
- hardness:  the case really is as hard as it claims (its `expect` block): at least so many
             broken bonds, particles left with no intact bond (own and dual), refinement levels,
             horizon ratio max/min, steps; a case that stopped being hard fails.
"""
import math
import os

import numpy as np

from run_folder import (CSV_FILES, WALL_COLUMNS, densities, frame_files, load_summary, read_frame,
                        read_table, run_columns)

DEFAULT_CRITERIA = {"energy_tolerance": 0.01, "momentum_tolerance": 1.0e-9,
                    "momentum_axes": ["x", "y", "z"]}
EXPECT_KEYS = ["broken_bonds", "isolated_particles", "max_level", "horizon_ratio", "steps"]


def history_columns(out_dir):
    """history.csv by column, plus `mapping_energy`: what refinement events added (refinement.csv)
    up to each row, counting the events after the first row (zones refined at step 0 come before
    it and are part of its energy)."""
    h = run_columns(out_dir, "history.csv")
    if h:
        h["mapping_energy"] = np.zeros(len(h["step"]))
        events = run_columns(out_dir, "refinement.csv")
        for step, energy in zip(events.get("step", []), events.get("mapping_energy", [])):
            if step > 0:
                h["mapping_energy"] += np.where(h["step"] >= step, energy, 0.0)
    return h


def all_finite_csv(out_dir):
    """Count of non-finite numbers in the run's CSV files."""
    bad = 0
    for name in CSV_FILES:
        table = read_table(os.path.join(out_dir, name))
        header = table[0] if table else []
        for row in (table[1] if table else []):
            cells = dict(zip(header, row))
            for column, cell in cells.items():
                if column == "angle_deg" and float(cells["distance"]) == 0:
                    continue  # documented: no angle while the crack has not left the notch
                try:
                    bad += not math.isfinite(float(cell))
                except ValueError:
                    pass  # a word column such as the crack tip's name
    return bad


def energy_balance(h):
    """(K + S - E0 - W - W_map) / max(E0 + |W| + |W_map|) at every history row (inf when the scale
    is 0 and the energy is not); W_map is what refinement events added (history_columns)."""
    total = h["kinetic_energy"] + h["strain_energy"]
    initial = total[0]
    mapping = h.get("mapping_energy", np.zeros(len(total)))
    scale = np.max(initial + np.abs(h["external_work"]) + np.abs(mapping))
    if scale <= 0:
        return np.where(total <= 0, 0.0, math.inf)
    return (total - initial - h["external_work"] - mapping) / scale


def energy_excess(h):
    """max (K + S - E0 - W) / max(E0 + |W|) over the history rows."""
    return float(np.max(energy_balance(h)))


def scan_frames(out_dir, frames):
    """One pass over every frame: non-finite numbers, max sum m|v|, smallest volume, last frame."""
    rho = densities(out_dir)
    scan = {"nonfinite": 0, "momentum_scale": 0.0, "min_volume": math.inf, "last": None}
    for frame in frames:
        f = read_frame(os.path.join(out_dir, frame))
        scan["nonfinite"] += sum(int(np.sum(~np.isfinite(a))) for a in f.values())
        speed = np.linalg.norm(np.atleast_2d(f["velocity"].T).T, axis=1)
        mass = rho[f["material"].astype(int)] * f["volume"]
        scan["momentum_scale"] = max(scan["momentum_scale"], float(np.sum(mass * speed)))
        scan["min_volume"] = min(scan["min_volume"], float(np.min(f["volume"])))
        scan["last"] = f
    return scan


def momentum_drift(h, scale, axes):
    """max over rows and axes of |P_a - P_a(0)| / scale."""
    drift = 0.0
    for axis in axes:
        p = h[f"momentum_{axis}"]
        drift = max(drift, float(np.max(np.abs(p - p[0]))))
    return drift / scale if scale > 0 else (0.0 if drift == 0 else math.inf)


def hardness_facts(summary, last, h):
    """What made the case hard, measured from its outputs."""
    isolated = 0
    if "bond_count" in last and "dual_count" in last:
        isolated = int(np.sum((last["bond_count"] == 0) & (last["dual_count"] == 0)))
    horizon = last["horizon"]
    return {"broken_bonds": int(summary.get("broken_bonds", 0)), "isolated_particles": isolated,
            "max_level": int(np.max(last["level"])) if "level" in last else 0,
            "horizon_ratio": float(np.max(horizon) / np.min(horizon)),
            "steps": int(summary.get("steps", 0)),
            "energy_dip": float(-np.min(energy_balance(h)))}


def same_csv(dir_a, dir_b, name):
    """'' when the two runs' CSV files agree cell for cell (wall-time columns left out)."""
    a, b = read_table(os.path.join(dir_a, name)), read_table(os.path.join(dir_b, name))
    if a is None and b is None:
        return ""
    if a is None or b is None or a[0] != b[0]:
        return f"{name}: present or header differs"
    keep = [k for k, col in enumerate(a[0]) if col not in WALL_COLUMNS]
    if len(a[1]) != len(b[1]):
        return f"{name}: {len(a[1])} rows against {len(b[1])}"
    for n, (ra, rb) in enumerate(zip(a[1], b[1])):
        for k in keep:
            if ra[k] != rb[k]:
                return f"{name}: row {n + 1} column {a[0][k]}: {ra[k]} against {rb[k]}"
    return ""


def same_frames(dir_a, dir_b):
    frames_a, frames_b = frame_files(dir_a), frame_files(dir_b)
    if len(frames_a) != len(frames_b) or not frames_a:
        return f"frames: {len(frames_a)} against {len(frames_b)}"
    fa = read_frame(os.path.join(dir_a, frames_a[-1]))
    fb = read_frame(os.path.join(dir_b, frames_b[-1]))
    if sorted(fa) != sorted(fb):
        return "last frame: different arrays"
    for name in fa:
        if fa[name].shape != fb[name].shape or not np.array_equal(fa[name], fb[name]):
            return f"last frame: array {name} differs"
    return ""


def reproducibility(dir_a, dir_b):
    """'' when the runs are identical, else what differs first."""
    for name in CSV_FILES:
        if difference := same_csv(dir_a, dir_b, name):
            return difference
    return same_frames(dir_a, dir_b)


def verdict(value, passed, note=""):
    return {"value": value, "pass": bool(passed), "note": note}


def check_run(dir_a, dir_b=None, criteria=None, expect=None):
    """Every criterion for one case: {criterion: {value, pass, note}} plus 'facts'."""
    c = dict(DEFAULT_CRITERIA, **(criteria or {}))
    for required in ("summary.json", "history.csv", "scene.resolved.yaml"):
        if not os.path.exists(os.path.join(dir_a, required)):
            return {"status": verdict("missing", False, f"{dir_a}: no {required}")}
    summary = load_summary(dir_a)
    frames = frame_files(dir_a)
    if not frames:
        return {"status": verdict(summary.get("status"), False, f"{dir_a}: no frame")}
    h = history_columns(dir_a)
    scan = scan_frames(dir_a, frames)
    last = scan["last"]
    bad = all_finite_csv(dir_a) + scan["nonfinite"]
    result = {"status": verdict(summary.get("status"), summary.get("status") == "completed",
                                summary.get("message", ""))}
    result["finite"] = verdict(bad, bad == 0, "non-finite numbers in the CSV files or frames")
    energy = energy_excess(h) if bad == 0 else math.inf
    result["energy"] = verdict(energy, energy <= c["energy_tolerance"])
    drift = (momentum_drift(h, scan["momentum_scale"], c["momentum_axes"]) if bad == 0
             else math.inf)
    result["momentum"] = verdict(drift, drift <= c["momentum_tolerance"],
                                 "axes " + "".join(c["momentum_axes"]))
    result["volume"] = verdict(scan["min_volume"], scan["min_volume"] > 0)
    if dir_b is not None:
        difference = reproducibility(dir_a, dir_b)
        result["reproducible"] = verdict("identical" if not difference else "differs",
                                         not difference, difference)
    facts = hardness_facts(summary, last, h)
    short = [f"{k} {facts[k]:.4g} < {v}" for k, v in (expect or {}).items() if not facts[k] >= v]
    result["hardness"] = verdict(len(short), not short, "; ".join(short))
    result["facts"] = facts
    return result
