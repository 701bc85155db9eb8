#!/usr/bin/python3
"""The velocity of a wave at each of its returns against a reference run (CMES 2019 §3, the
multi-horizon paper's bar; issue 19):

  wave_returns.py REFERENCE RUN [RUN ...] [--labels A B ...] [--json]

Each run's frames after the first are the returns (the bar case writes one frame per return,
at the same times in every run). At each return k the error of a run is
max_x |v(x) − v_ref(x)| / max_x |v_ref(x)| over the reference's particles, v of the run
interpolated linearly to them; the table has one column per run. --json prints
{label: [e_1, e_2, ...]} instead.
"""
import argparse
import glob
import json
import os
import sys

import numpy as np

import run_folder


def frames(run):
    """[(time, x sorted, v along x)] of a run's .pvd frames."""
    pvds = sorted(glob.glob(os.path.join(run, "*.pvd")))
    if not pvds:
        sys.exit(f"wave_returns: no .pvd collection in {run}")
    out = []
    for time, path in run_folder.read_pvd(pvds[0]):
        arrays = run_folder.read_frame(path)
        x = arrays["points"][:, 0]
        v = arrays["velocity"]
        v = v[:, 0] if v.ndim > 1 else v
        order = np.argsort(x)
        out.append((time, x[order], v[order]))
    return out


def return_errors(reference, run):
    """The error at each return (frames 1, 2, ...) of `run` against `reference`."""
    ref, own = frames(reference), frames(run)
    if len(own) != len(ref):
        sys.exit(f"wave_returns: {run} has {len(own)} frames, the reference {len(ref)}")
    errors = []
    for (t_ref, x_ref, v_ref), (t, x, v) in zip(ref[1:], own[1:]):
        if abs(t - t_ref) > 1e-9 * max(abs(t_ref), 1e-30) + 1e-15:
            sys.exit(f"wave_returns: frame at t = {t:.9g} s in {run}, {t_ref:.9g} s in the reference")
        errors.append(float(np.max(np.abs(np.interp(x_ref, x, v) - v_ref)) /
                            np.max(np.abs(v_ref))))
    return errors


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("reference")
    parser.add_argument("runs", nargs="+")
    parser.add_argument("--labels", nargs="*")
    parser.add_argument("--json", action="store_true")
    a = parser.parse_args()
    labels = a.labels or [os.path.basename(os.path.normpath(r)) for r in a.runs]
    if len(labels) != len(a.runs):
        sys.exit("wave_returns: one label per run")
    table = {label: return_errors(a.reference, run) for label, run in zip(labels, a.runs)}
    if a.json:
        print(json.dumps(table))
        return
    print("return | " + " | ".join(labels))
    for k in range(len(next(iter(table.values())))):
        print(f"{k + 1:6d} | " + " | ".join(f"{100 * table[l][k]:6.2f} %" for l in labels))


if __name__ == "__main__":
    main()
