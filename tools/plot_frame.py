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
    return points, values, (time.GetValue(0) if time is not None else float("nan"))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("vtu")
    parser.add_argument("field")
    parser.add_argument("png")
    args = parser.parse_args()
    points, values, time = read(args.vtu, args.field)
    if np.ptp(points[:, 2]) > 0:
        mid = 0.5 * (points[:, 2].min() + points[:, 2].max())
        keep = np.abs(points[:, 2] - mid) <= 0.05 * np.ptp(points[:, 2])
        points, values = points[keep], values[keep]
    fig, ax = plt.subplots(figsize=(8, 8 * max(np.ptp(points[:, 1]), 1e-9) / max(np.ptp(points[:, 0]), 1e-9) + 1))
    size = max(0.5, 4e4 / len(points))
    sc = ax.scatter(points[:, 0], points[:, 1], c=values, s=size, cmap="viridis", marker="s", linewidths=0)
    fig.colorbar(sc, ax=ax, label=args.field)
    ax.set_aspect("equal")
    ax.set_title(f"{args.vtu}  t = {time:.4g} s")
    fig.savefig(args.png, dpi=110, bbox_inches="tight")


if __name__ == "__main__":
    main()
