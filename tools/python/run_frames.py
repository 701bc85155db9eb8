"""Frames of a run as pictures (plot_run.py, plot_frame.py): one field per particle, 3D sliced."""
import dataclasses
import glob
import os
import re
from dataclasses import dataclass

import matplotlib.pyplot as plt
import numpy as np

import run_folder
from run_data import US, InputError


@dataclass
class Frame:
    """One .vtu frame: reference positions and one field (vectors as magnitudes) per particle."""
    path: str
    field: str
    points: "np.ndarray"
    values: "np.ndarray"
    spacing: "np.ndarray"
    time: float
    step: int
    vector: bool = False
    slice_note: str = ""

    @property
    def dimension(self):
        extent = np.ptp(self.points, axis=0)
        return 3 if extent[2] > 0 else (2 if extent[1] > 0 else 1)

    @property
    def label(self):
        return f"|{self.field}|" if self.vector else self.field


def estimated_spacing(points):
    """For frames without a `spacing` field: the spacing of a lattice filling the bounding box."""
    extent = np.ptp(points, axis=0)
    extent = extent[extent > 0]
    cell = np.prod(extent) / len(points) if extent.size else 1.0
    return np.full(len(points), cell ** (1.0 / max(extent.size, 1)))


def read_frame(path, name):
    """The positions, field `name`, spacing, time and step of a .vtu frame."""
    arrays, fields = run_folder.read_vtu(path)
    if name not in arrays or name == "points":
        names = [k for k in arrays if k != "points"]
        raise InputError(f"{path}: no point field '{name}' (fields: {', '.join(names)})")
    points, values = arrays["points"], arrays[name]
    vector = values.ndim == 2
    if vector:
        values = np.linalg.norm(values, axis=1)
    spacing = arrays["spacing"] if "spacing" in arrays else estimated_spacing(points)
    return Frame(path, name, points, values, spacing, fields.get("TimeValue", float("nan")),
                 int(fields.get("Step", -1)), vector)


def mid_slice(frame):
    """A 3D frame cut to the particles within half a spacing of the mid-thickness plane."""
    if frame.dimension < 3:
        return frame
    z = frame.points[:, 2]
    mid = 0.5 * (z.min() + z.max())
    keep = np.abs(z - mid) <= 0.5 * frame.spacing.max()
    note = f"mid-thickness slice z ≈ {mid:.4g} m ({keep.sum()} of {len(z)} particles)"
    return dataclasses.replace(frame, points=frame.points[keep], values=frame.values[keep],
                               spacing=frame.spacing[keep], slice_note=note)


def particles_figure(frame):
    """A figure and equal axes framing the x-y extent of the particles."""
    pad = frame.spacing.max()
    low, high = frame.points[:, :2].min(axis=0) - pad, frame.points[:, :2].max(axis=0) + pad
    width, height = high - low
    fig, ax = plt.subplots(figsize=(8, max(1.5, 8 * height / width) + 0.8))
    ax.set_xlim(low[0], high[0])
    ax.set_ylim(low[1], high[1])
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    return fig, ax


def draw_particles(fig, ax, frame, **style):
    """The particles as squares as wide as their spacing, coloured by the frame's values."""
    fig.canvas.draw()  # the axes' final size, to turn metres into points
    points_per_metre = ax.get_window_extent().width * 72.0 / fig.dpi / np.diff(ax.get_xlim())[0]
    size = (1.05 * frame.spacing * points_per_metre) ** 2  # scatter sizes are points squared
    return ax.scatter(frame.points[:, 0], frame.points[:, 1], c=frame.values, s=size, marker="s",
                      linewidths=0, **style)


def colour_range(frame):
    """Damage has the fixed scale 0-1, so frames compare; other fields their own range."""
    if frame.field == "damage":
        return 0.0, 1.0
    return float(frame.values.min()), float(frame.values.max())


def frame_title(frame, what):
    title = f"{what} at t = {frame.time * US:.4g} µs (step {frame.step})"
    return title + (f"\n{frame.slice_note}" if frame.slice_note else "")


def save(fig, path):
    """Saves and closes a figure; a temporary name and a rename, so no half-written picture."""
    temporary = path + ".tmp.png"
    fig.savefig(temporary, dpi=110, bbox_inches="tight")
    plt.close(fig)
    os.replace(temporary, path)


def save_field_png(frame, png, title):
    """A picture of the frame's field: x-y particles (1D: the field along x)."""
    vmin, vmax = colour_range(frame)
    if frame.dimension == 1:
        fig, ax = plt.subplots(figsize=(8, 4))
        ax.plot(frame.points[:, 0], frame.values, ".", ms=3)
        ax.set_xlabel("x (m)")
        ax.set_ylabel(frame.label)
        ax.set_ylim(vmin, vmax if vmax > vmin else vmin + 1.0)
    else:
        frame = mid_slice(frame)
        fig, ax = particles_figure(frame)
        artist = draw_particles(fig, ax, frame, cmap="viridis", vmin=vmin, vmax=vmax)
        fig.colorbar(artist, ax=ax, label=frame.label)
    ax.set_title(frame_title(frame, f"{title}: {frame.label}"))
    save(fig, png)
    return frame


def choose_frames(frames, times=None, count=4):
    """Indices into `frames`: the nearest to each time, or `count` spread evenly over them."""
    if times:
        frame_times = np.array([t for t, _ in frames])
        nearest = (int(np.argmin(np.abs(frame_times - t))) for t in times)
        return list(dict.fromkeys(nearest))
    spread = np.linspace(0, len(frames) - 1, min(count, len(frames)))
    return list(dict.fromkeys(int(round(k)) for k in spread))


def plot_frames(run, name="damage", times=None):
    """<name>_<k>.png for the chosen frames; earlier pictures of the field are removed first."""
    if not run.frames:
        return []
    for old in glob.glob(run.path("plots", f"{name}_*.png")):
        if re.fullmatch(rf"{re.escape(name)}_\d+\.png", os.path.basename(old)):
            os.remove(old)
    written = []
    for k, index in enumerate(choose_frames(run.frames, times)):
        png = run.path("plots", f"{name}_{k}.png")
        frame = save_field_png(read_frame(run.frames[index][1], name), png, run.name)
        print(f"wrote {png}: {os.path.basename(frame.path)}, t = {frame.time * US:.4g} µs"
              + (f", {frame.slice_note}" if frame.slice_note else ""))
        written.append(png)
    return written
