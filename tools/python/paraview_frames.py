"""Headless ParaView pictures of a dhpd run: Point Gaussian particles, warp, damage and levels."""
# Run with ParaView's pvbatch (or pvpython); Debian's ParaView 5.11 has neither EGL nor OSMesa, so
# it needs an X server: `xvfb-run -a pvbatch tools/python/paraview_frames.py OUT`. Debian 12's
# python3-paraview conflicts with python3-vtk9 (which dhpd plot needs): unpacked instead of
# installed, it is found with --paraview-python DIR or $DHPD_PARAVIEW_PYTHON (docs/outputs.md).
#
#   xvfb-run -a pvbatch tools/python/paraview_frames.py OUT [--frames first,last | all | 0,5,9]
#       [--times T1,T2] [--warp SCALE] [--width PIXELS] [--field damage] [--disc circle|square]
#       [--radius 0.7071] [--png-dir DIR] [--paraview-python DIR]
#
# Opens OUT's .pvd (NAME.pvd of the scene, else the only .pvd), warps the particles by
# `displacement` (times --warp, default 1), draws each particle as a Point Gaussian splat scaled
# by its `spacing`: a disc of radius --radius × spacing (default 1/√2: the circle through the
# corners of the particle's cell, so neighbouring discs leave no gap; 0.5, touching discs,
# leaves a gap at every cell corner, which shows as moiré streaks), or with --disc square the
# particle's cell itself (half-width spacing / 2, tiling the lattice exactly), and writes per
# chosen frame DIR/damage_NNNNNN.png (damage on a fixed 0-1 scale, Viridis) and, when the frames
# carry `level`, DIR/level_NNNNNN.png (one colour per refinement level, the colours of dhpd
# plot's levels.png); NNNNNN is the frame's index in the .pvd. A text line gives the run, t in
# µs, the frame and the warp. The camera frames the undeformed body (a large --warp may leave
# it). DIR defaults to OUT/paraview. Exit code 2 for a folder without a .pvd or a bad option.
import argparse
import glob
import os
import sys
import xml.etree.ElementTree as ElementTree

LEVEL_COLOURS = [(0.12, 0.47, 0.71), (1.0, 0.5, 0.05), (0.17, 0.63, 0.17), (0.84, 0.15, 0.16),
                 (0.58, 0.4, 0.74), (0.55, 0.34, 0.29), (0.89, 0.47, 0.76), (0.5, 0.5, 0.5)]


def fail(message):
    sys.stderr.write(f"paraview_frames.py: error: {message}\n")
    sys.exit(2)


def find_pvd(directory):
    """NAME.pvd of the scene the run's summary names, else the only .pvd of the folder."""
    if not os.path.isdir(directory):
        fail(f"{directory}: no such directory (expected a dhpd run's output folder)")
    found = sorted(glob.glob(os.path.join(directory, "*.pvd")))
    summary = os.path.join(directory, "summary.json")
    if os.path.isfile(summary):
        import json
        try:
            with open(summary) as f:
                named = os.path.join(directory, f"{json.load(f).get('scene')}.pvd")
            if named in found:
                return named
        except ValueError:
            pass
    if len(found) != 1:
        fail(f"{directory}: {'no' if not found else 'more than one'} .pvd file (expected the "
             "frames of one dhpd run)")
    return found[0]


def pvd_times(pvd):
    """The frames' times of a .pvd, in file order."""
    try:
        root = ElementTree.parse(pvd).getroot()
    except ElementTree.ParseError as error:
        fail(f"{pvd}: not a readable .pvd ({error})")
    return [float(d.get("timestep")) for d in root.iter("DataSet")]


def chosen(times, frames, wanted_times):
    """Indices of the frames to render: --times (the nearest frames) or --frames."""
    if not times:
        fail("the .pvd lists no frames")
    if wanted_times:
        return list(dict.fromkeys(min(range(len(times)), key=lambda k: abs(times[k] - t))
                                  for t in wanted_times))
    picks = []
    for word in frames.split(","):
        word = word.strip()
        if word == "all":
            picks += range(len(times))
        elif word in ("first", "last"):
            picks.append(0 if word == "first" else len(times) - 1)
        elif word.lstrip("-").isdigit() and -len(times) <= int(word) < len(times):
            picks.append(int(word) % len(times))
        else:
            fail(f"--frames: '{word}' is not first, last, all or a frame index below {len(times)}")
    return list(dict.fromkeys(picks))


def parse(argv):
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("directory", help="a dhpd run's output folder")
    parser.add_argument("--frames", default="first,last",
                        help="first, last, all or frame indices, by commas (default first,last)")
    parser.add_argument("--times", help="render the frames nearest these times, s: T1,T2,...")
    parser.add_argument("--warp", type=float, default=1.0,
                        help="displacement scale factor of the warp (default 1: true shape)")
    parser.add_argument("--width", type=int, default=1600, help="picture width, pixels")
    parser.add_argument("--field", default="damage", help="the colour of the first view")
    parser.add_argument("--disc", choices=("circle", "square"), default="circle",
                        help="splat shape: a disc (default) or the particle's square cell")
    parser.add_argument("--radius", type=float, default=0.7071,
                        help="disc radius over spacing (default 0.7071 = 1/√2: no gaps)")
    parser.add_argument("--png-dir", help="where the PNGs go (default OUT/paraview)")
    parser.add_argument("--paraview-python", default=os.environ.get("DHPD_PARAVIEW_PYTHON"),
                        help="dist-packages of an unpacked python3-paraview (default: "
                        "$DHPD_PARAVIEW_PYTHON; none: the installed one)")
    args = parser.parse_args(argv)
    try:
        args.times = [float(t) for t in args.times.split(",")] if args.times else None
    except ValueError:
        fail(f"--times: expected times in s separated by commas, got '{args.times}'")
    return args


def import_paraview(directory):
    """paraview.simple, from `directory` (an unpacked python3-paraview's dist-packages) first
    when given: Debian 12's python3-paraview conflicts with python3-vtk9, which dhpd plot needs,
    so it may be unpacked beside it instead of installed (docs/outputs.md)."""
    if directory:
        if not os.path.isdir(os.path.join(directory, "paraview")):
            fail(f"--paraview-python {directory}: no paraview package there")
        sys.path.insert(0, directory)
        for name in [m for m in sys.modules if m == "vtkmodules" or m.startswith("vtkmodules.")]:
            del sys.modules[name]  # VTK's own Python modules, not ParaView's
    try:
        import paraview.simple as pv
    except ImportError as error:
        fail(f"ParaView's Python modules are missing ({error}): run this script with pvbatch or "
             "pvpython, with Debian's python3-paraview installed or unpacked (--paraview-python; "
             "docs/outputs.md)")
    return pv


def point_arrays(reader):
    return [reader.PointData.GetArray(k).Name
            for k in range(reader.PointData.GetNumberOfArrays())]


def particles(pv, source, view, arrays, args, spacing):
    """Shows `source` as Point Gaussian discs of radius args.radius × spacing (or squares of
    half-width spacing / 2); `spacing` (m) for frames without the field."""
    shown = pv.Show(source, view)
    shown.SetRepresentationType("Point Gaussian")
    shown.ShaderPreset = "Plain circle"
    factor = args.radius
    if args.disc == "square":  # a quad twice the radius, cut to |offset| <= radius
        shown.ShaderPreset = "Custom"
        shown.CustomTriangleScale = 2
        shown.CustomShader = ("//VTK::Color::Impl\n"
                              "if (abs(offsetVCVSOutput.x) > 1.0 || abs(offsetVCVSOutput.y) > 1.0)"
                              " { discard; }\n")
        factor = 0.5
    if "spacing" in arrays:
        shown.ScaleByArray = 1
        shown.SetScaleArray = ["POINTS", "spacing"]
        shown.UseScaleFunction = 0
        shown.GaussianRadius = factor
    else:
        shown.GaussianRadius = factor * spacing
    return shown


def damage_colours(pv, shown, view, field):
    pv.ColorBy(shown, ("POINTS", field))
    lut = pv.GetColorTransferFunction(field)
    lut.ApplyPreset("Viridis (matplotlib)", True)
    if field == "damage":
        lut.AutomaticRescaleRangeMode = "Never"
        lut.RescaleTransferFunction(0.0, 1.0)
    shown.SetScalarBarVisibility(view, True)
    bar = pv.GetScalarBar(lut, view)
    bar.Title, bar.ComponentTitle = field, ""
    bar.TitleColor = bar.LabelColor = [0.0, 0.0, 0.0]
    bar.AutomaticLabelFormat = 0
    bar.LabelFormat = bar.RangeLabelFormat = "%-#.2g"


def level_colours(pv, shown, view, top):
    """Colour by `level` with one colour per integer 0..top (categories)."""
    pv.ColorBy(shown, ("POINTS", "level"))
    lut = pv.GetColorTransferFunction("level")
    lut.InterpretValuesAsCategories = 1
    lut.Annotations = [str(v) for k in range(top + 1) for v in (k, f"level {k}")]
    lut.IndexedColors = [c for k in range(top + 1) for c in LEVEL_COLOURS[k % len(LEVEL_COLOURS)]]
    shown.SetScalarBarVisibility(view, True)
    bar = pv.GetScalarBar(lut, view)
    bar.Title, bar.ComponentTitle = "refinement level", ""
    bar.TitleColor = bar.LabelColor = [0.0, 0.0, 0.0]


def render_view(pv, size, flat):
    view = pv.CreateRenderView()
    view.ViewSize = size
    view.Background = [1.0, 1.0, 1.0]
    try:
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass
    view.OrientationAxesVisibility = 0 if flat else 1
    if flat:
        view.InteractionMode = "2D"
        view.CameraParallelProjection = 1
    return view


def caption(pv, view, name):
    """A Text source shown in the view's upper-left corner; returns the source."""
    text = pv.Text(Text=name)
    shown = pv.Show(text, view)
    shown.WindowLocation = "Upper Left Corner"
    shown.FontSize = 22
    shown.Color = [0.0, 0.0, 0.0]
    return text


def lattice_spacing(reader, bounds):
    """For frames without `spacing`: the spacing of a lattice filling the bounding box."""
    sides = [b - a for a, b in zip(bounds[::2], bounds[1::2]) if b > a]
    count = max(reader.GetDataInformation().GetNumberOfPoints(), 1)
    volume = 1.0
    for side in sides:
        volume *= side
    return (volume / count) ** (1.0 / max(len(sides), 1))


def frame_bounds(reader):
    reader.UpdatePipeline(reader.TimestepValues[0] if reader.TimestepValues else 0.0)
    return reader.GetDataInformation().GetBounds()


def place_camera(view, bounds, flat):
    x0, x1, y0, y1, z0, z1 = bounds
    centre = [(x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2]
    view.CameraFocalPoint = centre
    if flat:  # the body in the left 84 % of the picture, the colour bar right of it
        width, height = view.ViewSize
        visible = max((y1 - y0) / 0.8, (x1 - x0) / 0.84 * height / width)  # world height shown
        centre[0] += 0.06 * visible * width / height
        view.CameraFocalPoint = centre
        view.CameraPosition = [centre[0], centre[1], centre[2] + 10.0 * max(x1 - x0, y1 - y0)]
        view.CameraViewUp = [0.0, 1.0, 0.0]
        view.CameraParallelScale = 0.5 * visible
    else:
        span = max(x1 - x0, y1 - y0, z1 - z0)
        view.CameraPosition = [centre[0] + 1.2 * span, centre[1] - 1.6 * span,
                               centre[2] + 1.4 * span]
        view.CameraViewUp = [0.0, 0.0, 1.0]
        view.ResetCamera()


def setup(pv, pvd, args):
    """The reader, the warp and one view per picture: [(kind, view, caption source)]."""
    reader = pv.PVDReader(FileName=pvd)
    reader.UpdatePipelineInformation()
    bounds = frame_bounds(reader)
    arrays = point_arrays(reader)
    if args.field not in arrays:
        fail(f"{pvd}: no point field '{args.field}' (fields: {', '.join(arrays)})")
    warp = pv.WarpByVector(Input=reader)
    warp.Vectors = ["POINTS", "displacement"]
    warp.ScaleFactor = args.warp
    flat = bounds[5] - bounds[4] <= 0.0
    aspect = (bounds[3] - bounds[2]) / max(bounds[1] - bounds[0], 1e-300) if flat else 0.75
    size = [args.width, max(200, int(args.width * min(aspect, 1.5) * 1.15) + 120)]
    views = []
    kinds = [args.field] + (["level"] if "level" in arrays else [])
    spacing = lattice_spacing(reader, bounds)
    for kind in kinds:
        view = render_view(pv, size, flat)
        shown = particles(pv, warp, view, arrays, args, spacing)
        if kind == "level":
            top = int(max(reader.PointData["level"].GetRange()[1], 1))
            level_colours(pv, shown, view, top)
        else:
            damage_colours(pv, shown, view, kind)
        views.append((kind, view, caption(pv, view, "")))
        pv.Render(view)  # the first render resets the camera: place it after
        place_camera(view, bounds, flat)
    return reader, views


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    pvd = find_pvd(args.directory)
    times = pvd_times(pvd)
    frames = chosen(times, args.frames, args.times)
    pv = import_paraview(args.paraview_python)
    out = args.png_dir or os.path.join(args.directory, "paraview")
    os.makedirs(out, exist_ok=True)
    reader, views = setup(pv, pvd, args)
    name = os.path.splitext(os.path.basename(pvd))[0]
    if not any(kind == "level" for kind, _, _ in views):
        print(f"note: {pvd}: the frames have no `level` field, so no level pictures")
    for index in frames:
        t = times[index]
        for kind, view, text in views:
            text.Text = (f"{name}   t = {t * 1e6:.4g} µs   frame {index} of {len(times) - 1}"
                         f"   {kind}" + (f"   warp ×{args.warp:g}" if args.warp != 1 else ""))
            view.ViewTime = t
            pv.Render(view)
            png = os.path.join(out, f"{kind}_{index:06d}.png")
            pv.SaveScreenshot(png, view, ImageResolution=view.ViewSize)
            print(f"wrote {png}: t = {t * 1e6:.4g} µs")
    for _, view, _ in views:
        pv.Delete(view)
    del reader
    return 0


if __name__ == "__main__":
    sys.exit(main())
