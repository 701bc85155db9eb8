#!/usr/bin/python3
"""Whether two dhpd run folders hold the same results, bit for bit (issue 13: a refactoring must
not change a number).

    tools/python/compare_runs.py DIR_A DIR_B [DIR_A2 DIR_B2 ...]

Compares history.csv, cracks.csv and refinement.csv as text, less the columns that measure wall
time (refinement.csv `seconds`, `resort_seconds`), and every frame: the same
arrays with the same bytes (frames are picked by file name, `NAME_NNNNNN.vtu`). summary.json is
compared without its timing keys and the scene file's path. Prints one line
per pair and every difference found; exits 0 when all pairs are identical, 1 otherwise, 2 when a
folder is missing.
"""
import os
import sys

from run_folder import CSV_FILES, WALL_COLUMNS, frame_files, load_summary, read_frame, read_rows

# Keys that measure the machine or name where the files were, not what was computed.
WALL_KEYS = {"wall_seconds", "seconds_per_phase", "particle_steps_per_second",
             "bond_updates_per_second", "estimated_memory_mb", "peak_memory_mb", "output",
             "scene_file", "allocated_bytes", "bytes_per_particle", "bytes_per_directed_bond"}


def csv_rows(path):
    """The rows of a CSV less its wall-clock columns (None when the file is absent)."""
    rows = read_rows(path)
    if not rows:
        return rows
    keep = [k for k, name in enumerate(rows[0]) if name not in WALL_COLUMNS]
    return [[r[k] for k in keep if k < len(r)] for r in rows]


def summary_without_timing(directory):
    s = load_summary(directory)
    return None if s is None else {k: v for k, v in s.items() if k not in WALL_KEYS}


def frame_differences(a, b):
    """Differences between the frames of two runs (names and arrays, byte for byte)."""
    fa, fb = frame_files(a), frame_files(b)
    if fa != fb:
        return [f"frames differ: {len(fa)} against {len(fb)}"]
    out = []
    for name in fa:
        x = read_frame(os.path.join(a, name))
        y = read_frame(os.path.join(b, name))
        if sorted(x) != sorted(y):
            out.append(f"{name}: arrays {sorted(x)} against {sorted(y)}")
            continue
        for key in x:
            if x[key].shape != y[key].shape or x[key].tobytes() != y[key].tobytes():
                out.append(f"{name}: array '{key}' differs")
    return out


def differences(a, b):
    out = []
    for name in CSV_FILES:
        ra, rb = csv_rows(os.path.join(a, name)), csv_rows(os.path.join(b, name))
        if ra != rb:
            first = next((k for k, (p, q) in enumerate(zip(ra or [], rb or [])) if p != q), None)
            out.append(f"{name} differs" + (f" (first at row {first})" if first is not None
                                            else " (presence or length)"))
    if summary_without_timing(a) != summary_without_timing(b):
        out.append("summary.json differs (timing keys left out)")
    return out + frame_differences(a, b)


def main(argv):
    if len(argv) < 2 or len(argv) % 2:
        sys.stderr.write(__doc__)
        return 2
    bad = 0
    for a, b in zip(argv[0::2], argv[1::2]):
        for d in (a, b):
            if not os.path.isdir(d):
                sys.stderr.write(f"compare_runs: no folder '{d}'\n")
                return 2
        diff = differences(a, b)
        print(f"{'identical' if not diff else 'DIFFERENT'}: {a} {b}")
        for line in diff:
            print(f"  {line}")
        bad += 1 if diff else 0
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
