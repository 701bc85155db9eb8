#!/usr/bin/python3
"""Runs one full paper case and checks its summary.json against the published ranges (issue 5).

    check_case.py --dhpd BIN --out DIR CASE.yaml --range KEY MIN MAX [--range ...] [--below KEY KEY]

KEY is a path into summary.json: `particles_end`, `cracks.0.angle_deg`, `cracks.1.initiation_time`,
`cracks.0.branch_times.0`, `rayleigh_speed`. `--below A B` asserts A < B (tip speed below c_R).
These runs take minutes, so they carry the ctest label `verification` and `tools/dhpd test`
leaves them out; run them with `ctest --test-dir build -L verification`.
"""
import argparse
import json
import os
import subprocess
import sys


def value(summary, key):
    node = summary
    for part in key.split("."):
        node = node[int(part)] if isinstance(node, list) else node[part]
    return node


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("case")
    parser.add_argument("--dhpd", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--range", nargs=3, action="append", default=[],
                        metavar=("KEY", "MIN", "MAX"))
    parser.add_argument("--below", nargs=2, action="append", default=[], metavar=("A", "B"))
    args = parser.parse_args()
    run = subprocess.run([args.dhpd, "run", args.case, "--out", args.out, "--quiet"])
    if run.returncode != 0:
        sys.exit(f"{args.case}: dhpd run failed with exit code {run.returncode}")
    with open(os.path.join(args.out, "summary.json")) as f:
        summary = json.load(f)
    failures = []
    for key, lo, hi in args.range:
        v = value(summary, key)
        ok = v is not None and float(lo) <= v <= float(hi)
        print(f"{key} = {v} (allowed {lo} .. {hi}) {'ok' if ok else 'FAILED'}")
        failures += [] if ok else [key]
    for a, b in args.below:
        va, vb = value(summary, a), value(summary, b)
        ok = va is not None and vb is not None and va < vb
        print(f"{a} = {va} < {b} = {vb} {'ok' if ok else 'FAILED'}")
        failures += [] if ok else [a]
    if failures:
        sys.exit(f"{args.case}: out of range: {', '.join(failures)}")


if __name__ == "__main__":
    main()
