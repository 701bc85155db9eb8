"""A scene's pre-cracks, notches, holes and loaded or fixed regions over x-y axes in mm."""
# Drawn exactly: box, disk, polygon and 2D cracks (segments); sphere and cylinder as the outline
# of their projection on the x-y plane, 3D cracks (planar polygons) projected; half-spaces cut to
# the picture (in 3D at the plane z of the picture); union and difference as the outlines of
# their members (a difference's removed members dashed: holes and notches); random-disks not yet
# resolved to disks as their bounding box (dotted). A 1D scene gets none.
import numpy as np
from matplotlib.patches import Polygon as PolygonPatch
from matplotlib.transforms import offset_copy

MM = 1e3
CIRCLE = np.linspace(0.0, 2.0 * np.pi, 97)
STYLE = {"traction": ("tab:red", "traction"), "velocity": ("tab:orange", "prescribed velocity"),
         "fixed": ("tab:blue", "fixed"), "initial": ("tab:green", "initial condition"),
         "body": ("cyan", "body outline, holes and notches (dashed)")}


def xy(point):
    return np.array([float(point[0]), float(point[1]) if len(point) > 1 else 0.0])


def circle(center, radius):
    return xy(center) + float(radius) * np.column_stack([np.cos(CIRCLE), np.sin(CIRCLE)])


def convex_hull(points):
    """The convex hull of 2D points, counter-clockwise (monotone chain)."""
    pts = sorted(map(tuple, np.round(points, 15)))
    if len(pts) < 3:
        return np.array(pts)

    def half(seq):
        out = []
        for p in seq:
            while len(out) >= 2 and np.cross(np.subtract(out[-1], out[-2]),
                                             np.subtract(p, out[-2])) <= 0:
                out.pop()
            out.append(p)
        return out[:-1]
    return np.array(half(pts) + half(reversed(pts)))


def cylinder_outline(shape):
    """The projection on x-y of a cylinder: the hull of its two end circles."""
    c, a = np.array(shape["center"], float), np.array(shape["axis"], float)
    a = a / np.linalg.norm(a)
    u = np.cross(a, [1.0, 0.0, 0.0] if abs(a[0]) < 0.9 else [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(a, u)
    ring = float(shape["radius"]) * (np.outer(np.cos(CIRCLE), u) + np.outer(np.sin(CIRCLE), v))
    ends = np.vstack([c + ring, c + float(shape["height"]) * a + ring])
    return convex_hull(ends[:, :2])


def clip_half_plane(polygon, normal, offset):
    """The part of a convex polygon with normal·x <= offset (Sutherland-Hodgman, one plane)."""
    out = []
    for k, p in enumerate(polygon):
        q = polygon[(k + 1) % len(polygon)]
        dp, dq = normal @ p - offset, normal @ q - offset
        if dp <= 0:
            out.append(p)
        if dp * dq < 0:
            out.append(p + (q - p) * dp / (dp - dq))
    return np.array(out)


def half_space_outline(shape, bounds, z):
    """A half-space cut to the picture's box (in 3D at the plane z)."""
    n, p = np.array(shape["normal"], float), np.array(shape["point"], float)
    offset = float(n @ p) - (n[2] * z if len(n) > 2 else 0.0)
    (x0, x1), (y0, y1) = bounds
    box = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
    normal = np.array([n[0], n[1] if len(n) > 1 else 0.0])
    if not normal.any():
        return box if offset >= 0 else np.zeros((0, 2))
    return clip_half_plane(box, normal, offset)


def outlines(shape, bounds, z=0.0, dashed=False):
    """[(closed x-y polygon in m, line style)] of a shape (see the module docstring)."""
    kind = shape.get("shape")
    style = "--" if dashed else "-"
    if kind == "box":
        (x0, y0), (x1, y1) = xy(shape["min"]), xy(shape["max"])
        return [(np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]]), style)]
    if kind in ("disk", "sphere"):
        return [(circle(shape["center"], shape["radius"]), style)]
    if kind == "polygon":
        return [(np.array([xy(p) for p in shape["points"]]), style)]
    if kind == "cylinder":
        return [(cylinder_outline(shape), style)]
    if kind == "half-space":
        return [(half_space_outline(shape, bounds, z), style)]
    if kind == "union":
        return [o for member in shape["of"] for o in outlines(member, bounds, z, dashed)]
    if kind == "difference":
        first, *rest = shape["of"]
        return outlines(first, bounds, z, dashed) + [
            o for member in rest for o in outlines(member, bounds, z, True)]
    if kind == "random-disks":
        (x0, y0), (x1, y1) = xy(shape["min"]), xy(shape["max"])
        return [(np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]]), ":")]
    return []


def vector_text(values, unit, scale=1.0):
    return "[" + ", ".join(f"{float(v) * scale:g}" for v in values) + f"] {unit}"


def condition_label(condition):
    """(kind, legend text) of a boundary condition."""
    if "traction" in condition:
        return "traction", "traction " + vector_text(condition["traction"], "MPa", 1e-6)
    if condition.get("fixed"):
        return "fixed", "fixed"
    velocity = condition.get("velocity", {})
    text = ", ".join(f"{k} = {float(v):g}" for k, v in velocity.items())
    return "velocity", f"velocity {text} m/s"


def initial_label(condition):
    parts = [f"{k} {vector_text(condition[k], u)}" for k, u in
             (("velocity", "m/s"), ("displacement", "m"), ("strain", "")) if k in condition]
    return "initial " + ", ".join(parts)


def regions(scene):
    """[(kind, label, shape)] of the scene's body parts, boundary and initial conditions."""
    out = [("body", None, part) for part in scene.get("body", []) if "shape" in part]
    for condition in scene.get("boundary_conditions", []):
        kind, label = condition_label(condition)
        out.append((kind, label, condition["region"]))
    for condition in scene.get("initial_conditions", []):
        out.append(("initial", initial_label(condition), condition["region"]))
    return out


def draw_cracks(ax, scene, labelled):
    for k, crack in enumerate(scene.get("cracks", [])):
        points = np.array([xy(p) for p in crack]) * MM
        closed = len(points) > 2  # a 3D pre-crack, projected
        line = np.vstack([points, points[:1]]) if closed else points
        ax.plot(line[:, 0], line[:, 1], color="magenta", lw=2.0, solid_capstyle="butt",
                label=("pre-crack" + (" (projected)" if closed else "")) if k == 0 and labelled
                else None, zorder=5)
    for k, tip in enumerate((scene.get("measure") or {}).get("tips", [])):
        at = xy(tip["at"]) * MM
        ax.plot(*at, marker="x", color="magenta", ms=6, mew=1.5, zorder=6, ls="none",
                label="notch tip (measure)" if k == 0 and labelled else None)


def draw_scene(ax, scene, bounds, z=0.0, legend=True):
    """Draws the scene on ax (axes in mm); bounds ((x0, x1), (y0, y1)) in m cut half-spaces;
    returns how many items were drawn."""
    if not scene or int(scene.get("dimension", 2)) < 2:
        return 0
    drawn, seen = 0, set()
    for kind, label, shape in regions(scene):
        colour, name = STYLE[kind]
        for k, (polygon, style) in enumerate(outlines(shape, bounds, z)):
            if len(polygon) < 2:
                continue
            text = (label or name) if k == 0 and (label or name) not in seen else None
            seen.add(text)
            fill = kind != "body"
            ax.add_patch(PolygonPatch(polygon * MM, closed=True, fill=fill, lw=1.0 if fill else 1.2,
                                      ls=style, ec=colour, fc=colour if fill else "none",
                                      alpha=0.35 if fill else 0.9, label=text if legend else None,
                                      zorder=4))
            drawn += 1
    draw_cracks(ax, scene, legend)
    drawn += len(scene.get("cracks", []))
    if legend and drawn:
        legend_below(ax, 3)
    return drawn


def legend_below(ax, columns):
    """The axes' legend under its x label (a fixed distance in points, whatever the height)."""
    below = offset_copy(ax.transAxes, fig=ax.figure, y=-38, units="points")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, 0.0), bbox_transform=below, ncol=columns,
              fontsize=7, frameon=False)
