#!/usr/bin/python3
"""The CMES 2019 bar (cases/multi_horizon_bar.yaml; issue 19): the velocity at each of the
wave's eight returns to the middle (tools/python/wave_returns.py) with dual horizons,
multi-horizon PD and the classical variable-horizon model, against the bar refined everywhere
and against the unrefined bar, as measured (docs/verification.md, "Multi-horizon PD"):
dual horizons stay within 0.3 % of the refined bar at the first return and 26 % at the eighth;
multi-horizon is 5.9 % and 171 %, a little better than the classical model (6.2 %, 200 %), far
from the paper's 15 % against the unrefined bar; the ordinary state-based forms alike (0.37 % /
36 % and 7.3 % / 159 %); a sharp pulse stays stable."""
import os
import subprocess
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import support  # noqa: E402

support.import_tools()
import wave_returns  # noqa: E402

CASE = os.path.join(support.SOURCE, "cases", "multi_horizon_bar.yaml")
RUNS = {"fine": ["body.0.spacing=0.0001"],
        "unrefined": ["body.1.spacing=0.0004", "body.2.spacing=0.0004"],
        "dual": ["model=dual-horizon"], "multi": ["model=multi-horizon"],
        "classical": ["model=classical-variable"],
        "pulse": ["model=multi-horizon", "initial_conditions.0.gaussian.width=0.0005"],
        "state_fine": ["model={family: ordinary-state, horizon: dual-horizon}",
                       "body.0.spacing=0.0001"],
        "state_dual": ["model={family: ordinary-state, horizon: dual-horizon}"],
        "state_multi": ["model={family: ordinary-state, horizon: multi-horizon}"]}
WORK = None


def setUpModule():
    global WORK
    support.require_binary()
    WORK = support.Workdir("wave_returns")
    for name, sets in RUNS.items():
        cmd = [support.BIN, "run", CASE, "-o", WORK(name), "-q"]
        for s in sets:
            cmd += ["--set", s]
        done = subprocess.run(cmd, capture_output=True, text=True)
        if done.returncode != 0:
            raise AssertionError(f"{' '.join(cmd)}: exit {done.returncode}\n{done.stderr}")


def tearDownModule():
    if WORK:
        WORK.cleanup()


def errors(name, reference):
    return wave_returns.return_errors(WORK(reference), WORK(name))


class EightReturns(unittest.TestCase):
    def test_dual_horizons_follow_the_refined_bar(self):
        e = errors("dual", "fine")
        self.assertEqual(len(e), 8)
        self.assertLess(e[0], 0.005)
        self.assertLess(e[7], 0.30)

    def test_multi_horizon_reflects_more_than_dual_horizons_and_a_little_less_than_classical(self):
        dual, multi, classical = (errors(n, "fine") for n in ("dual", "multi", "classical"))
        for k in range(8):
            self.assertGreater(multi[k], 3.0 * dual[k], f"return {k + 1}")
            self.assertLess(multi[k], classical[k], f"return {k + 1}")

    def test_state_based_multi_horizon_reflects_more_than_dual_horizons(self):
        dual, multi = (errors(n, "state_fine") for n in ("state_dual", "state_multi"))
        self.assertLess(dual[0], 0.005)
        for k in range(8):
            self.assertGreater(multi[k], 3.0 * dual[k], f"return {k + 1}")

    def test_the_paper_s_fifteen_percent_is_not_reproduced(self):
        multi = errors("multi", "unrefined")
        self.assertGreater(max(multi), 0.15)

    def test_a_sharp_pulse_stays_stable(self):
        frames = wave_returns.frames(WORK("pulse"))
        self.assertEqual(len(frames), 9)
        self.assertLess(max(abs(v).max() for _, _, v in frames), 2.0)


if __name__ == "__main__":
    support.main()
