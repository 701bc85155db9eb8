#!/usr/bin/python3
"""Finite-element reference solutions for the state-based plate cases, computed by CalculiX
(Debian `calculix-ccx`, an independent solver), written as small CSV files that the tests read.

  fe_reference.py plate-vibration  -o tests/data/fe/plate_vibration.csv
  fe_reference.py cutout-vibration -o tests/data/fe/cutout_vibration.csv
  fe_reference.py plate-tension    -o tests/data/fe/plate_tension.csv
  fe_reference.py cutout-tension   -o tests/data/fe/cutout_tension.csv
  (--size H --dt DT for a convergence check; --keep DIR keeps the deck and CalculiX's files;
   the committed files: the defaults, 0.01 m elements, dt = 5e-7 s, about 6 and 2 minutes for
   the vibrations, seconds for the static cases)

The problem (horizon-size paper §5.1 and §5.5.2; Euler–Lagrange paper §5.2): a 1 m × 1 m plate,
plane stress, E = 200 GPa, ν = 0.25, ρ = 7850 kg/m³, centred at the origin, its left edge
x = −0.5 clamped, released at rest from the uniaxial strain u_x = ε (x + 0.5), u_y = 0 with
ε = 0.001. The cut-out variant has a centred square hole of side 0.4 m. CalculiX assembles the
stiffness K and mass M of a hexahedral mesh (write_deck says why not its own time stepping);
with u = u0 + w, u0 the initial field, w starts at rest from 0 under M ẅ + K w = −K u0, the
release of the free edges' tractions as a step load (for the linear u0, −K u0 is exactly that
load: the patch test), integrated by Newmark's average acceleration (newmark). Written: u(t),
v(t) at (0.255, 0.255) m every 1 µs (bilinear in its element), or the cut-out's field at
t = 4e-4 s on every other particle centre of the Δx = 0.01 m plate.

The tension cases (horizon-size paper §5.2 and §5.5.1; Euler–Lagrange paper §5.1): the same
plate, its left edge clamped, pulled by σ = 200 MPa on its right edge x = 0.5 (consistent nodal
forces), solved statically (K u = f); written: u_x, u_y along y = 0 and along x = 0 every 0.01 m
(the particle rows of the Δx = 0.01 m plate lie 0.005 m either side), outside the hole.
"""
import argparse
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

E, NU, RHO, THICKNESS, STRAIN = 200.0e9, 0.25, 7850.0, 0.01, 0.001
HALF = 0.5
PROBE = (0.255, 0.255)
CASES = {
    # name: (hole side, end time, field output at the end instead of the probe's history)
    "plate-vibration": (0.0, 1.0e-3, False),
    "cutout-vibration": (0.4, 4.0e-4, True),
    # static: (hole side, None, lines y = 0 and x = 0)
    "plate-tension": (0.0, None, True),
    "cutout-tension": (0.4, None, True),
}
STRESS = 200.0e6  # Pa on the right edge of the tension cases
SAMPLE = 1.0e-6  # s between the written samples
FIELD_SPACING = 0.02  # field points: every other particle centre of the Δx = 0.01 m plate


def lattice(size, hole):
    """Nodes {(i, j): (x, y)} and quadrilaterals (counter-clockwise) of the plate with its hole."""
    n = round(2 * HALF / size)
    if abs(n * size - 2 * HALF) > 1e-9:
        sys.exit(f"fe_reference: --size {size} does not divide the 1 m plate")
    inside_hole = lambda x, y: hole > 0 and abs(x) < hole / 2 - 1e-12 and abs(y) < hole / 2 - 1e-12
    elements = []
    for i in range(n):
        for j in range(n):
            cx, cy = -HALF + (i + 0.5) * size, -HALF + (j + 0.5) * size
            if not inside_hole(cx, cy):
                elements.append(((i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)))
    used = sorted({c for e in elements for c in e})
    nodes = {c: (-HALF + c[0] * size, -HALF + c[1] * size) for c in used}
    return nodes, elements


def probe_weights(nodes, size, point):
    """The corner nodes of the element holding `point` and their bilinear weights (the
    hexahedron's in-plane shape functions on its mid-plane face)."""
    i, j = (int((point[k] + HALF) // size) for k in (0, 1))
    s, t = ((point[k] + HALF) / size - (i, j)[k] for k in (0, 1))
    corners = {(i, j): (1 - s) * (1 - t), (i + 1, j): s * (1 - t), (i + 1, j + 1): s * t,
               (i, j + 1): (1 - s) * t}
    return {c: w for c, w in corners.items() if w > 1e-12 and c in nodes}


def field_points(hole):
    """Every other particle centre of the Δx = 0.01 m plate (x, y = −0.495 + 0.02 k) outside the
    hole: where the field is compared."""
    count = round(2 * HALF / FIELD_SPACING)
    line = [-HALF + 0.005 + FIELD_SPACING * k for k in range(count)]
    return [(x, y) for y in line for x in line if not (abs(x) < hole / 2 and abs(y) < hole / 2)]


def write_deck(path, nodes, elements, nu):
    """The CalculiX deck that assembles K and M (*FREQUENCY, SOLVER=MATRIXSTORAGE): the upper half
    of the plate's thickness (z from 0 to THICKNESS/2), one layer of C3D8I (incompatible modes: no
    shear locking in in-plane bending), u_z = 0 on the mid-plane z = 0 (symmetry), the top face
    free, so plane stress; the left edge clamped in x and y. Returns the node ids of the mid-plane.

    Why not CalculiX's own time stepping: its plane elements (CPS4, expanded to solids inside) ran
    waves √2 too fast in *DYNAMIC in version 2.20 (a clamped bar under an end load: particle
    velocity 7.2 m/s against εc = 5.05 m/s, while *FREQUENCY gave the right modes), and its
    implicit steps on solids refactor the matrix at every increment (0.2 s an increment on 900
    nodes). The matrices are CalculiX's; the time integration below is Newmark's average
    acceleration with one factorisation."""
    ids = {c: k + 1 for k, c in enumerate(nodes)}
    top = len(nodes)
    line = lambda values: ", ".join(str(v) for v in values) + "\n"
    with open(path, "w") as f:
        f.write("** dhpd FE reference (tools/python/fe_reference.py)\n*NODE\n")
        for layer, z in ((0, 0.0), (top, THICKNESS / 2)):
            for c, (x, y) in nodes.items():
                f.write(f"{ids[c] + layer}, {x:.12g}, {y:.12g}, {z:.12g}\n")
        f.write("*ELEMENT, TYPE=C3D8I, ELSET=PLATE\n")
        for k, e in enumerate(elements):
            f.write(line([k + 1] + [ids[c] for c in e] + [ids[c] + top for c in e]))
        left = [ids[c] for c, (x, _) in nodes.items() if abs(x + HALF) < 1e-12]
        write_set(f, "LEFT", left + [n + top for n in left])
        write_set(f, "MID", sorted(ids.values()))
        f.write(f"*MATERIAL, NAME=STEEL\n*ELASTIC\n{E:.6g}, {nu}\n*DENSITY\n{RHO}\n")
        f.write("*SOLID SECTION, ELSET=PLATE, MATERIAL=STEEL\n")
        f.write("*BOUNDARY\nLEFT, 1, 2\nMID, 3, 3\n")
        f.write("*STEP\n*FREQUENCY, SOLVER=MATRIXSTORAGE\n*END STEP\n")
    return ids, top


def read_matrices(work):
    """K and M (symmetric, from CalculiX's triangle) and, per equation, (node, direction)."""
    dofs = []
    with open(os.path.join(work, "plate.dof")) as f:
        for text in f:
            node, direction = text.strip().split(".")
            dofs.append((int(node), int(direction)))
    n = len(dofs)

    def matrix(name):
        data = np.loadtxt(os.path.join(work, name), ndmin=2)
        i, j, v = data[:, 0].astype(int) - 1, data[:, 1].astype(int) - 1, data[:, 2]
        off = i != j
        return sp.csc_matrix((np.concatenate([v, v[off]]), (np.concatenate([i, j[off]]),
                                                             np.concatenate([j, i[off]]))), (n, n))

    return matrix("plate.sti"), matrix("plate.mas"), dofs


def initial_field(dofs, coordinates, nu):
    """u0 per equation: ε (x + 0.5) along x, 0 along y, −ν/(1−ν) ε z through the thickness (the
    plane-stress strain state with σ_zz = 0); 0 for CalculiX's incompatible-mode unknowns."""
    u0 = np.zeros(len(dofs))
    for k, (node, direction) in enumerate(dofs):
        if node not in coordinates:
            continue
        x, _, z = coordinates[node]
        u0[k] = STRAIN * (x + HALF) if direction == 1 else (
            -nu / (1 - nu) * STRAIN * z if direction == 3 else 0.0)
    return u0


def newmark(K, M, f, dt, steps, on_step):
    """Average-acceleration Newmark (trapezoidal, no numerical damping) from rest at w = 0 under
    the constant load f; on_step(k, w) after each step. Only M a enters the scheme, so M a is
    carried instead of a (M a = f − K w = f at the start): no solve with M, whose incompatible-mode
    rows make it singular."""
    c = 4.0 / dt**2
    lu = spla.splu((K + c * M).tocsc())
    w = np.zeros(K.shape[0])
    v = np.zeros_like(w)
    Ma = f.copy()
    for k in range(1, steps + 1):
        w_new = lu.solve(f + M @ (c * w + (4.0 / dt) * v) + Ma)
        dw = w_new - w
        Ma = M @ (c * dw - (4.0 / dt) * v) - Ma
        v = (2.0 / dt) * dw - v
        w = w_new
        on_step(k, w)


def write_set(f, name, members):
    f.write(f"*NSET, NSET={name}\n")
    for k in range(0, len(members), 16):
        f.write(", ".join(str(m) for m in members[k:k + 16]) + ",\n")


def run_calculix(deck_dir, name):
    ccx = shutil.which("ccx")
    if not ccx:
        sys.exit("fe_reference: CalculiX (ccx) not found; install it with: apt-get install calculix-ccx")
    env = dict(os.environ, OMP_NUM_THREADS=os.environ.get("OMP_NUM_THREADS", "2"))
    done = subprocess.run([ccx, "-i", name], cwd=deck_dir, env=env, capture_output=True, text=True)
    if done.returncode != 0 or "*ERROR" in done.stdout:
        sys.exit(f"fe_reference: ccx failed:\n{done.stdout[-2000:]}{done.stderr[-2000:]}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("case", choices=sorted(CASES))
    parser.add_argument("-o", "--out", required=True)
    parser.add_argument("--size", type=float, default=0.01, help="element size, m")
    parser.add_argument("--dt", type=float, default=5.0e-7, help="time step, s")
    parser.add_argument("--keep", help="keep the deck and CalculiX's files in this folder")
    parser.add_argument("--nu", type=float, default=NU, help="Poisson's ratio (checks only)")
    a = parser.parse_args()
    hole, end, with_field = CASES[a.case]
    if end is None:
        at = line_points(hole)
        elements, samples = solve_tension(a, hole, at)
        write_csv(a, hole, elements, None, samples, at)
        return
    at = field_points(hole) if with_field else [PROBE]
    elements, energy, samples = solve(a, hole, end, at)
    write_csv(a, hole, elements, energy, samples, at)


def line_points(hole):
    """Every 0.01 m along y = 0 and along x = 0 (x, y = −0.495 … 0.495), outside the hole."""
    line = [-HALF + 0.005 + 0.01 * k for k in range(100)]
    points = [(x, 0.0) for x in line] + [(0.0, y) for y in line]
    return [(x, y) for x, y in points if not (abs(x) < hole / 2 and abs(y) < hole / 2)]


def matrices(a, hole):
    """The mesh, CalculiX's K and M, the equations' (node, direction) and the node ids."""
    nodes, elements = lattice(a.size, hole)
    work = a.keep or tempfile.mkdtemp(prefix="dhpd-fe-")
    os.makedirs(work, exist_ok=True)
    ids, top = write_deck(os.path.join(work, "plate.inp"), nodes, elements, a.nu)
    run_calculix(work, "plate")
    K, M, dofs = read_matrices(work)
    if not a.keep:
        shutil.rmtree(work)
    return nodes, elements, ids, top, K, M, dofs


def solve_tension(a, hole, at):
    """(element count, [(0, [(ux, uy) at each of `at`])]) of K u = f, f the consistent nodal
    forces of σ on the right face of the half-thickness model (σ × its area, a quarter of each
    face element's to each corner). Checked: far from the clamp (x from 0.1 to 0.4 on y = 0 of the
    plate without a hole) the strain is σ/E to 2 %."""
    nodes, elements, ids, top, K, _, dofs = matrices(a, hole)
    equation = {d: k for k, d in enumerate(dofs)}
    f = np.zeros(len(dofs))
    share = STRESS * a.size * (THICKNESS / 2) / 4
    for (i, j), (x, y) in nodes.items():
        if abs(x - HALF) > 1e-12:
            continue
        faces = sum(1 for dj in (-1, 0) if (i, j + dj) in nodes and (i, j + dj + 1) in nodes)
        for node in (ids[(i, j)], ids[(i, j)] + top):
            f[equation[(node, 1)]] += share * faces
    u = spla.spsolve(K.tocsc(), f)
    weights = [probe_weights(nodes, a.size, point) for point in at]
    rows = {c: (equation.get((ids[c], 1)), equation.get((ids[c], 2))) for w in weights for c in w}
    values = in_plane(u, rows, weights)
    if hole == 0.0:
        middle = [(x, v[0]) for (x, y), v in zip(at, values) if y == 0.0 and 0.1 <= x <= 0.4]
        slope = np.polyfit([m[0] for m in middle], [m[1] for m in middle], 1)[0]
        if abs(slope / (STRESS / E) - 1) > 0.02:
            sys.exit(f"fe_reference: strain {slope:.6g} on y = 0, σ/E = {STRESS / E:.6g}: the "
                     "load or the matrices are wrong")
    return len(elements), [(0.0, values)]


def solve(a, hole, end, at):
    """(element count, initial strain energy, [(t, [(ux, uy) at each of `at`])]): samples every
    SAMPLE seconds for a probe, the last step only for a field."""
    nodes, elements, ids, top, K, M, dofs = matrices(a, hole)
    coordinates = {ids[c]: (x, y, 0.0) for c, (x, y) in nodes.items()}
    coordinates.update({ids[c] + top: (x, y, THICKNESS / 2) for c, (x, y) in nodes.items()})
    u0 = initial_field(dofs, coordinates, a.nu)
    energy = 0.5 * u0 @ (K @ u0) * 2  # both halves of the thickness
    if abs(energy - plane_stress_energy(hole, a.nu)) > 1e-6 * energy:
        sys.exit(f"fe_reference: initial strain energy {energy:.9g} J, plane stress "
                 f"{plane_stress_energy(hole, a.nu):.9g} J: the mesh or the matrices are wrong")
    equation = {d: k for k, d in enumerate(dofs)}
    weights = [probe_weights(nodes, a.size, point) for point in at]
    rows = {c: (equation.get((ids[c], 1)), equation.get((ids[c], 2))) for w in weights for c in w}
    steps = int(round(end / a.dt))
    every = max(1, int(round(SAMPLE / a.dt)))
    samples = [(0.0, in_plane(u0, rows, weights))]
    due = lambda k: (k % every == 0 and len(at) == 1) or k == steps
    newmark(K, M, -(K @ u0), a.dt, steps, lambda k, w: (
        samples.append((k * a.dt, in_plane(u0 + w, rows, weights))) if due(k) else None))
    return len(elements), energy, samples


def in_plane(u, rows, weights):
    """(ux, uy) at each point: bilinear over the corners of its element."""
    value = lambda r: 0.0 if r is None else u[r]
    return [tuple(sum(w * value(rows[c][k]) for c, w in point.items()) for k in (0, 1))
            for point in weights]


def plane_stress_energy(hole, nu):
    """½ σ:ε V of the initial uniaxial strain in plane stress, J."""
    return E / (1 - nu**2) * STRAIN**2 / 2 * (1.0 - hole**2) * THICKNESS


def write_csv(a, hole, elements, energy, samples, at):
    with open(a.out, "w") as f:
        if energy is None:
            f.write(f"# CalculiX {shutil.which('ccx')}: C3D8I, element size {a.size} m, "
                    f"{elements} elements; static, sigma {STRESS:g} Pa on x = 0.5, x = -0.5 "
                    f"clamped; E {E:g} Pa, nu {a.nu}, hole {hole} m\n"
                    "# written by tools/python/fe_reference.py\n")
        else:
            analytic = plane_stress_energy(hole, a.nu)
            f.write(f"# CalculiX {shutil.which('ccx')}: C3D8I, element size {a.size} m, "
                    f"{elements} elements; Newmark average acceleration, dt {a.dt} s; E {E:g} "
                    f"Pa, nu {a.nu}, rho {RHO}, strain {STRAIN}, hole {hole} m\n"
                    f"# initial strain energy {energy:.6g} J (plane stress {analytic:.6g} J)\n"
                    "# written by tools/python/fe_reference.py; time from the release\n")
        if len(at) > 1:
            time, values = samples[-1]
            f.write(f"# field at t = {time:.6g} s, bilinear in the elements\nx,y,ux,uy\n")
            for (x, y), (ux, uy) in zip(at, values):
                f.write(f"{x:.6f},{y:.6f},{ux:.9e},{uy:.9e}\n")
            return
        f.write(f"# probe at ({PROBE[0]}, {PROBE[1]}) m, bilinear in its element\ntime,ux,uy\n")
        for time, values in samples:
            f.write(f"{time:.9e},{values[0][0]:.9e},{values[0][1]:.9e}\n")


if __name__ == "__main__":
    main()
