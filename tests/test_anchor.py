"""fraccontact-bench anchor: GSL's rk8pd scripted as a user would,
at the loosest tolerance that meets 1e-6, against fraccontact-solve's
independent reference (its own event bracketing, at rtol 1e-14)."""

import json
import math
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
BENCH = pathlib.Path(os.environ.get("FRACCONTACT_BENCH", ROOT / "build" / "fraccontact-bench"))
SOLVE = pathlib.Path(os.environ.get("FRACCONTACT_SOLVE", ROOT / "build" / "fraccontact-solve"))
K, M = 3.299e8, 0.7437
V20 = math.sqrt(2 * 9.81 * 0.02)  # as --height 0.02 computes it (the default v 0.626418 is rounded)


@pytest.fixture(scope="module")
def bench():
    if not BENCH.exists():
        pytest.fail(f"{BENCH} does not exist: build first (scripts/build)")
    return BENCH


def run_json(*args):
    done = subprocess.run([str(a) for a in args], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


# The anchor's rtol is the loosest of 1e-3, 3e-4, 1e-4, ... 1e-12 that meets
# 1e-6 in every figure. The h20 impact: its four figures at separation. The
# soft dashpot (c = 50, v = 3): the striker creeps for 290 ms before it
# separates, so its "10 ms of contact" is a span: F_peak and the state at
# 10 ms. The reference's own error is far below (at rtol 1e-12 and 1e-16 it
# agrees with itself to 2e-15), so the bound is the anchor's 1e-6 itself; at
# these rtol the largest error is 2.2e-7 (h20: eps) and 4.1e-7 (soft:
# F_peak), at the next looser one 1.1e-6 and 1.2e-6: the test sees a lost
# digit, and leaves a factor 2.4 or more for another libm or compiler.
CASES = {
    "h20": dict(c=6080.0, v=V20, t_end=1.0, rtol=1e-6, reference=["--height", "0.02"]),
    "soft 10 ms": dict(c=50.0, v=3.0, t_end=0.01, rtol=3e-6, reference=["--v", "3", "--t-end", "0.01"]),
}


@pytest.mark.parametrize("name", CASES)
def test_anchor_meets_1e_6_against_the_reference(bench, name):
    case = CASES[name]
    a = run_json(bench, "anchor", repr(K), repr(case["c"]), repr(M), repr(case["v"]), repr(case["t_end"]),
                 repr(case["rtol"]), 1)
    r = run_json(SOLVE, "--law", "hertz", "--k", repr(K), "--m", repr(M), "--c", repr(case["c"]), *case["reference"],
                 "--reference", "--rtol", "1e-14", "--json")
    assert r["params"]["v"] == case["v"]
    if r["impacts"]:
        assert a["separated"]
        got = {key: a[key] for key in ("F_peak", "eps", "t_contact", "x2_end")}
        want = {key: r[key] for key in got}
    else:
        assert not a["separated"] and a["eps"] is None and a["end"]["t"] == case["t_end"]
        got = {"F_peak": a["F_peak"], **{key: a["end"][key] for key in ("x1", "x2", "v")}}
        want = {key: r["end"][key] for key in got}
    for key in got:
        assert got[key] == pytest.approx(want[key], rel=1e-6, abs=0), key
    # the cost the anchor stands for: a few hundred right-hand sides per h20 impact
    assert a["rhs_evaluations"] > 10 * a["steps"] and a["us_per_impact"] > 0


def test_anchor_rejects_bad_arguments(bench):
    for args in (["anchor", "1", "2", "3", "4", "5"], ["anchor", "1", "2", "-3", "4", "5", "1e-6"],
                 ["anchor", "1", "2", "3", "4", "5", "abc"]):
        assert subprocess.run([str(bench), *args], capture_output=True, timeout=60).returncode == 2
