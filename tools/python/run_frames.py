"""Frames of a run as pictures (plot_run.py, plot_frame.py): one field per particle, 3D sliced."""
import dataclasses
import glob
import os
import re
from dataclasses import dataclass

import matplotlib.pyplot as plt
import numpy as np

import run_folder
import run_overlay
from run_data import MM, US, InputError

try:  # a truncated frame makes VTK print a page of errors; read_frame says it in one line
    from vtkmodules.vtkCommonCore import vtkObject
    vtkObject.GlobalWarningDisplayOff()
except ImportError:
    pass


class UnreadableFrame(Exception):
    """A frame file VTK cannot read (e.g. truncated by a full disk): skipped with a note."""


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
    z: float = 0.0  # the plane of a 3D frame's slice, m

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
    if "points" not in arrays or len(arrays["points"]) == 0:
        raise UnreadableFrame(f"{path}: not a readable VTK frame (truncated or empty)")
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
    note = f"mid-thickness slice z ≈ {mid * MM:.4g} mm ({keep.sum()} of {len(z)} particles)"
    return dataclasses.replace(frame, points=frame.points[keep], values=frame.values[keep],
                               spacing=frame.spacing[keep], slice_note=note, z=mid)


def frame_box(frame):
    """((x0, x1), (y0, y1)) of the particles padded by a spacing, m."""
    pad = frame.spacing.max()
    low, high = frame.points[:, :2].min(axis=0) - pad, frame.points[:, :2].max(axis=0) + pad
    return (low[0], high[0]), (low[1], high[1])


def frame_axes(ax, frame):
    """Equal x-y axes in mm framing the particles."""
    (x0, x1), (y0, y1) = frame_box(frame)
    ax.set_xlim(x0 * MM, x1 * MM)
    ax.set_ylim(y0 * MM, y1 * MM)
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")


def particles_figure(frame):
    """A figure and equal axes in mm framing the x-y extent of the particles."""
    (x0, x1), (y0, y1) = frame_box(frame)
    fig, ax = plt.subplots(figsize=(8, max(1.5, 8 * (y1 - y0) / (x1 - x0)) + 0.8))
    frame_axes(ax, frame)
    return fig, ax


def draw_particles(fig, ax, frame, drawn=False, **style):
    """The particles as squares as wide as their spacing, coloured by the frame's values
    (`drawn`: the figure's layout is final and drawn already)."""
    if not drawn:
        fig.canvas.draw()  # the axes' final size, to turn millimetres into points
    points_per_mm = ax.get_window_extent().width * 72.0 / fig.dpi / np.diff(ax.get_xlim())[0]
    size = (1.05 * frame.spacing * MM * points_per_mm) ** 2  # scatter sizes are points squared
    return ax.scatter(frame.points[:, 0] * MM, frame.points[:, 1] * MM, c=frame.values, s=size,
                      marker="s", linewidths=0, **style)


def draw_scene(ax, frame, scene, legend=True):
    """The scene's pre-cracks and regions over a frame's picture (run_overlay)."""
    return run_overlay.draw_scene(ax, scene, frame_box(frame), frame.z, legend)


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


def save_field_png(frame, png, title, scene=None):
    """A picture of the frame's field: x-y particles with the scene drawn over them (1D: the
    field along x)."""
    vmin, vmax = colour_range(frame)
    if frame.dimension == 1:
        fig, ax = plt.subplots(figsize=(8, 4))
        ax.plot(frame.points[:, 0] * MM, frame.values, ".", ms=3)
        ax.set_xlabel("x (mm)")
        ax.set_ylabel(frame.label)
        ax.set_ylim(vmin, vmax if vmax > vmin else vmin + 1.0)
    else:
        frame = mid_slice(frame)
        fig, ax = particles_figure(frame)
        artist = draw_particles(fig, ax, frame, cmap="viridis", vmin=vmin, vmax=vmax)
        fig.colorbar(artist, ax=ax, label=frame.label)
        draw_scene(ax, frame, scene)
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


def times_notes(frames, times):
    """Notes for --times that lie outside the frames' span (the nearest frame is drawn)."""
    known = [t for t, _ in frames if np.isfinite(t)]
    if not times or not known:
        return []
    first, last = min(known), max(known)
    gap = (last - first) / max(len(known) - 1, 1)
    return [f"--times {t:g} s lies outside the frames ({first:.4g} to {last:.4g} s): the nearest "
            "frame is drawn" for t in times if t < first - gap or t > last + gap]


def plot_frames(run, name="damage", times=None):
    """<name>_<k>.png for the chosen frames; earlier pictures of the field are removed first;
    an unreadable frame is skipped with a note."""
    if not run.frames:
        return []
    for old in glob.glob(run.path("plots", f"{name}_*.png")):
        if re.fullmatch(rf"{re.escape(name)}_\d+\.png", os.path.basename(old)):
            os.remove(old)
    run.notes += times_notes(run.frames, times)
    written = []
    for index in choose_frames(run.frames, times):
        png = run.path("plots", f"{name}_{len(written)}.png")
        try:
            frame = read_frame(run.frames[index][1], name)
        except UnreadableFrame as error:
            run.notes.append(f"{error}: skipped")
            continue
        frame = save_field_png(frame, png, run.name, run.scene)
        print(f"wrote {png}: {os.path.basename(frame.path)}, t = {frame.time * US:.4g} µs"
              + (f", {frame.slice_note}" if frame.slice_note else ""))
        written.append(png)
    return written
