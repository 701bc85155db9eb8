#!/usr/bin/python3
"""A dhpd run against a finite-element reference of tools/python/fe_reference.py:

  fe_compare.py probe OUT REFERENCE.csv [--probe P] [--plot FILE.png]
                                                      u(t), v(t) of history.csv's probe P
  fe_compare.py field OUT REFERENCE.csv               the last frame's displacement field

prints a JSON map: the RMS difference of each component over the run (probe: at the history's
times up to the reference's end, the reference interpolated linearly in time; field: at the
reference's points: the particle there, or the mean of the equally near ones) divided by the
reference's peak |value|.
"""
import argparse
import csv
import glob
import json
import os
import sys

import numpy as np


def read_reference(path):
    """(column names, rows) of a reference CSV (comment lines start with '#')."""
    with open(path) as f:
        lines = [line for line in f if not line.startswith("#")]
    names = lines[0].strip().split(",")
    return names, np.array([[float(v) for v in line.split(",")] for line in lines[1:]])


def relative_rms(values, reference):
    return float(np.sqrt(np.mean((values - reference) ** 2)) / np.max(np.abs(reference)))


def probe_errors(out, reference, probe="P"):
    _, ref = read_reference(reference)
    with open(os.path.join(out, "history.csv")) as f:
        rows = list(csv.DictReader(f))
    t = np.array([float(r["time"]) for r in rows])
    keep = t <= ref[-1, 0] * (1 + 1e-9)
    result = {}
    for k, axis in ((1, "x"), (2, "y")):
        ours = np.array([float(r[f"{probe}_u{axis}"]) for r in rows])[keep]
        theirs = np.interp(t[keep], ref[:, 0], ref[:, k])
        result[f"u{axis}"] = relative_rms(ours, theirs)
        result[f"peak_u{axis}"] = float(np.max(np.abs(ref[:, k])))
    result["samples"] = int(keep.sum())
    return result


def plot_probe(out, reference, probe, path):
    """u(t) and v(t) of the run's probe over the reference's, one panel each."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    _, ref = read_reference(reference)
    with open(os.path.join(out, "history.csv")) as f:
        rows = list(csv.DictReader(f))
    t = [1e3 * float(r["time"]) for r in rows]
    fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for k, axis in enumerate("xy"):
        axes[k].plot(t, [float(r[f"{probe}_u{axis}"]) for r in rows], label=f"dhpd ({out})")
        axes[k].plot(1e3 * ref[:, 0], ref[:, k + 1], "k--", label="finite elements")
        axes[k].set_ylabel(f"u_{axis} of {probe} (m)")
        axes[k].legend()
    axes[1].set_xlabel("time (ms)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)


def last_frame(out):
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
    frames = sorted(glob.glob(os.path.join(out, "*_[0-9]*.vtu")))
    if not frames:
        sys.exit(f"fe_compare: no frame in {out}")
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(frames[-1])
    reader.Update()
    grid = reader.GetOutput()
    points = vtk_to_numpy(grid.GetPoints().GetData())
    u = vtk_to_numpy(grid.GetPointData().GetArray("displacement"))
    return points, u


def field_errors(out, reference):
    """At each reference point the mean of the particles nearest to it (ties to 1e-6): the
    particle there on the Δx = 0.01 m lattice, the four around it (bilinear) on 0.005 m."""
    from scipy.spatial import cKDTree
    _, ref = read_reference(reference)
    points, u = last_frame(out)
    distance, index = cKDTree(points[:, :2]).query(ref[:, :2], k=4)
    if np.any(distance[:, 0] > 0.01):
        sys.exit(f"fe_compare: reference points farther than 0.01 m from every particle in {out}")
    nearest = distance <= distance[:, :1] * (1 + 1e-6) + 1e-12
    mean = lambda c: (u[index, c] * nearest).sum(axis=1) / nearest.sum(axis=1)
    return {"ux": relative_rms(mean(0), ref[:, 2]), "uy": relative_rms(mean(1), ref[:, 3]),
            "peak_ux": float(np.max(np.abs(ref[:, 2]))), "peak_uy": float(np.max(np.abs(ref[:, 3]))),
            "points": len(ref)}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("kind", choices=["probe", "field"])
    parser.add_argument("out")
    parser.add_argument("reference")
    parser.add_argument("--probe", default="P")
    parser.add_argument("--plot", help="probe: also draw u(t), v(t) over the reference here")
    a = parser.parse_args()
    if a.plot and a.kind == "probe":
        plot_probe(a.out, a.reference, a.probe, a.plot)
    result = probe_errors(a.out, a.reference, a.probe) if a.kind == "probe" else field_errors(
        a.out, a.reference)
    print(json.dumps(result))


if __name__ == "__main__":
    main()
