"""The one reader of a run folder (frames, CSV files, summary.json, densities) for all the tools."""
import csv
import glob
import json
import os
import re
import xml.etree.ElementTree as ElementTree

import numpy as np

EXPECTED = "expected the output directory of a dhpd run, with summary.json and history.csv"
# What plot and report need: a history or frames (a killed or failed run still has them).
EXPECTED_ANY = ("expected the output directory of a dhpd run, with history.csv rows or frames "
                "(written by 'dhpd run SCENE -o DIR')")
CSV_FILES = ("history.csv", "cracks.csv", "refinement.csv")
# refinement.csv's columns that measure wall time: they differ between identical runs.
WALL_COLUMNS = {"seconds", "resort_seconds"}
FRAME_NAME = re.compile(r"_\d+\.vtu$")


class InputError(Exception):
    """A problem with the input directory or arguments: one message, exit code 2."""


# ---- CSV tables ---------------------------------------------------------------------------------


def read_rows(path):
    """Every row of a CSV file as lists of strings, header first; None when it does not exist."""
    if not os.path.exists(path):
        return None
    with open(path, newline="") as f:
        return list(csv.reader(f))


def read_table(path):
    """Header and rows (lists of strings) of a CSV file; None when it does not exist."""
    rows = read_rows(path)
    if rows is None:
        return None
    return (rows[0], rows[1:]) if rows else ([], [])


def read_records(path):
    """The rows of a CSV file as {column: text} maps (blank lines skipped); None when absent."""
    table = read_table(path)
    if table is None:
        return None
    header, rows = table
    return [dict(zip(header, row)) for row in rows if row]


def columns_of(header, rows):
    """Rows of strings by column: name -> array (float, or str if not numeric)."""
    columns = {}
    for k, name in enumerate(header):
        cells = [row[k] if k < len(row) else "" for row in rows]
        try:
            columns[name] = np.array([float(c) for c in cells])
        except ValueError:
            columns[name] = np.array(cells)
    return columns


def read_columns(path):
    """The columns of a CSV file with a header (columns_of); InputError when it is empty."""
    rows = [row for row in read_rows(path) or [] if row]
    if not rows:
        raise InputError(f"{path}: empty (expected a header line and rows)")
    return columns_of(rows[0], rows[1:])


def run_columns(directory, name):
    """A CSV file of the run by column (history.csv, cracks.csv, refinement.csv): {} when the
    file is absent or has no rows."""
    rows = [row for row in read_rows(os.path.join(directory, name)) or [] if row]
    return columns_of(rows[0], rows[1:]) if len(rows) > 1 else {}


# ---- summary.json and the resolved scene --------------------------------------------------------


def load_summary(directory):
    """summary.json as a dict; None when it does not exist (invalid JSON raises ValueError)."""
    path = os.path.join(directory, "summary.json")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        return json.load(f)


def read_summary(directory):
    """summary.json of a run directory; InputError when the directory, the file or its JSON is
    not there."""
    path = os.path.join(directory, "summary.json")
    if not os.path.isdir(directory):
        raise InputError(f"{directory}: no such directory; {EXPECTED}")
    if not os.path.isfile(path):
        raise InputError(f"{path}: missing; {EXPECTED}")
    try:
        return load_summary(directory)
    except json.JSONDecodeError as error:
        raise InputError(f"{path}: not valid JSON ({error})")


def load_scene(directory):
    """The resolved scene (scene.resolved.yaml's first document) and its `derived` map; (None,
    {}) when the file is absent or does not read as YAML maps."""
    import yaml  # only the scene readers need it

    path = os.path.join(directory, "scene.resolved.yaml")
    if not os.path.isfile(path):
        return None, {}
    try:
        with open(path) as f:
            documents = list(yaml.safe_load_all(f))
    except (OSError, yaml.YAMLError):
        return None, {}
    scene = documents[0] if documents and isinstance(documents[0], dict) else None
    derived = documents[1].get("derived", {}) if len(documents) > 1 and isinstance(
        documents[1], dict) else {}
    return scene, derived if isinstance(derived, dict) else {}


def densities(directory):
    """rho of each material in the order of the resolved scene (the frame's material index)."""
    import yaml

    with open(os.path.join(directory, "scene.resolved.yaml")) as f:
        scene = next(yaml.safe_load_all(f))
    return np.array([float(m["rho"]) for m in scene["materials"].values()])


# ---- frames -------------------------------------------------------------------------------------


def read_pvd(path):
    """[(time, frame path)] of a ParaView collection, in file order."""
    try:
        root = ElementTree.parse(path).getroot()
    except ElementTree.ParseError as error:
        raise InputError(f"{path}: not a readable .pvd collection ({error})")
    base = os.path.dirname(path)
    return [(float(d.get("timestep")), os.path.join(base, d.get("file")))
            for d in root.iter("DataSet")]


def pvd_candidates(directory, name):
    """The run's collection: [DIR/NAME.pvd] when it exists, else every .pvd of DIR, sorted."""
    pvd = os.path.join(directory, f"{name}.pvd")
    return [pvd] if os.path.isfile(pvd) else sorted(glob.glob(os.path.join(directory, "*.pvd")))


def has_pvd(directory):
    return any(f.endswith(".pvd") for f in os.listdir(directory))


def frame_files(directory):
    """The .vtu frames of a run by file name (NAME_<k>.vtu), in order."""
    return sorted(f for f in os.listdir(directory) if FRAME_NAME.search(f))


def read_vtu(path):
    """A .vtu frame: ({"points": positions, point array name: values, ...}, {numeric field-data
    name: its first value}); "points" is left out when the file holds none."""
    from vtkmodules import vtkIOXML as vtk_xml  # only frames need VTK
    from vtkmodules.util.numpy_support import vtk_to_numpy

    if not os.path.isfile(path):
        raise InputError(f"{path}: no such frame file")
    reader = vtk_xml.vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    grid = reader.GetOutput()
    arrays = {}
    if grid.GetPoints() is not None:
        arrays["points"] = vtk_to_numpy(grid.GetPoints().GetData())
    data = grid.GetPointData()
    for k in range(data.GetNumberOfArrays()):
        arrays[data.GetArrayName(k)] = vtk_to_numpy(data.GetArray(k))
    fields = {}
    for k in range(grid.GetFieldData().GetNumberOfArrays()):
        array = grid.GetFieldData().GetArray(k)  # None for a non-numeric array
        if array is not None and array.GetNumberOfTuples():
            fields[array.GetName()] = array.GetValue(0)
    return arrays, fields


def read_frame(path):
    """Points and every point-data array of a .vtu frame as numpy arrays."""
    arrays, _ = read_vtu(path)
    if "points" not in arrays:
        raise ValueError(f"{path}: not a readable VTK frame")
    return arrays


def last_frame(directory):
    """The arrays of the run's last frame by file name (read_frame); None without a frame file
    or without a .pvd."""
    frames = frame_files(directory)
    if not frames or not has_pvd(directory):
        return None
    return read_frame(os.path.join(directory, frames[-1]))
