"""fraccontact-solve from the command line: its options, its outputs, its
reference against scipy, and the model it shares with the FMU."""

import csv
import json
import math
import os
import pathlib
import subprocess

import pytest

from fmu_driver import C, K, M, run_impact
from scipy_contact import solve_drop
from test_fmu_physics import reference_drop

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOLVE = os.environ.get("FRACCONTACT_SOLVE", str(ROOT / "build" / "fraccontact-solve"))
V0 = 0.626418  # the solver's and the FMU's default impact velocity
KEYS = ("F_peak", "eps", "t_contact", "x_perm", "E_diss")


def solve(*args, check=True):
    done = subprocess.run([SOLVE, *map(str, args)], capture_output=True, text=True, timeout=600)
    if check:
        assert done.returncode == 0, done.stderr
    return done


def solve_json(*args):
    return json.loads(solve(*args, "--json").stdout)


def test_help_documents_every_option():
    text = solve("--help").stdout
    source = (ROOT / "solver" / "fraccontact_solve.c").read_text()
    options = {line.split('"')[1] for line in source.splitlines() if line.strip().startswith('{"--')}
    assert len(options) > 20
    for option in options:
        assert option in text, option


def test_json_has_the_promised_keys():
    r = solve_json()
    for key in KEYS + ("steps", "cpu_seconds", "impacts", "separated"):
        assert key in r, key
    assert r["separated"] and r["impacts"] == 1 and r["steps"] > 10000 and r["cpu_seconds"] >= 0


@pytest.mark.parametrize("args, says", [
    (["--c", "-1"], "c = -1"), (["--c", "abc"], "--c 'abc'"), (["--bogus", "1"], "--bogus"),
    (["--law", "foo"], "--law 'foo'"), (["--dt", "0"], "dt_max = 0"), (["--m", "0"], "m = 0"),
    (["--height", "-1e-3"], "--height"), (["--t-end", "0"], "--t-end"), (["--json=1"], "--json"),
    (["--k"], "needs a value"), (["--g1-nodes", "2.5"], "--g1-nodes"), (["--scheme", "rk4"], "--scheme")])
def test_bad_options_exit_2_with_a_clear_message(args, says):
    done = solve(*args, check=False)
    assert done.returncode == 2 and says in done.stderr, (done.returncode, done.stderr)
    assert done.stdout == ""


def test_unwritable_csv_fails_and_leaves_nothing(tmp_path):
    target = tmp_path / "missing" / "out.csv"
    done = solve("--csv", target, check=False)
    assert done.returncode == 1 and "cannot write" in done.stderr
    assert not target.parent.exists()


def test_csv_series(tmp_path):
    path = tmp_path / "h20.csv"
    r = solve_json("--law", "hertz", "--csv", path, "--output-interval", "1e-5")
    rows = list(csv.DictReader(open(path)))
    assert not (tmp_path / "h20.csv.tmp").exists()
    t = [float(row["t_s"]) for row in rows]
    assert t[0] == 0.0 and all(b > a for a, b in zip(t, t[1:]))
    assert t[1] == pytest.approx(1e-5)
    F = [float(row["F_N"]) for row in rows]
    assert max(F) <= r["F_peak"] and max(F) > 0.999 * r["F_peak"]
    for row in rows:  # 12 digits are written
        x, x1, x2 = float(row["x_m"]), float(row["x1_m"]), float(row["x2_m"])
        if x1 > 0:
            assert x == pytest.approx(x1 + x2, rel=1e-11)
        else:  # after separation: the gap to the dented surface
            assert x <= x2 * (1 + 1e-11)


def test_height_gives_the_impact_velocity():
    assert solve_json("--height", "0.02")["v0"] == pytest.approx(math.sqrt(2 * 9.81 * 0.02), rel=1e-15)


def test_reference_matches_scipy():
    """Two independent high-accuracy solvers of the same ODE (GSL rk8pd and
    scipy DOP853, each at ~1e-12): they agree to 1e-9."""
    r = solve_json("--reference", "--law", "hertz")
    ref = reference_drop(K, C, M, V0)
    ref["x_perm"] = ref.pop("x2")
    for key in KEYS:
        assert r[key] == pytest.approx(ref[key], rel=1e-9), key


def test_stiff_reference_matches_scipy_radau():
    """c = 30: the dashpot relaxes ~100 times faster than a Hertz contact
    lasts, so the reference switches to BDF. So soft a dashpot never lets the
    striker rebound: compare the state after 10 ms with scipy's Radau."""
    c, t_end = 30.0, 0.01
    r = solve_json("--reference", "--law", "hertz", "--c", c, "--t-end", t_end)
    ref = solve_drop(K, c, M, V0, method="Radau", rtol=1e-12, t_end=t_end)
    assert r["impacts"] == 0 and not ref["separated"]
    assert r["x_perm"] == pytest.approx(ref["x2"], rel=1e-8)
    assert r["v_end"] == pytest.approx(ref["v_end"], rel=1e-8)
    assert r["E_diss"] == pytest.approx(ref["E_diss"], rel=1e-8)
    assert r["F_peak"] == pytest.approx(ref["F_peak"], rel=1e-8)


def test_solver_and_fmu_share_the_model(slave):
    """Same code, same steps: the CLI and the FMU agree to rounding."""
    for law, name in ((1, "g1"), (2, "hertz")):
        r = solve_json("--law", name)
        f = run_impact(slave(law=law))
        assert r["F_peak"] == pytest.approx(f["F_peak"], rel=1e-12)
        assert r["eps"] == pytest.approx(f["eps"], rel=1e-12)
        assert r["x_perm"] == pytest.approx(f["x2"], rel=1e-12)


def test_sdirk_is_second_order_and_central_first_against_the_reference():
    ref = solve_json("--reference", "--law", "hertz")
    for scheme, order in (("sdirk2", 2.0), ("central", 1.0)):
        errors = [abs(solve_json("--law", "hertz", "--scheme", scheme, "--dt", dt)["x_perm"] / ref["x_perm"] - 1)
                  for dt in (4e-7, 2e-7, 1e-7)]
        observed = [math.log2(a / b) for a, b in zip(errors, errors[1:])]
        assert all(abs(p - order) < 0.15 for p in observed), (scheme, errors, observed)


def test_extrapolated_g1_law_is_second_order():
    """Law g1x cancels G1's 3/(8N): it converges to Hertz like the scheme
    (F_peak, the largest of the step values, is left out: sampling the peak
    on the step grid makes its error oscillate)."""
    ref = solve_json("--reference", "--law", "hertz")
    for key in ("eps", "x_perm", "t_contact"):
        errors = [abs(solve_json("--law", "g1x", "--dt", dt)[key] / ref[key] - 1) for dt in (4e-7, 2e-7, 1e-7)]
        observed = [math.log2(a / b) for a, b in zip(errors, errors[1:])]
        assert all(abs(p - 2) < 0.15 for p in observed), (key, errors, observed)
