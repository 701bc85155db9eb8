#!/usr/bin/python3
"""A dhpd run against a finite-element reference of tools/python/fe_reference.py:

  fe_compare.py probe OUT REFERENCE.csv [--probe P] [--plot FILE.png]
                                                      u(t), v(t) of history.csv's probe P
  fe_compare.py field OUT REFERENCE.csv               the last frame's displacement field

prints a JSON map: the RMS difference of each component over the run (probe: at the history's
times up to the reference's end, the reference interpolated linearly in time; field: at the
reference's points, each the particle there) divided by the reference's peak |value|.
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
    _, ref = read_reference(reference)
    points, u = last_frame(out)
    lookup = {(round(x, 6), round(y, 6)): k for k, (x, y, _) in enumerate(points)}
    missing = [(x, y) for x, y in ref[:, :2] if (round(x, 6), round(y, 6)) not in lookup]
    if missing:
        sys.exit(f"fe_compare: no particle at {len(missing)} reference points, e.g. {missing[0]}")
    at = [lookup[(round(x, 6), round(y, 6))] for x, y in ref[:, :2]]
    return {"ux": relative_rms(u[at, 0], ref[:, 2]), "uy": relative_rms(u[at, 1], ref[:, 3]),
            "peak_ux": float(np.max(np.abs(ref[:, 2]))), "peak_uy": float(np.max(np.abs(ref[:, 3]))),
            "points": len(at)}


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
