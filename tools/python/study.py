#!/usr/bin/python3
"""What accuracy costs in time: `dhpd study STUDY.yaml` (issue 5).

Runs a family of variants of one case (spacings, static fine/coarse zones, refinement thresholds,
buffers, levels), each through `dhpd run` with `--set` overrides, and measures for each its wall
time, particle-steps and peak memory, and its errors against a reference run: crack angle,
initiation time, tip-path distance, damage-field difference and L2 displacement error
(docs/theory.md §15, §17). Writes study.csv, study.md and pareto.png (error against time, Pareto front
marked) into the output folder and names the cheapest variant within the error budget. study.csv,
study.md and pareto.png are rewritten after every run, so a study stopped part-way keeps the rows
it measured. Run again into the same folder, a study reuses each run folder whose summary.json is
completed and whose study_variant.json (written there after the run: scene file, overrides,
threads, wall time, peak memory) names the same scene, overrides and threads, and says so; any
other run folder of the study is removed and run afresh. Peak memory is the engine process's own:
summary.json `peak_memory_mb` when the run wrote it, else VmHWM of /proc/PID/status polled while
the run lasts (study.csv `peak_source` says which; launch.py).

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
    fronts: {key: time.multirate, values: [false, true]}   # optional: every variant once per
                                     # value, one Pareto front each (study_fronts.py)
    criteria: {broken_bonds: 0.25, branching: 0.1}   # optional: limits every variant must meet;
                                     # study.md lists the misses and `dhpd study` exits 1
    reference_spread: {label: time step, set: {time.safety: [0.4, 0.6]}}   # optional: the
                                     # reference again under each of these overrides (a grid;
                                     # changes that should not matter, such as the time step):
                                     # every variant is measured against each of these members
                                     # and the reference, and meets the criteria when it meets
                                     # them against one (its crack is one the reference's
                                     # discretisation also gives; study_members.py)
    perturbed_reference: {label: safety 0.6, set: {time.safety: 0.6}}   # optional: the reference
                                     # again with these overrides on top (a change that should
                                     # not matter, such as the time step), measured against the
                                     # reference like a variant and held to the same criteria:
                                     # a criterion tighter than the reference's own spread under
                                     # it could not tell a good variant from a bad one, so the
                                     # study then fails as ill-posed
A variant may name its own `case`, fixed `set` overrides and a `grid` of overrides whose
cartesian product gives one run each; `expect: miss` marks a control (e.g. the uniform coarse
lattice) that must miss a criterion, else the study fails: its criteria cannot tell variants
apart. Metrics: angle_deg (largest |Δ angle| over the tips),
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
import hashlib
import itertools
import json
import os
import shutil
import sys

import yaml

import launch
import study_angles
import study_fe
import study_fronts
import study_members
from study_metrics import check_mirror, mirror_spread
from study_report import METRICS, criteria_failures, fmt, write_outputs

VARIANT_FILE = "study_variant.json"  # in each run folder: the variant and what its run measured


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
        runs.append((f"{label} ({suffix})" if suffix else label, case, overrides,
                     entry.get("expect")))
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
                            "frames", "mirror", "angles", "criteria", "perturbed_reference",
                            "reference_spread", "fronts", "fe_reference", "published"}
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
        check_mirror(path, study["mirror"], fail)
    if not isinstance(study.get("reference", {}), dict) or "grid" in study.get("reference", {}):
        fail(f"{path}: reference must be {{label: TEXT, set: {{KEY: VALUE, ...}}}} (one run, "
             "no grid)")
    perturbed = study.get("perturbed_reference")
    if perturbed is not None and not (
            isinstance(perturbed, dict) and set(perturbed) <= {"label", "set"}
            and isinstance(perturbed.get("set"), dict) and perturbed["set"]):
        fail(f"{path}: perturbed_reference must be {{label: TEXT, set: {{KEY: VALUE, ...}}}}, "
             f"not {perturbed!r}")
    spread = study.get("reference_spread")
    if spread is not None and not (
            isinstance(spread, dict) and set(spread) <= {"label", "set"}
            and isinstance(spread.get("set"), dict) and spread["set"]
            and all(isinstance(v, list) and v for v in spread["set"].values())):
        fail(f"{path}: reference_spread must be {{label: TEXT, set: {{KEY: [VALUE, ...], ...}}}}, "
             f"not {spread!r}")
    for v in study["variants"]:
        if isinstance(v, dict) and v.get("expect", "miss") != "miss":
            fail(f"{path}: a variant's expect must be 'miss', not {v['expect']!r}")
    if "fronts" in study and study_fronts.check(study["fronts"]):
        fail(f"{path}: {study_fronts.check(study['fronts'])}")
    if "fe_reference" in study:
        problem = study_fe.check(study["fe_reference"], os.path.dirname(os.path.abspath(path)))
        if problem:
            fail(f"{path}: {problem}")
    if not isinstance(study.get("published", ""), str):
        fail(f"{path}: published must be a text, not {study['published']!r}")
    if "angles" in study and not study_angles.valid(study["angles"]):
        fail(f"{path}: angles must be {{early_distance: NUMBER > 0}} (m), "
             f"not {study['angles']!r}")
    return study


def file_sha256(path):
    """SHA-256 of a file's bytes (None when it cannot be read)."""
    digest = hashlib.sha256()
    try:
        with open(path, "rb") as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                digest.update(block)
    except OSError:
        return None
    return digest.hexdigest()


def variant_record(case, overrides, threads, dhpd):
    """What makes a variant's run (JSON-normalised): its scene file and that file's content, the
    overrides, the threads and the dhpd executable's content (a rebuilt engine or an edited
    scene runs again; files the scene refers to are not hashed)."""
    engine = shutil.which(dhpd) or dhpd
    return json.loads(json.dumps({"case": os.path.abspath(case), "overrides": overrides,
                                  "threads": threads, "scene_sha256": file_sha256(case),
                                  "dhpd_sha256": file_sha256(engine)}))


def earlier_run(out_dir, record):
    """(summary, result) of an earlier run of the same variant in out_dir: its summary.json
    completed and its VARIANT_FILE of the same case, overrides and threads; else None."""
    try:
        with open(os.path.join(out_dir, VARIANT_FILE)) as f:
            stored = json.load(f)
    except (OSError, ValueError):
        return None
    summary = launch.readable_summary(out_dir)
    result = stored.get("result") if isinstance(stored, dict) else None
    if (not isinstance(summary, dict) or summary.get("status") != "completed"
            or any(stored.get(k) != v for k, v in record.items())
            or not isinstance(result, dict) or not isinstance(result.get("wall_s"), (int, float))):
        return None
    return summary, result


def run_one(dhpd, case, overrides, out_dir, threads):
    """Runs one variant, or reuses its earlier completed run in out_dir; returns its summary and
    result (wall seconds, peak memory in MiB and its source, reused)."""
    record = variant_record(case, overrides, threads, dhpd)
    earlier = earlier_run(out_dir, record)
    if earlier is not None:
        summary, result = earlier
        return summary, dict(result, reused=True)
    if os.path.isdir(out_dir):  # the study's own folder of a run it cannot reuse: made afresh
        shutil.rmtree(out_dir)
    run = launch.run(dhpd, case, out_dir, overrides, threads)
    # A run the guard stopped (exit 3: unstable, or a static run that did not converge) is a
    # result of its variant: its row says so and has no errors.
    stopped = run.code == 3 and (run.summary or {}).get("status") == "unstable"
    if run.code != 0 and not stopped:
        fail(f"run of {case} with {overrides} failed (exit {run.code}):\n{run.stderr}")
    if run.summary is None:
        fail(f"run of {case} with {overrides} wrote no readable {out_dir}/summary.json")
    result = {"wall_s": run.wall, "peak_mib": run.peak_mib, "peak_source": run.peak_source}
    if stopped:
        print(f"dhpd study: the run stopped: {run.summary.get('message', '')}", flush=True)
        return run.summary, dict(result, reused=False)
    with open(os.path.join(out_dir, VARIANT_FILE + ".tmp"), "w") as f:
        json.dump(dict(record, result=result), f, indent=2)
    os.replace(os.path.join(out_dir, VARIANT_FILE + ".tmp"), os.path.join(out_dir, VARIANT_FILE))
    return run.summary, dict(result, reused=False)


def measure_run(dhpd, label, case, overrides, out_dir, threads=None):
    """Runs one variant (or reuses its earlier run) and returns its row (errors filled in
    later) and summary."""
    summary, result = run_one(dhpd, case, overrides, out_dir, threads)
    if result["reused"]:
        print(f"dhpd study: {label}: reused {out_dir} (its summary.json is completed, with the "
              "same overrides)", flush=True)
    steps = summary.get("steps", 0)
    particles = 0.5 * (summary.get("particles_start", 0) + summary.get("particles_end", 0))
    row = {"label": label, "case": os.path.basename(case), "overrides": overrides,
           "wall_s": result["wall_s"], "particle_steps": particles * steps,
           "peak_mib": result.get("peak_mib"), "peak_source": result.get("peak_source", "unknown"),
           "reused": result["reused"], "particles_end": summary.get("particles_end"),
           "status": summary.get("status"), "out": out_dir}
    row.update({m: None for m in METRICS})
    return row, summary


def report_failures(study, rows, perturbed):
    """Prints every missed criterion (controls marked `expect: miss` must miss one instead; a
    variant run under the reference_spread's changes passes when enough of its runs do); the
    exit code: 1 when a variant fails, else 0."""
    judged = [r for r in rows if r.get("expect") != "miss"]
    failures = criteria_failures(study, judged + ([perturbed] if perturbed else []))
    verdicts = study_members.group_verdicts(study, judged)
    failed_groups = {g for g, ok, _, _ in verdicts if not ok}
    for label, metric, value, limit in failures:
        what = (" (the reference perturbed: the comparison is ill-posed)"
                if perturbed and label == perturbed["label"] else "")
        row = next((r for r in judged if r["label"] == label), {})
        against = f" (against {row['matched']})" if row.get("matched") else ""
        tolerated = row and row.get("group") not in failed_groups
        print(f"dhpd study: {label}: {metric} = {fmt(value)} is not within {limit}{what}{against}"
              + (" (tolerated: enough of its variant's runs pass)" if tolerated else ""),
              flush=True)
    for group, ok, passed, total in verdicts:
        if total > 1:
            print(f"dhpd study: {group}: {passed} of {total} runs meet every criterion"
                  + ("" if ok else ", too few"), flush=True)
    controls = study_members.control_failures(study, rows)
    for line in controls:
        print(f"dhpd study: {line}", flush=True)
    perturbed_failed = perturbed is not None and criteria_failures(study, [perturbed])
    return 1 if failed_groups or controls or perturbed_failed else 0


def plan(args):
    """The study, its output folder, the reference (label, case, overrides) and the variants."""
    if not os.path.isfile(args.study):
        fail(f"cannot read study file '{args.study}'")
    study = load_study(args.study)
    here = os.path.dirname(os.path.abspath(args.study))
    out = args.out or f"study-{study.get('name', 'study')}"
    ref_entry = dict(study.get("reference", {}))
    ref_entry.setdefault("label", "reference")
    (ref_label, ref_case, ref_set, _), = expand(here, study["case"], ref_entry)
    frames = study.get("frames", 2)
    if not isinstance(frames, int) or frames < 1:
        fail(f"{args.study}: frames must be an integer >= 1, not {frames!r}")
    # No checkpoints: they would cost each variant disk time in proportion to its size.
    quiet = {"output.frames": frames, "output.checkpoint_every": 0}
    spread = study.get("reference_spread")
    spread_sets = [] if spread is None else [
        (label, overrides) for label, _, overrides, _ in
        expand(here, study["case"], {"label": spread.get("label", "reference"),
                                     "grid": spread["set"]})]
    members = [(label, {**quiet, **ref_set, **overrides}) for label, overrides in spread_sets]
    # Each variant runs as given and, with a reference_spread, under each of its changes too (a
    # control only as given): the variant is judged on the share of its runs that pass
    # (study_members.group_verdicts).
    runs = []
    for label, case, overrides, expect in (r for v in study["variants"]
                                           for r in expand(here, study["case"], v)):
        runs.append((label, case, {**quiet, **overrides}, expect, label))
        if expect != "miss":
            runs += [(f"{label} [{member.split('(')[-1].rstrip(')')}]", case,
                      {**quiet, **overrides, **changes}, expect, label)
                     for member, changes in spread_sets]
    runs = study_fronts.expand(study.get("fronts"), runs)  # once per front's value, if any
    return study, out, (ref_label, ref_case, {**quiet, **ref_set}), runs, members


class Study:
    """The measured rows so far; study.csv, study.md and pareto.png rewritten after each."""

    def __init__(self, study, out, dhpd, here):
        self.study, self.out, self.dhpd, self.here = study, out, dhpd, here
        self.threads = study.get("threads")
        self.early = study.get("angles", {}).get("early_distance", 0.0)
        self.rows, self.perturbed, self.spread, self.total = [], None, None, 0
        self.members = []  # the reference, then its reference_spread runs (study_members.py)

    def measure(self, label, case, overrides, folder, reach=None, member=False):
        row, summary = measure_run(self.dhpd, label, case, overrides,
                                   os.path.join(self.out, folder), self.threads)
        row["angles"] = []
        if row["status"] != "completed":  # stopped by the guard: nothing to compare
            return row, summary
        if not member:
            study_members.compare_with_members(row, summary, self.members, self.study, reach)
        row["angles"] = study_angles.crack_angles(row["out"], summary, self.early)
        problem = study_fe.measure(row, self.study, self.here)
        if problem:
            fail(f"cannot compare with fe_reference: {problem}")
        return row, summary

    def reference(self, label, case, overrides, members):
        print(f"dhpd study: reference {label}", flush=True)
        self.ref_row, self.ref_summary = self.measure(label, case, overrides, "run-reference",
                                                      member=True)
        self.members = [study_members.member(label, self.ref_row, self.ref_summary)]
        ref_paths = self.members[0]["paths"]
        if "mirror" in self.study:
            self.spread = mirror_spread(ref_paths, self.study["mirror"])
        for k, (member_label, member_set) in enumerate(members):
            print(f"dhpd study: reference member {member_label}", flush=True)
            row, summary = self.measure(member_label, case, member_set,
                                        f"run-reference-{k + 1:02d}", member=True)
            self.members.append(study_members.member(member_label, row, summary))
        return self.write()

    def write(self):
        reused = [r["label"] for r in [self.ref_row] + self.rows if r.get("reused")]
        return write_outputs(self.study, self.rows, self.ref_row, self.out, self.perturbed,
                             self.spread, (len(self.rows), self.total, reused), self.members)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("study")
    parser.add_argument("--dhpd", required=True, help="the dhpd executable")
    parser.add_argument("--out", help="output folder (default: study-NAME)")
    args = parser.parse_args()
    study, out, (ref_label, ref_case, ref_set), runs, members = plan(args)
    os.makedirs(out, exist_ok=True)
    state = Study(study, out, args.dhpd, os.path.dirname(os.path.abspath(args.study)))
    state.total = len(runs)
    state.reference(ref_label, ref_case, ref_set, members)
    for k, (label, case, overrides, expect, group, front) in enumerate(runs):
        print(f"dhpd study: [{k + 1}/{len(runs)}] {label}", flush=True)
        row = state.measure(label, case, overrides, f"run-{k:02d}")[0]
        row["expect"], row["group"], row["front"] = expect, group, front
        state.rows.append(row)
        state.write()
    if "perturbed_reference" in study:
        entry = study["perturbed_reference"]
        label = entry.get("label", "perturbed reference")
        print(f"dhpd study: perturbed reference {label}", flush=True)
        # Judged as the variants are: "near the reference's damage" within their reach.
        reach = max((r.get("spurious_reach") or 0.0 for r in state.rows), default=0.0) or None
        state.perturbed = state.measure(label, ref_case, {**ref_set, **entry["set"]},
                                        "run-perturbed-reference", reach)[0]
    best = state.write()
    print(f"dhpd study: wrote {out}/study.csv, study.md, pareto.png"
          + (f"; cheapest within budget: {best['label']} ({best['wall_s']:.2f} s)" if best else ""))
    return report_failures(study, state.rows, state.perturbed)


if __name__ == "__main__":
    sys.exit(main())
