#!/usr/bin/python3
"""The state-based plate cases against the finite-element reference (issue 17, item 6; the
tension cases: issue 18).

    check_fe_plate.py --dhpd BIN --out DIR fast|ranking|calculix

`fast` (every test run, ~25 s): ordinary state-based (OSB) δ = 3Δx and correspondence (NOSB)
δ = 1Δx, 2Δx on cases/plate_vibration.yaml, and both on cases/cutout_plate_vibration.yaml,
cases/plate_tension.yaml and cases/cutout_plate_tension.yaml (statics, fictitious layers),
against tests/data/fe/*.csv: the RMS difference of u and v over the run (or over the field at
4e-4 s, or along y = 0 and x = 0 at equilibrium) within the bounds below, as a fraction of the
reference's peak.
`ranking` (label verification): δ = 1..5 Δx for both families on the vibrating and the pulled
plate, the two-region grids and the Δx = 0.005 m grids (where NOSB 2Δx and the cut-out's v come
within 5 %); the papers' ranking (OSB best at 3-4Δx, NOSB at 1-2Δx) must come out for both.
`calculix` (label verification): the reference computed again with CalculiX
(tools/python/fe_reference.py; Debian calculix-ccx) equals the committed files.
"""
import argparse
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(SOURCE, "tools", "python"))
import fe_compare  # noqa: E402

PLATE = os.path.join(SOURCE, "cases", "plate_vibration.yaml")
CUTOUT = os.path.join(SOURCE, "cases", "cutout_plate_vibration.yaml")
TENSION = os.path.join(SOURCE, "cases", "plate_tension.yaml")
CUTOUT_TENSION = os.path.join(SOURCE, "cases", "cutout_plate_tension.yaml")
# The field each scene is compared on (None: the probe's history against plate_vibration.csv).
FIELD_REFERENCE = {CUTOUT: "cutout_vibration.csv", TENSION: "plate_tension.csv",
                   CUTOUT_TENSION: "cutout_tension.csv"}
DATA = os.path.join(SOURCE, "tests", "data", "fe")
NOSB = ["model.family=correspondence"]
TWO_REGIONS = ["body.1.spacing=0.005"]

# (name, scene, overrides, bound on the u and v errors). Measured (Δx = 0.01 m): OSB δ = 3Δx
# 0.024 / 0.029; NOSB δ = 1Δx 0.013 / 0.023, δ = 2Δx 0.020 / 0.028; cut-out OSB 0.011 / 0.036,
# NOSB 0.009 / 0.033: docs/verification.md, "Plate vibration against finite elements".
# Tension (statics, fictitious layers; issue 18 asks 3 % of the peak): plate OSB 3Δx 0.0002 /
# 0.0015, NOSB 2Δx 0.0001 / 0.0003; cut-out OSB 0.0044 / 0.0179, NOSB 0.0062 / 0.0115.
FAST = [
    ("osb_3dx", PLATE, ["horizon.factor=3"], 0.05),
    ("nosb_1dx", PLATE, NOSB + ["horizon.factor=1"], 0.05),
    ("nosb_2dx", PLATE, NOSB + ["horizon.factor=2"], 0.05),
    ("cutout_osb_3dx", CUTOUT, ["horizon.factor=3"], 0.05),
    ("cutout_nosb_2dx", CUTOUT, NOSB + ["horizon.factor=2"], 0.05),
    ("tension_osb_3dx", TENSION, ["horizon.factor=3"], 0.03),
    ("tension_nosb_2dx", TENSION, NOSB + ["horizon.factor=2"], 0.03),
    ("cutout_tension_osb_3dx", CUTOUT_TENSION, ["horizon.factor=3"], 0.03),
    ("cutout_tension_nosb_2dx", CUTOUT_TENSION, NOSB + ["horizon.factor=2"], 0.03),
]


def run(dhpd, out, scene, overrides, allow_unconverged=False):
    """Runs the scene; a static run that did not converge (exit 3) returns False when allowed."""
    cmd = [dhpd, "run", scene, "--out", out, "--quiet", "--overwrite"]
    for o in overrides:
        cmd += ["--set", o]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode == 3 and allow_unconverged and "did not converge" in done.stderr:
        return False
    if done.returncode != 0:
        sys.exit(f"{' '.join(cmd)}: exit {done.returncode}\n{done.stderr}")
    return True


def errors(dhpd, root, name, scene, overrides, allow_unconverged=False):
    """The run's errors; a static run that did not converge counts as error 1 in u and v."""
    out = os.path.join(root, name)
    if not run(dhpd, out, scene, overrides, allow_unconverged):
        return {"ux": 1.0, "uy": 1.0, "unconverged": True}
    if scene in FIELD_REFERENCE:
        return fe_compare.field_errors(out, os.path.join(DATA, FIELD_REFERENCE[scene]))
    return fe_compare.probe_errors(out, os.path.join(DATA, "plate_vibration.csv"))


def fast(dhpd, root):
    failures = []
    print(f"{'run':18s} {'u err':>7s} {'v err':>7s}  bound")
    for name, scene, overrides, bound in FAST:
        e = errors(dhpd, root, name, scene, overrides)
        ok = e["ux"] <= bound and e["uy"] <= bound
        print(f"{name:18s} {e['ux']:7.4f} {e['uy']:7.4f}  {bound}  {'ok' if ok else 'FAILED'}")
        failures += [] if ok else [name]
    return failures


def horizon_ranking(dhpd, root, scene, label):
    """δ = 1..5 Δx for both families on `scene`: the papers' ranking, and NOSB's error growing
    with δ beyond 2Δx (OSB at 1Δx does not settle in the static case: counted as error 1)."""
    failures = []
    table = {}
    for family, extra in (("osb", []), ("nosb", NOSB)):
        for n in range(1, 6):
            e = errors(dhpd, root, f"{label}_{family}_{n}dx", scene, extra + [f"horizon.factor={n}"],
                       allow_unconverged=True)
            table[(family, n)] = e["ux"] + e["uy"]
            note = "  (did not converge)" if e.get("unconverged") else ""
            print(f"{label} {family:5s} δ = {n}Δx  u {e['ux']:.5f}  v {e['uy']:.5f}{note}")
    best_osb = min(range(1, 6), key=lambda n: table[("osb", n)])
    best_nosb = min(range(1, 6), key=lambda n: table[("nosb", n)])
    print(f"{label} best: OSB δ = {best_osb}Δx (papers: 3-4), NOSB δ = {best_nosb}Δx (papers: 1-2)")
    failures += [] if best_osb in (3, 4) else [f"{label} OSB ranking"]
    failures += [] if best_nosb in (1, 2) else [f"{label} NOSB ranking"]
    if not table[("nosb", 2)] < table[("nosb", 3)] < table[("nosb", 4)]:
        failures.append(f"{label} NOSB error grows with δ beyond 2Δx")
    return failures


def ranking(dhpd, root):
    failures = horizon_ranking(dhpd, root, PLATE, "vibration")
    failures += horizon_ranking(dhpd, root, TENSION, "tension")
    fine = ["body.0.spacing=0.005"]
    for name, scene, extra, bound in (
            ("two_regions_osb_3dx", PLATE, ["horizon.factor=3"] + TWO_REGIONS, 0.05),
            ("two_regions_nosb_2dx", PLATE, NOSB + ["horizon.factor=2"] + TWO_REGIONS, 0.05),
            ("fine_nosb_2dx", PLATE, NOSB + ["horizon.factor=2"] + fine + ["body.1.spacing=0.005"],
             0.05),
            ("cutout_fine_osb_3dx", CUTOUT, ["horizon.factor=3"] + fine, 0.05),
            ("cutout_fine_nosb_2dx", CUTOUT, NOSB + ["horizon.factor=2"] + fine, 0.05),
            ("tension_two_regions_osb_3dx", TENSION, ["horizon.factor=3"] + fine, 0.03),
            ("tension_two_regions_nosb_2dx", TENSION, NOSB + ["horizon.factor=2"] + fine, 0.03)):
        e = errors(dhpd, root, name, scene, extra)
        ok = e["ux"] <= bound and e["uy"] <= bound
        print(f"{name}: u {e['ux']:.4f}  v {e['uy']:.4f}  bound {bound}  {'ok' if ok else 'FAILED'}")
        failures += [] if ok else [name]
    return failures


def bar_solution(times, x=0.755, strain=1.0e-3, length=1.0, speed=(200.0e9 / 7850.0) ** 0.5):
    """u(x, t) of a clamped-free bar released at rest from u = strain · x (modal series, 4,000
    modes): the plate with ν = 0, whose rows do not interact."""
    import numpy as np
    n = np.arange(1, 4001)
    k = (2 * n - 1) * np.pi / (2 * length)
    amplitude = 2 * strain * (-1.0) ** (n + 1) / (length * k**2) * np.sin(k * x)
    return (amplitude[None, :] * np.cos(np.outer(times, speed * k))).sum(axis=1)


def calculix(root):
    import numpy as np
    failures = []
    # The pipeline first: with ν = 0 the plate is a bar with a closed-form answer (0.05 m
    # elements: 1.7 % of the peak, 0.85 % at 0.025 m: the smeared wave front, first order).
    bar = os.path.join(root, "bar.csv")
    done = subprocess.run(["/usr/bin/python3", os.path.join(SOURCE, "tools", "python",
                                                            "fe_reference.py"), "plate-vibration",
                           "-o", bar, "--size", "0.05", "--dt", "1e-6", "--nu", "0"])
    if done.returncode != 0:
        return ["fe_reference.py failed (is calculix-ccx installed? tools/dhpd verify installs it)"]
    _, ref = fe_compare.read_reference(bar)
    error = fe_compare.relative_rms(ref[:, 1], bar_solution(ref[:, 0]))
    print(f"CalculiX bar (ν = 0, 0.05 m) against the closed form: {error:.4f} of the peak")
    failures += [] if error < 0.025 else ["the FE pipeline against the bar's closed form"]
    for case, file in (("plate-vibration", "plate_vibration.csv"),
                       ("cutout-vibration", "cutout_vibration.csv"),
                       ("plate-tension", "plate_tension.csv"),
                       ("cutout-tension", "cutout_tension.csv")):
        out = os.path.join(root, file)
        done = subprocess.run(["/usr/bin/python3", os.path.join(SOURCE, "tools", "python",
                                                                "fe_reference.py"), case, "-o", out])
        if done.returncode != 0:
            return [f"fe_reference.py {case} failed (is calculix-ccx installed?)"]
        _, ours = fe_compare.read_reference(out)
        _, committed = fe_compare.read_reference(os.path.join(DATA, file))
        same = ours.shape == committed.shape and np.allclose(ours, committed, rtol=1e-6,
                                                             atol=1e-6 * np.abs(committed).max())
        print(f"{file}: computed again {'equals' if same else 'DIFFERS FROM'} the committed file")
        failures += [] if same else [file]
    return failures


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("mode", choices=["fast", "ranking", "calculix"])
    parser.add_argument("--dhpd")
    parser.add_argument("--out", required=True)
    a = parser.parse_args()
    os.makedirs(a.out, exist_ok=True)
    failures = calculix(a.out) if a.mode == "calculix" else (
        fast(a.dhpd, a.out) if a.mode == "fast" else ranking(a.dhpd, a.out))
    if failures:
        sys.exit(f"check_fe_plate {a.mode}: FAILED: {', '.join(failures)}")


if __name__ == "__main__":
    main()
