"""Each tip's crack traced through the damage field: every branch, its branch points and times."""
# As the crack measure does it (docs/scenes.md `measure`): the damaged particles (φ ≥
# damage_threshold) are linked when closer than 1.5 times the larger spacing, a tip's crack is
# what is linked to a damaged particle within its horizon of the notch tip, and distances are path
# distances from the notch tip. Here the crack is cut into bins of path distance one horizon wide;
# the particles of a bin split into groups (linked within the bin, groups whose centroids lie
# within branch_separation horizons merged), each group a node linked to the node of the bin
# before that it shares most links with. A node with two children that each reach two bins on is
# a branch point. Positions are x-y (3D cracks projected). Each node's time is the first frame in
# which damage reached its centroid.
from dataclasses import dataclass, field

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components, dijkstra
from scipy.spatial import cKDTree

LINK = 1.5  # particles closer than LINK times the larger spacing are linked
MIN_BINS = 2  # a side branch shorter than this many bins is damage beside the crack, not a branch


@dataclass
class Crack:
    """One tip's traced crack: node centroids (x-y, m), their bins and parents (-1: the notch
    tip), and each node's time (s, nan until set)."""
    tip: str
    at: np.ndarray
    centroids: list = field(default_factory=list)
    bins: list = field(default_factory=list)
    parents: list = field(default_factory=list)
    times: list = field(default_factory=list)

    def children(self, node):
        return [k for k, p in enumerate(self.parents) if p == node]


def link_graph(points, spacing, at, horizon):
    """The links of the damaged particles and a virtual node (index n) joined to the particles
    within their horizon of the notch tip, at their distance from it; a sparse matrix."""
    n = len(points)
    pairs = cKDTree(points).query_pairs(LINK * float(spacing.max()), output_type="ndarray")
    length = np.linalg.norm(points[pairs[:, 0]] - points[pairs[:, 1]], axis=1) if len(pairs) else []
    keep = length <= LINK * np.maximum(spacing[pairs[:, 0]], spacing[pairs[:, 1]]) if len(
        pairs) else np.zeros(0, bool)
    rows, cols, weights = list(pairs[keep, 0]), list(pairs[keep, 1]), list(np.asarray(length)[keep])
    to_tip = np.linalg.norm(points - at, axis=1)
    seeds = np.nonzero(to_tip <= horizon)[0]
    rows += [n] * len(seeds)
    cols += list(seeds)
    weights += list(np.maximum(to_tip[seeds], 1e-30))
    graph = coo_matrix((weights, (rows, cols)), shape=(n + 1, n + 1)).tocsr()
    return graph + graph.T


def groups(graph, members, centroid_gap, points):
    """The groups of one bin's particles: linked within the bin, close centroids merged."""
    count, label = connected_components(graph[members][:, members], directed=False)
    parts = [members[label == c] for c in range(count)]
    merged = True
    while merged and len(parts) > 1:
        merged = False
        centres = [points[p].mean(axis=0) for p in parts]
        for a in range(len(parts)):
            for b in range(a + 1, len(parts)):
                if np.linalg.norm(centres[a] - centres[b]) <= centroid_gap:
                    parts[a] = np.concatenate([parts[a], parts.pop(b)])
                    merged = True
                    break
            if merged:
                break
    return parts


def parent_of(graph, part, previous, crack, points):
    """The node of the bin before that shares most links with `part` (the nearest without)."""
    if not previous:
        return -1
    sub = graph[part]
    scores = [sub[:, members].nnz for _, members in previous]
    if max(scores) > 0:
        return previous[int(np.argmax(scores))][0]
    centre = points[part].mean(axis=0)
    return min(previous, key=lambda p: np.linalg.norm(crack.centroids[p[0]] - centre))[0]


def trace(points, spacing, horizon, tip, separation=2.0):
    """A tip's Crack from damaged particles (x-y positions, spacing, horizon)."""
    at = np.asarray(tip["at"], float)[:2]
    crack = Crack(str(tip["name"]), at)
    if len(points) == 0:
        return crack
    graph = link_graph(points, spacing, at, horizon)
    distance = dijkstra(graph, directed=False, indices=len(points))[:-1]
    reached = np.isfinite(distance)
    if not reached.any():
        return crack
    width = float(np.median(horizon[reached]))
    bins = np.full(len(points), -1)  # -1: not reached (distance inf, which no int can hold)
    bins[reached] = np.floor(distance[reached] / width).astype(int)
    previous = []
    for b in range(int(bins[reached].max()) + 1):
        members = np.nonzero(reached & (bins == b))[0]
        current = []
        for part in groups(graph, members, separation * width, points) if len(members) else []:
            crack.parents.append(parent_of(graph, part, previous, crack, points))
            crack.centroids.append(points[part].mean(axis=0))
            crack.bins.append(b)
            crack.times.append(np.nan)
            current.append((len(crack.centroids) - 1, part))
        previous = current or previous
    return crack


def depth(crack, node):
    """Bins from `node` to the farthest node below it."""
    below = [depth(crack, c) for c in crack.children(node)]
    return 1 + max(below, default=0)


def kept_children(crack, node):
    """The children of a node that lead to a branch (MIN_BINS or more); all when only one."""
    children = crack.children(node)
    long = [c for c in children if depth(crack, c) >= MIN_BINS]
    return long if len(long) > 1 else (long or children)[:1] if children else []


def branches(crack):
    """(polylines as node lists from a branch point or the notch tip (-1), branch points as
    node indices)."""
    lines, points, stack = [], [], [(-1, [-1])]
    while stack:
        node, line = stack.pop()
        children = kept_children(crack, node)
        if len(children) == 1:
            stack.append((children[0], line + [children[0]]))
            continue
        if len(line) > 1:
            lines.append(line)
        if len(children) > 1:
            points.append(node)
            stack += [(c, [node, c]) for c in reversed(children)]
    return lines, points


def position(crack, node):
    return crack.at if node < 0 else crack.centroids[node]


def set_times(crack, frames):
    """Each node's time: the first of frames [(time, damaged x-y points, spacing)] with a damaged
    particle within LINK spacings of its centroid."""
    for time, points, spacing in frames:
        if len(points) == 0:
            continue
        distance, _ = cKDTree(points).query(np.array(crack.centroids).reshape(-1, 2))
        for k, d in enumerate(distance):
            if np.isnan(crack.times[k]) and d <= LINK * float(spacing.max()):
                crack.times[k] = time


def branch_time(crack, node):
    """When a branch point's branches had all appeared: the latest of its children's times."""
    return max((crack.times[c] for c in kept_children(crack, node)), default=np.nan)
