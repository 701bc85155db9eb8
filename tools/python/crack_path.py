"""crack_path.png and the report's branch tables: every traced branch, branch points, times."""
import numpy as np
import matplotlib.pyplot as plt

import crack_branches
import run_folder
import run_overlay
from run_data import MM, US
from run_frames import (UnreadableFrame, choose_frames, draw_particles, draw_scene, frame_title,
                        mid_slice, particles_figure, read_frame, save)

TIME_FRAMES = 40  # frames read (spread over the run) to date the nodes of the traced cracks
TIME_LABELS = 5  # tip positions of cracks.csv labelled with their time
COLOURS = plt.get_cmap("tab10").colors


def settings(run):
    """(damage threshold, branch separation, tips) of the scene's `measure`; without a scene
    the tips of cracks.csv, each at its first position."""
    measure = (run.scene or {}).get("measure") or {}
    tips = measure.get("tips") or []
    if not tips and run.cracks is not None:
        names = [str(t) for t in run.cracks["tip"]]
        first = {n: names.index(n) for n in dict.fromkeys(names)}
        tips = [{"name": n, "at": [run.cracks["x"][k], run.cracks["y"][k]]}
                for n, k in first.items()]
    return (float(measure.get("damage_threshold", 0.35)),
            float(measure.get("branch_separation", 2.0)), tips)


def damaged(path, threshold):
    """x-y positions, spacing and horizon of a frame's particles damaged to `threshold`."""
    arrays, _ = run_folder.read_vtu(path)
    if "points" not in arrays or "damage" not in arrays or len(arrays["points"]) == 0:
        raise UnreadableFrame(f"{path}: not a readable VTK frame with damage")
    keep = arrays["damage"] >= threshold
    spacing = arrays.get("spacing", np.full(len(keep), np.nan))[keep]
    horizon = arrays["horizon"][keep] if "horizon" in arrays else 3.015 * spacing
    return arrays["points"][keep, :2], spacing, horizon


def traced(run):
    """The Crack of each tip, traced in the last readable frame and dated by the frames."""
    threshold, separation, tips = settings(run)
    if not run.frames or not tips:
        return []
    dated = []
    for index in choose_frames(run.frames, None, TIME_FRAMES):
        try:
            dated.append((run.frames[index][0],) + damaged(run.frames[index][1], threshold))
        except UnreadableFrame:
            continue
    if not dated:
        return []
    _, points, spacing, horizon = dated[-1]
    cracks = [crack_branches.trace(points, spacing, horizon, tip, separation) for tip in tips]
    for crack in cracks:
        if crack.centroids:
            crack_branches.set_times(crack, [(t, p, s) for t, p, s, _ in dated])
    return cracks


def line_times(crack, line):
    times = [crack.times[n] for n in line if n >= 0 and np.isfinite(crack.times[n])]
    return (min(times), max(times)) if times else (np.nan, np.nan)


def branch_rows(cracks):
    """Report rows: [tip, branch, from (mm), to (mm), times (µs)] and [tip, branch point (mm),
    time (µs)]."""
    def mm(p):
        return f"({p[0] * MM:.1f}, {p[1] * MM:.1f})"
    branches, points = [], []
    for crack in cracks:
        lines, nodes = crack_branches.branches(crack)
        for k, line in enumerate(lines):
            t0, t1 = line_times(crack, line)
            branches.append([crack.tip, str(k + 1), mm(crack_branches.position(crack, line[0])),
                             mm(crack_branches.position(crack, line[-1])),
                             f"{t0 * US:.3g} – {t1 * US:.3g}"])
        for node in nodes:
            points.append([crack.tip, mm(crack_branches.position(crack, node)),
                           f"{crack_branches.branch_time(crack, node) * US:.3g}"])
    return branches, points


def draw_traced(ax, cracks):
    colour, marked = 0, False
    for crack in cracks:
        lines, nodes = crack_branches.branches(crack)
        for k, line in enumerate(lines):
            xy = np.array([crack_branches.position(crack, n) for n in line]) * MM
            t0, t1 = line_times(crack, line)
            ax.plot(xy[:, 0], xy[:, 1], "-", lw=2.2, color=COLOURS[colour % 10], zorder=7,
                    label=f"{crack.tip} branch {k + 1}: {t0 * US:.3g}–{t1 * US:.3g} µs")
            colour += 1
        for node in nodes:
            p = crack_branches.position(crack, node) * MM
            ax.plot(*p, "D", color="black", ms=7, zorder=9,
                    label=None if marked else "branch point (traced), its time")
            marked = True
            ax.annotate(f"{crack_branches.branch_time(crack, node) * US:.3g} µs", p,
                        xytext=(-52, 8), textcoords="offset points", fontsize=8, zorder=10,
                        bbox={"fc": "white", "ec": "black", "lw": 0.5, "pad": 1.5})


def draw_measured(ax, cracks_csv):
    """The tip positions of cracks.csv (a few labelled with their time) and the measurements at
    which the branch count rose (stars with their time)."""
    names = np.array([str(t) for t in cracks_csv["tip"]])
    branches, starred = cracks_csv.get("branches"), False
    for k, tip in enumerate(dict.fromkeys(names)):
        rows = names == tip
        x, y, t = cracks_csv["x"][rows] * MM, cracks_csv["y"][rows] * MM, cracks_csv["time"][rows]
        ax.plot(x, y, ".", ms=3, color="tab:gray", zorder=6,
                label="tip of cracks.csv, time (µs)" if k == 0 else None)
        moved = np.nonzero(np.hypot(x - x[0], y - y[0]) > 0)[0]
        for i in moved[np.linspace(0, len(moved) - 1, min(TIME_LABELS, len(moved))).astype(int)]:
            ax.annotate(f"{t[i] * US:.3g}", (x[i], y[i]), xytext=(-4, -11),
                        textcoords="offset points", fontsize=7, color="dimgray")
        most = 1
        for i in range(len(x)) if branches is not None else ():
            if branches[rows][i] > most:
                most = branches[rows][i]
                ax.plot(x[i], y[i], "*", color="gold", mec="black", ms=12, zorder=9,
                        label=None if starred else "branch count rose (cracks.csv)")
                starred = True
                ax.annotate(f"{t[i] * US:.3g} µs → {int(most)}", (x[i], y[i]), xytext=(6, -14),
                            textcoords="offset points", fontsize=8, zorder=10)


def background(run):
    """A figure with the last readable frame's damage in grey (and the scene), or empty axes."""
    for _, path in reversed(run.frames):
        try:
            frame = mid_slice(read_frame(path, "damage"))
        except UnreadableFrame:
            continue
        fig, ax = particles_figure(frame)
        draw_particles(fig, ax, frame, cmap="Greys", vmin=0.0, vmax=1.0, alpha=0.5)
        draw_scene(ax, frame, run.scene, legend=False)
        return fig, ax, frame_title(frame, f"{run.name}: crack branches over the damage")
    fig, ax = plt.subplots(figsize=(8, 6))
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    return fig, ax, f"{run.name}: crack tips (no frame to draw under them)"


def plot_crack_path(run, png):
    """crack_path.png: the traced branches (times from the frames), branch points, the tip path
    of cracks.csv with times, the measured branchings."""
    fig, ax, title = background(run)
    cracks = traced(run)
    draw_traced(ax, cracks)
    draw_measured(ax, run.cracks)
    ax.set_title(title + "\ntraced branches: damage ≥ the measure's threshold, in bins of path "
                 "distance one horizon wide", fontsize=9)
    run_overlay.legend_below(ax, 2)
    save(fig, png)
    return cracks
