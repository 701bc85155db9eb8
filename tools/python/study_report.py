"""study.csv, study.md and pareto.png of `dhpd study`, rewritten each time a variant finishes."""
import csv
import json
import os

import study_angles
import study_fe
import study_fronts

METRICS = ["angle_deg", "initiation", "tip_path", "damage", "l2_displacement", "broken_bonds",
           "branching", "path_both_ways", "crack_distance", "spurious_damage", "momentum"
           ] + study_fe.METRICS
# The error each metric measures and the unit pareto.png shows it in (scale from study.csv's).
AXIS = {"angle_deg": ("crack angle error, largest |Δθ| over the tips", "°", 1.0),
        "initiation": ("initiation time error, largest |Δt| / t_ref", "dimensionless", 1.0),
        "tip_path": ("tip path error, largest distance to the reference path", "mm", 1e3),
        "damage": ("damage field error, ∫|φ − φ_ref| dV / ∫φ_ref dV", "dimensionless", 1.0),
        "l2_displacement": ("L2 displacement error, ‖u − u_ref‖ / ‖u_ref‖", "dimensionless", 1.0),
        "broken_bonds": ("broken bond error, |B − B_ref| / B_ref", "dimensionless", 1.0),
        "branching": ("first branching error, |Δt_B1| / t_B1,ref", "dimensionless", 1.0),
        "path_both_ways": ("tip path error both ways, largest distance", "mm", 1e3),
        "crack_distance": ("crack distance error (Hausdorff)", "mm", 1e3),
        "spurious_damage": ("spurious cracked volume / cracked volume", "dimensionless", 1.0),
        "momentum": ("momentum drift / Σ m|v|", "dimensionless", 1.0), **study_fe.AXIS}
COLUMNS = ["label", "case", "wall_s", "particle_steps", "peak_mib", "particles_end"] + METRICS


def fmt(value, digits=4):
    if value is None:
        return "–"
    return f"{value:.{digits}g}" if isinstance(value, float) else str(value)


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


def axis_label(metric):
    what, unit, _ = AXIS[metric]
    return f"{what} ({unit})"


def plot_pareto(rows, metric, front, reference, path, budget=None, title=""):
    """The error against wall time: variants, the Pareto front (one per front of a study with
    `fronts`: `front` is then {label: indices}), the reference's time and the budget of the
    plotted error as a horizontal line."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scale = AXIS[metric][2]
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    shown = [r for r in rows if r[metric] is not None]
    fronts = front if isinstance(front, dict) else {None: front}
    colours = ["tab:red", "tab:purple", "tab:orange", "tab:green", "tab:brown"]
    for k, name in enumerate(fronts):  # the variants, in their front's colour when there are some
        group = [r for r in shown if r.get("front") == name]
        ax.scatter([r["wall_s"] for r in group], [r[metric] * scale for r in group],
                   color="tab:blue" if name is None else colours[k % len(colours)], alpha=0.6,
                   label="variants" if name is None else f"variants: {name}")
    for r in shown:
        ax.annotate(r["label"], (r["wall_s"], r[metric] * scale), fontsize=7,
                    xytext=(3, 3), textcoords="offset points")
    for k, (name, members) in enumerate(fronts.items()):
        pts = sorted((rows[i]["wall_s"], rows[i][metric] * scale) for i in members)
        if pts:
            ax.plot(*zip(*pts), color=colours[k % len(colours)], marker="o",
                    label="Pareto front" + (f": {name}" if name is not None else ""))
    ax.axvline(reference["wall_s"], color="grey", linestyle="--",
               label=f"reference ({reference['label']}, {reference['wall_s']:.3g} s)")
    if budget and metric in budget:
        ax.axhline(budget[metric] * scale, color="tab:green", linestyle=":", lw=2,
                   label=f"budget: {metric} ≤ {budget[metric] * scale:g}"
                   + ("" if AXIS[metric][1] == "dimensionless" else f" {AXIS[metric][1]}"))
    ax.set_xscale("log")
    if metric in study_fe.LOG_SCALE and shown and all(r[metric] > 0 for r in shown):
        ax.set_yscale("log")  # errors over decades: a horizon far off and the good ones
    ax.set_xlabel("wall time (s)")
    ax.set_ylabel(axis_label(metric))
    ax.set_title(f"{title}: error against wall time" if title else "error against wall time")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path + ".tmp.png", dpi=120)
    plt.close(fig)
    os.replace(path + ".tmp.png", path)


def write_csv(path, rows):
    """study.csv: one row per run (overrides as JSON; peak_source: where peak_mib comes from)."""
    with open(path + ".tmp", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(COLUMNS + ["overrides", "peak_source", "matched_reference"])
        for r in rows:
            w.writerow([r[c] if r[c] is not None else "" for c in COLUMNS]
                       + [json.dumps(r["overrides"]), r.get("peak_source", ""),
                          r.get("matched", "")])
    os.replace(path + ".tmp", path)


def criteria_failures(study, rows):
    """(variant, metric, value, limit) for every criterion a variant misses (an unmeasured
    metric misses too). A value at the limit up to round-off is within it: distances between
    lattice points come out as the limit plus an ulp (0.0008 = 4 spacings of 0.2 mm)."""
    out = []
    for r in rows:
        for metric, limit in study.get("criteria", {}).items():
            value = r[metric]
            if value is None or not value <= limit + 1e-9 * abs(limit):
                out.append((r["label"], metric, value, limit))
    return out


def group_verdicts(study, rows):
    """(variant, passed?, runs passing, runs) per variant (rows grouped by their `group`, a row
    without one alone): it passes when at most a quarter of its runs miss a criterion."""
    groups = {}
    for r in rows:
        groups.setdefault(r.get("group", r["label"]), []).append(r)
    out = []
    for group, members in groups.items():
        passing = sum(1 for r in members if not criteria_failures(study, [r]))
        out.append((group, len(members) - passing <= len(members) // 4, passing, len(members)))
    return out


def perturbed_lines(study, perturbed, failures):
    """study.md's paragraph on the reference's own spread under `perturbed_reference`."""
    if perturbed is None:
        return []
    mine = [f for f in failures if f[0] == perturbed["label"]]
    measured = ", ".join(f"{m} = {fmt(perturbed[m])}" for m in study.get("criteria", {}))
    return ["", f"Reference's own spread ({perturbed['label']}, against the reference): "
            f"{measured}: "
            + ("within every criterion, so the criteria can tell variants apart."
               if not mine else "**a criterion is tighter than the reference's own spread: the "
               "comparison is ill-posed** (choose a scene or an end time whose reference does "
               "not depend on this change).")]


def criteria_lines(study, rows, failures):
    if "criteria" not in study:
        return []
    limits = ", ".join(f"{k} ≤ {v}" for k, v in study["criteria"].items())
    verdicts = group_verdicts(study, rows)
    failed = [g for g, ok, _, _ in verdicts if not ok]
    lines = ["", f"Criteria ({limits}): "
             + ("**all variants pass**." if not failed else "**failed**:"), ""]
    lines += [f"- {g}: {passed} of {total} runs meet every criterion"
              + ("" if ok else " (too few: at most a quarter may miss)")
              for g, ok, passed, total in verdicts if total > 1]
    lines += [f"- {label}: {metric} = {fmt(value)} (limit {limit})"
              for label, metric, value, limit in failures]
    return lines


def spread_lines(members, rows):
    """study.md's paragraph on the reference members and which one each variant matched."""
    if len(members) < 2:
        return []
    listed = "; ".join(f"{m['label']}: {m['row'].get('particles_end')} particles, "
                       f"{m['summary'].get('broken_bonds')} broken bonds" for m in members)
    matched = "; ".join(f"{r['label']}: {r.get('matched')}" for r in rows)
    return ["", f"Reference members (the reference under changes that should not matter): "
            f"{listed}. Each variant's errors are against the member it matches best "
            f"(study_members.py): {matched}."]


def control_lines(study, rows):
    """study.md's line on the controls (`expect: miss`): each must miss a criterion."""
    controls = [r for r in rows if r.get("expect") == "miss"]
    if not controls:
        return []
    lines = []
    for r in controls:
        missed = [m for _, m, _, _ in criteria_failures(study, [r])]
        lines.append(f"- control {r['label']}: "
                     + (f"misses {', '.join(missed)} as it must" if missed else
                        "**meets every criterion: the criteria cannot tell variants apart**"))
    return ["", "Controls that must miss a criterion:", ""] + lines


def variant_lines(rows, ref_row, front, metric):
    """The table of runs: the metrics some run measured (and the plotted one)."""
    shown = [m for m in METRICS if m == metric or any(r.get(m) is not None for r in rows)]
    lines = ["| variant | wall (s) | vs reference | particle-steps | peak MiB | "
             + " | ".join(shown) + " | Pareto |", "|---" * (6 + len(shown)) + "|"]
    for i, r in enumerate(rows):
        speed = ref_row["wall_s"] / r["wall_s"] if r["wall_s"] > 0 else float("nan")
        peak = f"{r['peak_mib']:.0f}" if r.get("peak_mib") is not None else "–"
        lines.append(f"| {r['label']} | {r['wall_s']:.2f} | {speed:.1f}× faster | "
                     f"{r['particle_steps']:.3g} | {peak} | "
                     + " | ".join(fmt(r[m]) for m in shown)
                     + f" | {'yes' if i in front else ''} |")
    return lines


def progress_lines(progress):
    """The line saying how far the study is, and which runs it reused."""
    done, total, reused = progress
    lines = [] if done >= total else [f"**In progress: {done} of {total} variants done.**", ""]
    return lines + ([f"Reused from an earlier study run (completed, same overrides): "
                     f"{', '.join(reused)}.", ""] if reused else [])


def write_outputs(study, rows, ref_row, out, perturbed=None, mirror_spread=None,
                  progress=(0, 0, ()), members=()):
    """study.csv, pareto.png, study.md (and angles.csv) for the rows measured so far; the
    cheapest row within the budget."""
    metric = study.get("error", "angle_deg")
    write_csv(os.path.join(out, "study.csv"), [ref_row] + rows + ([perturbed] if perturbed else []))
    budget = study.get("budget", {})
    by_front = {name: [members[k] for k in pareto_front([rows[i] for i in members], metric)]
                for name, members in study_fronts.groups(rows).items()}
    front = [i for members in by_front.values() for i in members]
    plot_pareto(rows, metric, by_front if len(by_front) > 1 else front, ref_row,
                os.path.join(out, "pareto.png"), budget, study.get("name", "study"))
    best = cheapest_within(rows, budget)
    sources = [r.get("peak_source", "unknown") for r in [ref_row] + rows]
    peak = ", ".join(f"{s}: {sources.count(s)} run(s)" for s in dict.fromkeys(sources))
    lines = [f"# Study: {study.get('name', 'study')}", ""] + progress_lines(progress) + [
        f"Reference: **{ref_row['label']}** ({ref_row['case']}), "
        f"{ref_row['wall_s']:.1f} s, {ref_row['particles_end']} particles.", "",
        f"Peak memory: each engine process's own ({peak}).", ""]
    lines += variant_lines(rows, ref_row, front, metric)
    lines += ["", f"Error plotted: `{metric}`, {axis_label(metric)} (pareto.png).", ""]
    lines += study_fronts.lines(rows, ref_row, by_front,
                                lambda group: cheapest_within(group, budget))
    if "mirror" in study:
        a, b = study["mirror"]["tips"]
        lines += [f"Reference's own tip-path spread ({a} against mirrored {b}): "
                  + (f"{mirror_spread:.4g} m" if mirror_spread is not None else "not measured")
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
    lines += study_fe.lines(study, rows, ref_row)
    checked = rows + ([perturbed] if perturbed else [])
    lines += perturbed_lines(study, perturbed, criteria_failures(study, checked))
    lines += spread_lines(members, rows)
    judged = [r for r in rows if r.get("expect") != "miss"]
    lines += criteria_lines(study, judged, criteria_failures(study, judged))
    lines += control_lines(study, rows)
    lines += ["", "![error against time](pareto.png)", ""]
    with open(os.path.join(out, "study.md.tmp"), "w") as f:
        f.write("\n".join(lines))
    os.replace(os.path.join(out, "study.md.tmp"), os.path.join(out, "study.md"))
    return best
