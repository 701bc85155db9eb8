#!/usr/bin/python3
"""The stability suite: `dhpd stress [SUITE.yaml] [-o DIR]` and `dhpd stress --check DIR1 [DIR2]`.

Runs every case of a suite (default cases/stress/suite.yaml) with 1 and with 2 threads
(`dhpd run SCENE --out DIR --threads N --quiet`), checks the criteria of tools/python/stress_check.py on
the outputs and writes DIR/stress.csv and DIR/stress.md (default DIR: stress-NAME). Exit code 0
when every criterion of every case passes, 1 when any fails (each failure is printed), 2 on bad
input (the message names file, line, key path and what is allowed).

Suite file (YAML):
    name: stability
    criteria: {energy_tolerance: 0.01, momentum_tolerance: 1.0e-9}   # optional defaults
    cases:
      - name: horizon_ratio_1d           # unique; letters, digits, _ . -
        scene: horizon_ratio_1d.yaml     # relative to the suite file
        set: {time.safety: 0.9}          # optional --set overrides
        sweep: {time.safety: [0.5, 0.7]} # optional: one case per value, named NAME-VALUE
        criteria: {momentum_axes: [y]}   # optional per-case criteria (energy_tolerance,
        reason: why the criteria differ  #   momentum_tolerance, momentum_axes); needs reason
        expect: {broken_bonds: 1}        # optional: what makes the case hard, checked too
"""
import argparse
import csv
import os
import re
import shutil
import sys
import time

import yaml

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import launch  # noqa: E402  (beside this script)
import stress_check  # noqa: E402

SUITE_KEYS = {"name", "criteria", "cases"}
CASE_KEYS = {"name", "scene", "set", "sweep", "criteria", "reason", "expect"}
CRITERIA_KEYS = {"energy_tolerance", "momentum_tolerance", "momentum_axes"}
RUN_TIMEOUT_S = 1800  # one run of a case; a hang fails the case instead of the whole suite
ORDER = ["status", "finite", "energy", "momentum", "volume", "reproducible", "hardness"]


class SuiteError(Exception):
    pass


def fail(message):
    sys.stderr.write(f"dhpd stress: error: {message}\n")
    sys.exit(2)


class Located:
    """A YAML node turned into Python values, with the line of every key path."""

    def __init__(self, path):
        self.path, self.lines = path, {}
        with open(path) as f:
            try:
                node = yaml.compose(f)
            except yaml.YAMLError as e:
                mark = getattr(e, "problem_mark", None)
                line = mark.line + 1 if mark else 1
                raise SuiteError(f"{path}:{line}: not valid YAML: {getattr(e, 'problem', e)}")
        self.value = self.convert(node, "") if node is not None else None

    def convert(self, node, key_path):
        self.lines[key_path] = node.start_mark.line + 1
        if isinstance(node, yaml.MappingNode):
            out = {}
            for k, v in node.value:
                key = k.value
                sub = f"{key_path}.{key}" if key_path else key
                if key in out:
                    raise SuiteError(f"{self.path}:{k.start_mark.line + 1}: {sub}: duplicate key")
                self.lines[sub] = k.start_mark.line + 1
                out[key] = self.convert(v, sub)
            return out
        if isinstance(node, yaml.SequenceNode):
            return [self.convert(v, f"{key_path}.{n}" if key_path else str(n))
                    for n, v in enumerate(node.value)]
        return yaml.safe_load(yaml.serialize(node))

    def error(self, key_path, message):
        line = self.lines.get(key_path, self.lines.get(key_path.rsplit(".", 1)[0], 1))
        return SuiteError(f"{self.path}:{line}: {key_path}: {message}")


def check_keys(doc, value, key_path, allowed):
    if not isinstance(value, dict):
        raise doc.error(key_path or "suite", f"expected a map with keys {sorted(allowed)}")
    for key in value:
        if key not in allowed:
            sub = f"{key_path}.{key}" if key_path else key
            raise doc.error(sub, f"unknown key '{key}' (allowed: {', '.join(sorted(allowed))})")


def check_criteria(doc, criteria, key_path):
    check_keys(doc, criteria, key_path, CRITERIA_KEYS)
    for key in ("energy_tolerance", "momentum_tolerance"):
        value = criteria.get(key, 1.0)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
            raise doc.error(f"{key_path}.{key}", f"must be a number > 0, got {value!r}")
    axes = criteria.get("momentum_axes", ["x"])
    if not isinstance(axes, list) or not axes or any(a not in ("x", "y", "z") for a in axes):
        raise doc.error(f"{key_path}.momentum_axes",
                        f"must be a non-empty list of x, y, z, got {axes!r}")


def expand_case(doc, suite_dir, case, key_path, defaults):
    """The runs of one case entry: a list of (name, scene, overrides, criteria, expect)."""
    check_keys(doc, case, key_path, CASE_KEYS)
    for required in ("name", "scene"):
        if required not in case:
            raise doc.error(key_path, f"missing key '{required}'")
    name = str(case["name"])
    if not re.fullmatch(r"[A-Za-z0-9_.-]+", name):
        raise doc.error(f"{key_path}.name", f"'{name}' has characters other than letters, "
                        "digits, _ . - (allowed: [A-Za-z0-9_.-]+)")
    scene = os.path.join(suite_dir, str(case["scene"]))
    if not os.path.isfile(scene):
        raise doc.error(f"{key_path}.scene", f"no such scene file '{case['scene']}'")
    criteria = dict(defaults, **case.get("criteria", {}))
    if "criteria" in case:
        check_criteria(doc, case["criteria"], f"{key_path}.criteria")
        if not str(case.get("reason", "")).strip():
            raise doc.error(f"{key_path}.criteria", "per-case criteria need a 'reason'")
    expect = case.get("expect", {})
    check_keys(doc, expect, f"{key_path}.expect", set(stress_check.EXPECT_KEYS))
    for key, value in expect.items():
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise doc.error(f"{key_path}.expect.{key}", f"must be a number, got {value!r}")
    fixed = case.get("set", {})
    check_keys(doc, fixed, f"{key_path}.set", set(fixed) if isinstance(fixed, dict) else set())
    sweep = case.get("sweep", {})
    check_keys(doc, sweep, f"{key_path}.sweep", set(sweep) if isinstance(sweep, dict) else set())
    if len(sweep) > 1 or any(not isinstance(v, list) or not v for v in sweep.values()):
        raise doc.error(f"{key_path}.sweep", "must map one key to a non-empty list of values")
    if not sweep:
        return [(name, scene, dict(fixed), criteria, expect, case.get("reason", ""))]
    key, values = next(iter(sweep.items()))
    return [(f"{name}-{v}", scene, dict(fixed, **{key: v}), criteria, expect,
             case.get("reason", "")) for v in values]


def load_suite(path):
    if not os.path.isfile(path):
        raise SuiteError(f"{path}: no such suite file (a YAML file: see tools/python/stress.py)")
    doc = Located(path)
    suite = doc.value
    check_keys(doc, suite, "", SUITE_KEYS)
    if not isinstance(suite.get("cases"), list) or not suite["cases"]:
        raise doc.error("cases", "expected a non-empty list of cases")
    defaults = dict(stress_check.DEFAULT_CRITERIA, **suite.get("criteria", {}))
    if "criteria" in suite:
        check_criteria(doc, suite["criteria"], "criteria")
    runs, seen = [], set()
    for n, case in enumerate(suite["cases"]):
        for run in expand_case(doc, os.path.dirname(os.path.abspath(path)), case, f"cases.{n}",
                               defaults):
            if run[0] in seen:
                raise doc.error(f"cases.{n}.name", f"duplicate case name '{run[0]}'")
            seen.add(run[0])
            runs.append(run)
    return str(suite.get("name", "stress")), runs


def run_case(dhpd, scene, overrides, out_dir, threads):
    """One `dhpd run` in a fresh folder; returns what launch.run gave (a hang: exit code -1)."""
    shutil.rmtree(out_dir, ignore_errors=True)
    env = dict(os.environ)
    env.setdefault("OMP_WAIT_POLICY", "passive")  # no spinning against the other run's jobs
    run = launch.run(dhpd, scene, out_dir, overrides, threads, env=env, timeout=RUN_TIMEOUT_S)
    if run.timed_out:
        run.stderr = f"stopped after {RUN_TIMEOUT_S} s (a hang?)"
    else:
        run.stderr = run.stderr.strip()
    return run


def shown(value):
    if isinstance(value, float):
        return f"{value:.3g}"
    return str(value)


def write_report(out, title, rows):
    """stress.csv (one row per case, value and pass of each criterion) and stress.md."""
    facts = stress_check.EXPECT_KEYS + ["energy_dip"]
    header = ["case", "pass", "wall_1_s", "wall_2_s"] + facts
    for c in ORDER:
        header += [c, f"{c}_pass"]
    with open(os.path.join(out, "stress.csv"), "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(header + ["notes"])
        for r in rows:
            res = r["result"]
            line = [r["name"], r["pass"], f"{r['wall'][0]:.2f}", f"{r['wall'][1]:.2f}"]
            line += [res.get("facts", {}).get(k, "") for k in facts]
            for c in ORDER:
                line += [res[c]["value"], res[c]["pass"]] if c in res else ["", ""]
            writer.writerow(line + [r["notes"]])
    md = [f"# Stability suite: {title}", "",
          "| case | particles/steps | broken | isolated | levels | δ ratio | finite | energy "
          "| (dip) | momentum | min volume | status | 1 = 2 threads | wall 1/2 (s) | pass |",
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        res, fx = r["result"], r["result"].get("facts", {})

        def cell(c):
            if c not in res:
                return "—"
            return f"{shown(res[c]['value'])} {'✓' if res[c]['pass'] else '✗'}"
        md.append(f"| {r['name']} | {r.get('particles', '')}/{fx.get('steps', '')} | "
                  f"{fx.get('broken_bonds', '')} | {fx.get('isolated_particles', '')} | "
                  f"{fx.get('max_level', '')} | {shown(fx.get('horizon_ratio', ''))} | "
                  f"{cell('finite')} | {cell('energy')} | {shown(fx.get('energy_dip', ''))} | "
                  f"{cell('momentum')} | {cell('volume')} | "
                  f"{cell('status')} | {cell('reproducible')} | {r['wall'][0]:.1f}/"
                  f"{r['wall'][1]:.1f} | {'pass' if r['pass'] else '**FAIL**'} |")
    failures = [f"- {r['name']}: {r['notes']}" for r in rows if not r["pass"]]
    md += ["", "Failures:" if failures else "Every criterion of every case passes."] + failures
    with open(os.path.join(out, "stress.md"), "w") as f:
        f.write("\n".join(md) + "\n")


def failure_notes(result):
    return "; ".join(f"{c} {shown(result[c]['value'])}" + (f" ({result[c]['note']})"
                     if result[c]["note"] else "") for c in ORDER
                     if c in result and not result[c]["pass"])


def particles_of(summary):
    """"N" or "N→M" from a run's summary.json ("" without one)."""
    try:
        start, end = summary["particles_start"], summary["particles_end"]
    except (TypeError, KeyError):
        return ""
    return f"{start}→{end}" if start != end else str(end)


def run_suite(args):
    try:
        title, runs = load_suite(args.suite)
    except SuiteError as e:
        fail(str(e))
    out = args.out or f"stress-{title}"
    os.makedirs(out, exist_ok=True)
    rows, start = [], time.monotonic()
    for name, scene, overrides, criteria, expect, reason in runs:
        dirs = [os.path.join(out, name, f"threads{t}") for t in (1, 2)]
        launches = [run_case(args.dhpd, scene, overrides, d, t) for d, t in zip(dirs, (1, 2))]
        codes, walls = [r.code for r in launches], [r.wall for r in launches]
        result = stress_check.check_run(dirs[0], dirs[1], criteria, expect)
        if any(codes):
            result["status"] = stress_check.verdict(f"exit {codes}", False, " / ".join(
                r.stderr.splitlines()[-1] for r in launches if r.stderr))
        ok = all(v["pass"] for k, v in result.items() if k != "facts")
        notes = failure_notes(result) or reason
        rows.append({"name": name, "pass": ok, "wall": walls, "result": result, "notes": notes,
                     "particles": particles_of(launches[0].summary)})
        print(f"{name}: {'pass' if ok else 'FAIL ' + notes} ({walls[0]:.1f} s + {walls[1]:.1f} s)",
              flush=True)
    write_report(out, title, rows)
    failed = [r["name"] for r in rows if not r["pass"]]
    print(f"{len(rows) - len(failed)} of {len(rows)} cases pass in {time.monotonic() - start:.0f} s;"
          f" {os.path.join(out, 'stress.md')}" + (f"; failed: {', '.join(failed)}" if failed else ""))
    return 1 if failed else 0


def check_dirs(args):
    """`--check DIR1 [DIR2]`: the criteria on existing outputs, printed one per line."""
    for d in args.check:
        if not os.path.isdir(d):
            fail(f"{d}: no such directory (a run's output directory)")
    criteria = {}
    if args.energy_tolerance is not None:
        criteria["energy_tolerance"] = args.energy_tolerance
    if args.momentum_tolerance is not None:
        criteria["momentum_tolerance"] = args.momentum_tolerance
    if args.momentum_axes:
        criteria["momentum_axes"] = list(args.momentum_axes)
    result = stress_check.check_run(args.check[0], args.check[1] if len(args.check) > 1 else None,
                                    criteria)
    for c in ORDER:
        if c in result:
            r = result[c]
            print(f"{c}: {shown(r['value'])} {'pass' if r['pass'] else 'FAIL'}"
                  + (f" ({r['note']})" if r["note"] and not r["pass"] else ""))
    return 0 if all(v["pass"] for k, v in result.items() if k != "facts") else 1


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(prog="dhpd stress")
    parser.add_argument("suite", nargs="?",
                        default=os.path.join(here, "..", "cases", "stress", "suite.yaml"))
    parser.add_argument("--dhpd", default="dhpd")
    parser.add_argument("--out", "-o")
    parser.add_argument("--check", nargs="+", metavar="DIR")
    parser.add_argument("--energy-tolerance", type=float)
    parser.add_argument("--momentum-tolerance", type=float)
    parser.add_argument("--momentum-axes", choices=["x", "y", "z", "xy", "xyz", "xz", "yz"])
    args = parser.parse_args()
    if args.check:
        if len(args.check) > 2:
            fail("--check takes one or two run directories (1-thread run, 2-thread run)")
        return check_dirs(args)
    return run_suite(args)


if __name__ == "__main__":
    sys.exit(main())
