#!/usr/bin/python3
"""What accuracy costs in time: `dhpd study STUDY.yaml` (issue 5).

Runs a family of variants of one case (spacings, static fine/coarse zones, refinement thresholds,
buffers, levels), each through `dhpd run` with `--set` overrides, and measures for each its wall
time, particle-steps and peak memory, and its errors against a reference run: crack angle,
initiation time, tip-path distance, damage-field difference and L2 displacement error
(docs/theory.md §15, §17). Writes study.csv, study.md and pareto.png (error against time, Pareto front
marked) into the output folder and names the cheapest variant within the error budget.

Study file (YAML):
    name: branching_plate            # used in titles
    case: branching_plate_uniform.yaml   # scene file, relative to the study file
    reference: {label: uniform 0.25 mm, set: {body.0.spacing: 0.00025}}
    variants:
      - {label: uniform 1 mm, set: {body.0.spacing: 0.001}}
      - {label: adaptive, case: branching_plate_adaptive.yaml,
         grid: {effects.refinement.trigger.damage: [0.02, 0.05]}}
    error: angle_deg                 # the error plotted against time (any metric below)
    budget: {angle_deg: 3.0, tip_path: 0.002}   # limits for the "cheapest within budget"
    threads: 2                       # optional: --threads for every run
    frames: 2                        # frames per run (default 2: only the last is compared,
                                     # so writing frames costs every variant the same little)
    mirror: {tips: [upper, lower], axis: 1, at: 0.0}   # optional: two tips an exact solution
                                     # makes mirror images (about the plane x[axis] = at); the
                                     # distance between the reference's path of one and the
                                     # mirrored path of the other is its own tip-path spread,
                                     # the floor below which tip_path errors mean nothing
    angles: {early_distance: 0.02}   # optional: every run's crack angle per tip in angles.csv
                                     # and study.md, early (the median chord angle while the
                                     # tip lay early_distance/2 to early_distance m from the
                                     # notch tip) and final (the chord to the last tip), with
                                     # the scene's published angle
    criteria: {broken_bonds: 0.25, branching: 0.1}   # optional: limits every variant must meet;
                                     # study.md lists the misses and `dhpd study` exits 1
    perturbed_reference: {label: safety 0.6, set: {time.safety: 0.6}}   # optional: the reference
                                     # again with these overrides on top (a change that should
                                     # not matter, such as the time step), measured against the
                                     # reference like a variant and held to the same criteria:
                                     # a criterion tighter than the reference's own spread under
                                     # it could not tell a good variant from a bad one, so the
                                     # study then fails as ill-posed
A variant may name its own `case`, fixed `set` overrides and a `grid` of overrides whose
cartesian product gives one run each. Metrics: angle_deg (largest |Δ angle| over the tips),
initiation (largest |Δ t_init| / t_init,ref), tip_path (largest distance, m, from a variant's
tip positions to the reference tip path), damage (∫|φ − φ_ref| dV / ∫φ_ref dV at the end),
l2_displacement (‖u − u_ref‖ / ‖u_ref‖ at the end, ‖u‖² = Σ u·u V), broken_bonds (|B − B_ref| /
B_ref at the end), branching (largest |Δ t_B1| / t_B1,ref; infinite when only one run branches),
path_both_ways (tip_path also from the reference's tips to the variant's path), crack_distance
(symmetric Hausdorff distance, m, between the two runs' cracked particles, φ ≥ 0.35: robust to
which branch a tip follows), spurious_damage
(the variant's cracked volume, φ ≥ 0.35, farther than two of its coarsest spacings from every
particle the reference damaged to 0.1, over its cracked volume), momentum (largest drift of a
momentum component over the history, over Σ m|v| of the last frame). A variant of another
dimension than the reference (a 3D plate against a 2D reference) gets only angle_deg and
initiation; tip_path, damage and l2_displacement compare positions and are left empty.
"""
import argparse
import csv
import itertools
import json
import os
import sys

import yaml

import launch
import study_angles
from study_metrics import compare, distance_to_polyline, last_frame, tip_paths

METRICS = ["angle_deg", "initiation", "tip_path", "damage", "l2_displacement", "broken_bonds",
           "branching", "path_both_ways", "crack_distance", "spurious_damage", "momentum"]


def fail(message):
    """Input errors exit with code 2, like the rest of dhpd."""
    sys.stderr.write(f"dhpd study: error: {message}\n")
    sys.exit(2)


def expand(study_dir, default_case, entry):
    """The runs of one variant entry: (label, case path, overrides) for each grid point."""
    case = os.path.join(study_dir, entry.get("case", default_case))
    fixed = dict(entry.get("set", {}))
    grid = entry.get("grid", {})
    keys = list(grid)
    runs = []
    for values in itertools.product(*(grid[k] for k in keys)) if keys else [()]:
        overrides = dict(fixed)
        overrides.update(zip(keys, values))
        suffix = ", ".join(f"{k.split('.')[-1]}={v}" for k, v in zip(keys, values))
        label = entry.get("label", os.path.basename(case))
        runs.append((f"{label} ({suffix})" if suffix else label, case, overrides))
    return runs


def load_study(path):
    with open(path) as f:
        study = yaml.safe_load(f)
    if not isinstance(study, dict):
        fail(f"{path}: expected a map with case, reference and variants")
    for key in ("case", "variants"):
        if key not in study:
            fail(f"{path}: missing key '{key}'")
    unknown = set(study) - {"name", "case", "reference", "variants", "error", "budget", "threads",
                            "frames", "mirror", "angles", "criteria", "perturbed_reference"}
    if unknown:
        fail(f"{path}: unknown key(s) {sorted(unknown)}")
    if study.get("error", "angle_deg") not in METRICS:
        fail(f"{path}: error '{study['error']}' is not one of {METRICS}")
    for section in ("budget", "criteria"):
        for key, limit in study.get(section, {}).items():
            if key not in METRICS:
                fail(f"{path}: {section} key '{key}' is not one of {METRICS}")
            if isinstance(limit, bool) or not isinstance(limit, (int, float)) or limit < 0:
                fail(f"{path}: {section}.{key} must be a number >= 0, not {limit!r}")
    if "mirror" in study:
        check_mirror(path, study["mirror"])
    perturbed = study.get("perturbed_reference")
    if perturbed is not None and not (
            isinstance(perturbed, dict) and set(perturbed) <= {"label", "set"}
            and isinstance(perturbed.get("set"), dict) and perturbed["set"]):
        fail(f"{path}: perturbed_reference must be {{label: TEXT, set: {{KEY: VALUE, ...}}}}, "
             f"not {perturbed!r}")
    if "angles" in study and not study_angles.valid(study["angles"]):
        fail(f"{path}: angles must be {{early_distance: NUMBER > 0}} (m), "
             f"not {study['angles']!r}")
    return study


def check_mirror(path, mirror):
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


def run_one(dhpd, case, overrides, out_dir, threads):
    """Runs one variant; returns its summary, wall seconds and peak memory (MiB)."""
    run = launch.run(dhpd, case, out_dir, overrides, threads)
    if run.code != 0:
        fail(f"run of {case} with {overrides} failed (exit {run.code}):\n{run.stderr}")
    if run.summary is None:
        fail(f"run of {case} with {overrides} wrote no readable {out_dir}/summary.json")
    return run.summary, run.wall, run.peak_mib


def pareto_front(rows, metric):
    """Indices of the rows no other row beats in both wall time and `metric`."""
    valid = [i for i, r in enumerate(rows) if r[metric] is not None]
    front = []
    for i in valid:
        dominated = any(
            rows[j]["wall_s"] <= rows[i]["wall_s"] and rows[j][metric] <= rows[i][metric]
            and (rows[j]["wall_s"] < rows[i]["wall_s"] or rows[j][metric] < rows[i][metric])
            for j in valid)
        if not dominated:
            front.append(i)
    return front


def cheapest_within(rows, budget):
    """The fastest row whose every budgeted metric is known and within its limit."""
    ok = [r for r in rows
          if all(r[k] is not None and r[k] <= limit for k, limit in budget.items())]
    return min(ok, key=lambda r: r["wall_s"]) if ok else None


def plot_pareto(rows, metric, front, reference, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    xs = [r["wall_s"] for r in rows if r[metric] is not None]
    ys = [r[metric] for r in rows if r[metric] is not None]
    ax.scatter(xs, ys, color="tab:blue", label="variants")
    for r in rows:
        if r[metric] is not None:
            ax.annotate(r["label"], (r["wall_s"], r[metric]), fontsize=7,
                        xytext=(3, 3), textcoords="offset points")
    pts = sorted((rows[i]["wall_s"], rows[i][metric]) for i in front)
    if pts:
        ax.plot(*zip(*pts), color="tab:red", marker="o", label="Pareto front")
    ax.axvline(reference["wall_s"], color="grey", linestyle="--",
               label=f"reference ({reference['label']})")
    ax.set_xscale("log")
    ax.set_xlabel("wall time (s)")
    ax.set_ylabel(metric.replace("_", " "))
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def measure_run(dhpd, label, case, overrides, out_dir, threads=None):
    """Runs one variant and returns its row (errors filled in later)."""
    summary, wall, peak = run_one(dhpd, case, overrides, out_dir, threads)
    steps = summary.get("steps", 0)
    particles = 0.5 * (summary.get("particles_start", 0) + summary.get("particles_end", 0))
    row = {"label": label, "case": os.path.basename(case), "overrides": overrides,
           "wall_s": wall, "particle_steps": particles * steps, "peak_mib": peak,
           "particles_end": summary.get("particles_end"), "status": summary.get("status"),
           "out": out_dir}
    row.update({m: None for m in METRICS})
    return row, summary


def criteria_failures(study, rows):
    """(variant, metric, value, limit) for every criterion a variant misses (an unmeasured
    metric misses too)."""
    out = []
    for r in rows:
        for metric, limit in study.get("criteria", {}).items():
            value = r[metric]
            if value is None or not value <= limit:
                out.append((r["label"], metric, value, limit))
    return out


def perturbed_lines(study, perturbed, failures):
    """study.md's paragraph on the reference's own spread under `perturbed_reference`."""
    if perturbed is None:
        return []
    mine = [f for f in failures if f[0] == perturbed["label"]]
    measured = ", ".join(f"{m} = {fmt(perturbed[m])}" for m in study.get("criteria", {}))
    return ["", f"Reference's own spread ({perturbed['label']}, against the reference): {measured}: "
            + ("within every criterion, so the criteria can tell variants apart."
               if not mine else "**a criterion is tighter than the reference's own spread: the "
               "comparison is ill-posed** (choose a scene or an end time whose reference does "
               "not depend on this change).")]


def criteria_lines(study, rows, failures):
    if "criteria" not in study:
        return []
    limits = ", ".join(f"{k} ≤ {v}" for k, v in study["criteria"].items())
    lines = ["", f"Criteria ({limits}): "
             + ("**all variants pass**." if not failures else "**failed**:"), ""]
    lines += [f"- {label}: {metric} = {fmt(value)} (limit {limit})"
              for label, metric, value, limit in failures]
    return lines


def fmt(value, digits=4):
    return "–" if value is None else (f"{value:.{digits}g}" if isinstance(value, float) else str(value))


def write_outputs(study, rows, ref_row, out, perturbed=None):
    metric = study.get("error", "angle_deg")
    columns = ["label", "case", "wall_s", "particle_steps", "peak_mib", "particles_end"] + METRICS
    with open(os.path.join(out, "study.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(columns + ["overrides"])
        for r in [ref_row] + rows + ([perturbed] if perturbed else []):
            w.writerow([r[c] if r[c] is not None else "" for c in columns] + [json.dumps(r["overrides"])])
    front = pareto_front(rows, metric)
    plot_pareto(rows, metric, front, ref_row, os.path.join(out, "pareto.png"))
    budget = study.get("budget", {})
    best = cheapest_within(rows, budget)
    lines = [f"# Study: {study.get('name', 'study')}", "",
             f"Reference: **{ref_row['label']}** ({ref_row['case']}), "
             f"{ref_row['wall_s']:.1f} s, {ref_row['particles_end']} particles.", "",
             "| variant | wall (s) | vs reference | particle-steps | peak MiB | "
             + " | ".join(METRICS) + " | Pareto |",
             "|---" * (6 + len(METRICS)) + "|"]
    for i, r in enumerate(rows):
        speed = ref_row["wall_s"] / r["wall_s"] if r["wall_s"] > 0 else float("nan")
        lines.append(f"| {r['label']} | {r['wall_s']:.2f} | {speed:.1f}× faster | "
                     f"{r['particle_steps']:.3g} | {r['peak_mib']:.0f} | "
                     + " | ".join(fmt(r[m]) for m in METRICS)
                     + f" | {'yes' if i in front else ''} |")
    lines += ["", f"Error plotted: `{metric}` (pareto.png).", ""]
    if "mirror" in study:
        a, b = study["mirror"]["tips"]
        spread = mirror_spread(tip_paths(ref_row["out"]), study["mirror"])
        lines += [f"Reference's own tip-path spread ({a} against mirrored {b}): "
                  + (f"{spread:.4g} m" if spread is not None else "not measured")
                  + " (the two cracks are mirror images in an exact solution; a tip_path error "
                  "below this is within the reference's own uncertainty).", ""]
    if budget:
        limits = ", ".join(f"{k} ≤ {v}" for k, v in budget.items())
        lines.append(f"Cheapest within the budget ({limits}): "
                     + (f"**{best['label']}**, {best['wall_s']:.2f} s "
                        f"({ref_row['wall_s'] / best['wall_s']:.1f}× faster than the reference)."
                        if best else "none of the variants."))
    if "angles" in study:
        lines += study_angles.report(study["angles"]["early_distance"], [ref_row] + rows, out)
    checked = rows + ([perturbed] if perturbed else [])
    lines += perturbed_lines(study, perturbed, criteria_failures(study, checked))
    lines += criteria_lines(study, rows, criteria_failures(study, rows))
    lines += ["", "![error against time](pareto.png)", ""]
    with open(os.path.join(out, "study.md"), "w") as f:
        f.write("\n".join(lines))
    return best


def report_failures(study, rows, perturbed):
    """Prints every missed criterion; the exit code: 1 when there is one, else 0."""
    failures = criteria_failures(study, rows + ([perturbed] if perturbed else []))
    for label, metric, value, limit in failures:
        what = (" (the reference perturbed: the comparison is ill-posed)"
                if perturbed and label == perturbed["label"] else "")
        print(f"dhpd study: {label}: {metric} = {fmt(value)} is not within {limit}{what}",
              flush=True)
    return 1 if failures else 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("study")
    parser.add_argument("--dhpd", required=True, help="the dhpd executable")
    parser.add_argument("--out", help="output folder (default: study-NAME)")
    args = parser.parse_args()
    if not os.path.isfile(args.study):
        fail(f"cannot read study file '{args.study}'")
    study = load_study(args.study)
    here = os.path.dirname(os.path.abspath(args.study))
    out = args.out or f"study-{study.get('name', 'study')}"
    os.makedirs(out, exist_ok=True)
    ref_entry = dict(study.get("reference", {}))
    ref_entry.setdefault("label", "reference")
    (ref_label, ref_case, ref_set), = expand(here, study["case"], ref_entry)
    print(f"dhpd study: reference {ref_label}", flush=True)
    threads = study.get("threads")
    frames = study.get("frames", 2)
    if not isinstance(frames, int) or frames < 1:
        fail(f"{args.study}: frames must be an integer >= 1, not {frames!r}")
    # No checkpoints: they would cost each variant disk time in proportion to its size.
    quiet = {"output.frames": frames, "output.checkpoint_every": 0}
    ref_set = {**quiet, **ref_set}
    runs = [(label, case, {**quiet, **overrides})
            for label, case, overrides in
            (r for v in study["variants"] for r in expand(here, study["case"], v))]
    early = study.get("angles", {}).get("early_distance", 0.0)
    ref_row, ref_summary = measure_run(args.dhpd, ref_label, ref_case, ref_set,
                                       os.path.join(out, "run-reference"), threads)
    ref_row["angles"] = study_angles.crack_angles(ref_row["out"], ref_summary, early)
    ref_frame, ref_paths = last_frame(ref_row["out"]), tip_paths(ref_row["out"])
    rows = []
    for k, (label, case, overrides) in enumerate(runs):
        print(f"dhpd study: [{k + 1}/{len(runs)}] {label}", flush=True)
        row, summary = measure_run(args.dhpd, label, case, overrides,
                                   os.path.join(out, f"run-{k:02d}"), threads)
        compare(row, summary, ref_row, ref_summary, ref_frame, ref_paths)
        row["angles"] = study_angles.crack_angles(row["out"], summary, early)
        rows.append(row)
    perturbed = None
    if "perturbed_reference" in study:
        entry = study["perturbed_reference"]
        label = entry.get("label", "perturbed reference")
        print(f"dhpd study: perturbed reference {label}", flush=True)
        perturbed, summary = measure_run(args.dhpd, label, ref_case, {**ref_set, **entry["set"]},
                                         os.path.join(out, "run-perturbed-reference"), threads)
        # Judged as the variants are: "near the reference's damage" within their reach.
        reach = max((r.get("spurious_reach") or 0.0 for r in rows), default=0.0) or None
        compare(perturbed, summary, ref_row, ref_summary, ref_frame, ref_paths, reach)
        perturbed["angles"] = study_angles.crack_angles(perturbed["out"], summary, early)
    best = write_outputs(study, rows, ref_row, out, perturbed)
    print(f"dhpd study: wrote {out}/study.csv, study.md, pareto.png"
          + (f"; cheapest within budget: {best['label']} ({best['wall_s']:.2f} s)" if best else ""))
    return report_failures(study, rows, perturbed)


if __name__ == "__main__":
    sys.exit(main())
