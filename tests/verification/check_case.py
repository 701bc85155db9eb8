#!/usr/bin/python3
"""Runs one full paper case and checks its summary.json against the published ranges (issue 5).

    check_case.py --dhpd BIN --out DIR CASE.yaml --range KEY MIN MAX [--range ...] [--below KEY KEY]
                  [--clean-events-before T] [--set KEY=VALUE ...]

KEY is a path into summary.json: `particles_end`, `cracks.0.angle_deg`, `cracks.1.initiation_time`,
`cracks.0.branch_times.0`, `rayleigh_speed`. `--below A B` asserts A < B (tip speed below c_R).
`--clean-events-before T` asserts that at least one refinement event happened before T s and that
none of them started a bond broken (refinement.csv: started_broken and started_overstretched 0).
`--set` passes a scene override to the run (a variant of a shipped case).
These runs take minutes, so they carry the ctest label `verification` and `tools/dhpd test`
leaves them out; run them with `ctest --test-dir build -L verification`.
"""
import argparse
import csv
import json
import os
import subprocess
import sys


def value(summary, key):
    node = summary
    for part in key.split("."):
        node = node[int(part)] if isinstance(node, list) else node[part]
    return node


def clean_events(out, before):
    """Failures unless the events before `before` exist and start no bond broken."""
    with open(os.path.join(out, "refinement.csv")) as f:
        early = [r for r in csv.DictReader(f) if float(r["time"]) < before]
    broken = sum(int(r["started_broken"]) + int(r["started_overstretched"]) for r in early)
    ok = len(early) > 0 and broken == 0
    print(f"events before {before} s: {len(early)}, bonds started broken {broken} "
          f"{'ok' if ok else 'FAILED'}")
    return [] if ok else ["events before initiation"]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("case")
    parser.add_argument("--dhpd", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--range", nargs=3, action="append", default=[],
                        metavar=("KEY", "MIN", "MAX"))
    parser.add_argument("--below", nargs=2, action="append", default=[], metavar=("A", "B"))
    parser.add_argument("--clean-events-before", type=float, metavar="T")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    args = parser.parse_args()
    # --overwrite: a second `ctest -L verification` replaces the previous run of the case.
    overrides = [x for kv in args.set for x in ("--set", kv)]
    run = subprocess.run([args.dhpd, "run", args.case, "--out", args.out, "--quiet", "--overwrite"]
                         + overrides)
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
    if args.clean_events_before is not None:
        failures += clean_events(args.out, args.clean_events_before)
    if failures:
        sys.exit(f"{args.case}: out of range: {', '.join(failures)}")


if __name__ == "__main__":
    main()
