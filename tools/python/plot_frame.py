#!/usr/bin/python3
"""Render one point field of a dhpd .vtu frame to a PNG (2D scenes: x-y particles coloured by the
field, damage on a fixed 0-1 scale; 3D: the particles of the mid-thickness slice; 1D: the field
along x). The drawing is run_frames.py's, which `dhpd plot` (plot_run.py) uses for whole runs.

    /usr/bin/python3 tools/python/plot_frame.py out/branching_plate_uniform_000020.vtu damage out/damage.png
"""
import argparse
import os
import sys

import plot_run  # noqa: F401 (stops with the Debian package's name when a module is missing)
from run_data import InputError
from run_frames import read_frame, save_field_png


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("vtu")
    parser.add_argument("field")
    parser.add_argument("png")
    args = parser.parse_args()
    try:
        frame = read_frame(args.vtu, args.field)
    except InputError as error:
        print(f"dhpd: error: {error}", file=sys.stderr)
        return 2
    save_field_png(frame, args.png, os.path.basename(args.vtu))
    return 0


if __name__ == "__main__":
    sys.exit(main())
