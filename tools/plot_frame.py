#!/usr/bin/python3
"""Render one point field of a dhpd .vtu frame to a PNG (2D scenes: x-y scatter coloured by the
field; 3D: the particles in a slab around z = mid). Uses Debian's python3-vtk9 and matplotlib.

    /usr/bin/python3 tools/plot_frame.py out/cracked-plate_000020.vtu damage out/damage.png
"""
import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from vtk import vtkXMLUnstructuredGridReader  # noqa: E402
from vtk.util.numpy_support import vtk_to_numpy  # noqa: E402


def read(path, field):
    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    grid = reader.GetOutput()
    points = vtk_to_numpy(grid.GetPoints().GetData())
    array = grid.GetPointData().GetArray(field)
    if array is None:
        names = [grid.GetPointData().GetArrayName(k) for k in range(grid.GetPointData().GetNumberOfArrays())]
        raise SystemExit(f"{path}: no point field '{field}' (fields: {', '.join(names)})")
    values = vtk_to_numpy(array)
    if values.ndim == 2:
        values = np.linalg.norm(values, axis=1)
    time = grid.GetFieldData().GetArray("TimeValue")
    spacing = grid.GetPointData().GetArray("spacing")
    spacing = vtk_to_numpy(spacing) if spacing is not None else None
    return points, values, spacing, (time.GetValue(0) if time is not None else float("nan"))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("vtu")
    parser.add_argument("field")
    parser.add_argument("png")
    args = parser.parse_args()
    points, values, spacing, time = read(args.vtu, args.field)
    if spacing is None:
        spacing = np.full(len(points), np.sqrt(np.ptp(points[:, 0]) * max(np.ptp(points[:, 1]), 1e-12) / len(points)))
    if np.ptp(points[:, 2]) > 0:
        mid = 0.5 * (points[:, 2].min() + points[:, 2].max())
        keep = np.abs(points[:, 2] - mid) <= 0.5 * spacing.max()
        points, values, spacing = points[keep], values[keep], spacing[keep]
    width = np.ptp(points[:, 0]) + spacing.max()
    height = max(np.ptp(points[:, 1]), 0.0) + spacing.max()
    fig, ax = plt.subplots(figsize=(8, max(1.5, 8 * height / width) + 0.8))
    ax.set_xlim(points[:, 0].min() - spacing.max(), points[:, 0].max() + spacing.max())
    ax.set_ylim(points[:, 1].min() - spacing.max(), points[:, 1].max() + spacing.max())
    ax.set_aspect("equal")
    fig.canvas.draw()
    # Marker side = particle spacing, in points (scatter sizes are points squared).
    points_per_metre = ax.get_window_extent().width * 72.0 / fig.dpi / np.diff(ax.get_xlim())[0]
    size = (1.05 * spacing * points_per_metre) ** 2
    sc = ax.scatter(points[:, 0], points[:, 1], c=values, s=size, cmap="viridis", marker="s", linewidths=0)
    fig.colorbar(sc, ax=ax, label=args.field)
    ax.set_title(f"{args.vtu}  t = {time:.4g} s")
    fig.savefig(args.png, dpi=110, bbox_inches="tight")


if __name__ == "__main__":
    main()
