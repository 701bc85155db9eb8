"""The refinement-level map and the contact sheet of the frames (levels.png, contact_sheet.png)."""
import math
import os

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import BoundaryNorm, ListedColormap

from run_data import MM, US, InputError
from run_frames import (UnreadableFrame, choose_frames, draw_particles, draw_scene, frame_axes,
                        frame_box, frame_title, mid_slice, particles_figure, read_frame, save)

SHEET_FRAMES = 12  # frames on the contact sheet, spread evenly over the run
LEVEL_COLOURS = plt.get_cmap("tab10").colors


def level_colours(top):
    """A colour per level 0..top and the norm that maps each integer to its own colour."""
    colours = ListedColormap([LEVEL_COLOURS[k % len(LEVEL_COLOURS)] for k in range(top + 1)])
    return colours, BoundaryNorm(np.arange(-0.5, top + 1.5), top + 1)


def level_frame(run):
    """The last readable frame's `level` (mid-slice in 3D); None without frames or the field."""
    for _, path in reversed(run.frames):
        try:
            return mid_slice(read_frame(path, "level"))
        except UnreadableFrame:
            continue
        except InputError:
            return None
    return None


def level_counts(frame):
    """'level 0: 3458 particles (1 mm), level 1: ...' of a frame."""
    levels = frame.values.astype(int)
    parts = []
    for level in np.unique(levels):
        spacing = frame.spacing[levels == level]
        parts.append(f"level {level}: {int(np.sum(levels == level))} particles "
                     f"(Δx {spacing.min() * MM:.4g} mm)")
    return ", ".join(parts)


def save_level_png(run, png):
    """levels.png: the last frame's particles coloured by refinement level, one colour per
    integer; returns the frame's top level (None without a frame with `level`)."""
    frame = level_frame(run)
    if frame is None or frame.dimension < 2:
        return None
    top = int(frame.values.max())
    colours, norm = level_colours(max(top, 1))
    fig, ax = particles_figure(frame)
    artist = draw_particles(fig, ax, frame, cmap=colours, norm=norm)
    bar = fig.colorbar(artist, ax=ax, ticks=range(max(top, 1) + 1))
    bar.set_label("refinement level (each level halves the spacing)")
    draw_scene(ax, frame, run.scene, legend=False)
    ax.set_title(frame_title(frame, f"{run.name}: refinement level") + "\n" + level_counts(frame),
                 fontsize=9)
    save(fig, png)
    return top


def sheet_frames(run, field, count):
    """The frames of the sheet (mid-sliced), skipping unreadable ones with a note."""
    frames = []
    for index in choose_frames(run.frames, None, count):
        try:
            frames.append(mid_slice(read_frame(run.frames[index][1], field)))
        except UnreadableFrame as error:
            run.notes.append(f"{error}: left off the contact sheet")
    return frames


def sheet_figure(frames):
    """A figure with a grid of equal axes in mm, one per frame, and a colour-bar axes."""
    (x0, x1), (y0, y1) = frame_box(frames[-1])
    aspect = (y1 - y0) / (x1 - x0)
    columns = min(len(frames), 4 if aspect < 1.5 else 6)
    rows = math.ceil(len(frames) / columns)
    width = 3.6
    fig, axes = plt.subplots(rows, columns, squeeze=False,
                             figsize=(columns * width + 1.2, rows * (width * aspect + 0.7) + 0.6))
    fig.subplots_adjust(left=0.06, right=0.9, wspace=0.25, hspace=0.45)
    return fig, axes.ravel(), fig.add_axes([0.92, 0.2, 0.012, 0.6])


def save_contact_sheet(run, png, field="damage", count=SHEET_FRAMES):
    """contact_sheet.png: the field (damage on 0-1) of up to `count` frames spread over the run,
    in one grid, the scene drawn over each; returns how many frames it shows."""
    frames = sheet_frames(run, field, count)
    if not frames or frames[0].dimension < 2:
        return 0
    fig, axes, bar_axes = sheet_figure(frames)
    for ax, frame in zip(axes, frames):
        frame_axes(ax, frame)
    for ax in axes[len(frames):]:
        ax.axis("off")
    fig.canvas.draw()  # the final layout, for the particle sizes
    if field == "damage":
        vmin, vmax = 0.0, 1.0
    else:
        vmin = min(float(f.values.min()) for f in frames)
        vmax = max(float(f.values.max()) for f in frames)
    for ax, frame in zip(axes, frames):
        artist = draw_particles(fig, ax, frame, drawn=True, cmap="viridis", vmin=vmin, vmax=vmax)
        draw_scene(ax, frame, run.scene, legend=False)
        ax.set_title(f"t = {frame.time * US:.4g} µs (step {frame.step})", fontsize=9)
        ax.tick_params(labelsize=7)
        ax.xaxis.label.set_size(8)
        ax.yaxis.label.set_size(8)
    fig.colorbar(artist, cax=bar_axes, label=frames[0].label)
    fig.suptitle(f"{run.name}: {frames[0].label}, {len(frames)} of {len(run.frames)} frames"
                 + (f" ({frames[0].slice_note.split(' (')[0]})" if frames[0].slice_note else ""))
    save(fig, png)
    return len(frames)


def written(png, what):
    print(f"wrote {png}: {what}")
    return os.path.basename(png)
