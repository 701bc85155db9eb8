#!/usr/bin/python3
"""Runs a `dhpd study` with `angles:` and checks orderings of its crack angles (angles.csv).

    check_study_angles.py STUDY --dhpd BIN --out DIR [--window LO HI]
        [--closer MEASURE A B] [--asymmetric MEASURE A B] [--same-particles A B]
        [--report-closer MEASURE A B] [--report-asymmetric MEASURE A B]

A and B name runs by the first word of their study label (`I`, `II`, ...); MEASURE is `final`
(the chord to the last tip, summary.json angle_deg) or `early` (the chord when the tip first lies
the study's early_distance from the notch tip).
  --closer M A B      A's angles are closer to [LO, HI] than B's: the mean over A's tips of the
                      distance of the angle to the window (0 inside) is below B's.
  --asymmetric M A B  |angle(tip 1) − angle(tip 2)| of A is larger than that of B.
  --same-particles A B  A and B ran on the same number of particles (one point set).
  --report-closer, --report-asymmetric  the same comparisons, printed but not asserted: orderings
                      the paper shows that this study does not reproduce on every mesh (the
                      numbers are in cases/README.md and docs/verification.md).
The study takes minutes, so the ctest entry carries the label `verification`.
"""
import argparse
import csv
import os
import subprocess
import sys

MEASURES = {"final": "angle_deg", "early": "early_angle_deg"}


def by_run(path):
    """{first word of the label: [row per tip]} from angles.csv or study.csv."""
    runs = {}
    with open(path) as f:
        for row in csv.DictReader(f):
            runs.setdefault(row["label"].split()[0], []).append(row)
    return runs


def angles(runs, name, measure):
    if name not in runs:
        sys.exit(f"no run labelled '{name}' in the study (runs: {', '.join(runs)})")
    values = [r[MEASURES[measure]] for r in runs[name]]
    if len(values) != 2 or any(v == "" for v in values):
        sys.exit(f"run {name}: expected two tips with a {measure} angle, got {values}")
    return [float(v) for v in values]


def window_distance(values, lo, hi):
    return sum(max(lo - v, 0.0, v - hi) for v in values) / len(values)


def verdict(ok, asserted):
    if asserted:
        return "ok" if ok else "FAILED"
    return "(reported: holds here)" if ok else "(reported: not reproduced)"


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("study")
    parser.add_argument("--dhpd", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--window", nargs=2, type=float, default=[65.0, 70.0])
    parser.add_argument("--closer", nargs=3, action="append", default=[],
                        metavar=("MEASURE", "A", "B"))
    parser.add_argument("--asymmetric", nargs=3, action="append", default=[],
                        metavar=("MEASURE", "A", "B"))
    parser.add_argument("--same-particles", nargs=2, action="append", default=[],
                        metavar=("A", "B"))
    for name in ("--report-closer", "--report-asymmetric"):
        parser.add_argument(name, nargs=3, action="append", default=[],
                            metavar=("MEASURE", "A", "B"))
    args = parser.parse_args()
    for measure, _, _ in (args.closer + args.asymmetric + args.report_closer
                          + args.report_asymmetric):
        if measure not in MEASURES:
            sys.exit(f"measure '{measure}' is not one of {', '.join(MEASURES)}")
    run = subprocess.run([args.dhpd, "study", args.study, "-o", args.out])
    if run.returncode != 0:
        sys.exit(f"{args.study}: dhpd study failed with exit code {run.returncode}")
    runs = by_run(os.path.join(args.out, "angles.csv"))
    table = by_run(os.path.join(args.out, "study.csv"))
    lo, hi = args.window
    failures = []
    checks = [(c, True) for c in args.closer] + [(c, False) for c in args.report_closer]
    for (measure, a, b), asserted in checks:
        da = window_distance(angles(runs, a, measure), lo, hi)
        db = window_distance(angles(runs, b, measure), lo, hi)
        ok = da < db
        print(f"{measure} angles {a} {angles(runs, a, measure)} are {da:.2f}° from [{lo}, {hi}], "
              f"{b} {angles(runs, b, measure)} {db:.2f}°: {a} closer "
              f"{verdict(ok, asserted)}")
        failures += [] if ok or not asserted else [f"{a} closer than {b} ({measure})"]
    checks = [(c, True) for c in args.asymmetric] + [(c, False) for c in args.report_asymmetric]
    for (measure, a, b), asserted in checks:
        (a1, a2), (b1, b2) = angles(runs, a, measure), angles(runs, b, measure)
        ok = abs(a1 - a2) > abs(b1 - b2)
        print(f"{measure} |left − right|: {a} {abs(a1 - a2):.2f}°, {b} {abs(b1 - b2):.2f}°: "
              f"{a} more asymmetric {verdict(ok, asserted)}")
        failures += [] if ok or not asserted else [f"{a} more asymmetric than {b} ({measure})"]
    for a, b in args.same_particles:
        pa, pb = (table[n][0]["particles_end"] if n in table else None for n in (a, b))
        ok = pa is not None and pa == pb
        print(f"particles {a} {pa}, {b} {pb}: one point set {'ok' if ok else 'FAILED'}")
        failures += [] if ok else [f"{a} and {b} on one point set"]
    if failures:
        sys.exit(f"{args.study}: not reproduced: {'; '.join(failures)}")


if __name__ == "__main__":
    main()
