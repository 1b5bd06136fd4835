"""The fast subset of the stability matrix (fraccontact/reports/stability.py; the full
matrix is docs/stability.md): extreme dashpots, foam and steel, 0.1 mm/s to
30 m/s, 1 g to 1 t, steps from 1 ns to longer than the contact, N = 1e6,
rest under gravity, a gap, repeated impacts. Every run passes every check
(finite, no tension, 0 <= eps <= 1, momentum, no energy created beyond
rounding, F <= c v_max, the GSL reference where the step resolves the
contact) except the known findings listed in stability.KNOWN, which must
still fail exactly as listed; the h20 convergence study measures the
constants the reference tolerances use."""

import copy
import math
import os
import pathlib
import warnings

import pytest

from fraccontact.reports import stability

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOLVER = pathlib.Path(os.environ.get("FRACCONTACT_SOLVE", ROOT / "build" / "fraccontact-solve"))
CASES = [(name, case) for name, case in stability.matrix() if name in stability.FAST]


class KnownFinding(UserWarning):
    """A check the model fails, listed in stability.KNOWN (docs/stability.md)."""


def test_the_fast_subset_is_all_there():
    assert len(CASES) == len(stability.FAST)


def test_known_findings_name_real_runs_and_checks():
    names = {name for name, _ in stability.matrix()}
    for (name, law), checks in stability.KNOWN.items():
        assert name in names and law in ("g1", "hertz"), (name, law)
        assert checks <= set(stability.CHECKS) and checks, checks


@pytest.mark.parametrize("law", ["g1", "hertz"])
@pytest.mark.parametrize("name, case", CASES, ids=[name for name, _ in CASES])
def test_case_passes_every_check(name, case, law):
    row = stability.check(SOLVER, case, law, name)
    assert not row["unexpected"], row["unexpected"]
    if row["known"]:
        warnings.warn(KnownFinding(f"{name} (law {law}): " + "; ".join(row["failures"])))


@pytest.mark.parametrize("law", ["hertz", "g1"])
def test_convergence_at_h20(law):
    """Second order (Hertz), first order (G1, N = steps) against the
    reference, with constants within those the matrix's tolerances use."""
    name, case = next((n, c) for n, c in stability.CONVERGENCE if n in stability.FAST_CONVERGENCE)
    study = stability.convergence(SOLVER, name, case, law)
    assert not study["failures"], study["failures"]
    assert set(study["orders"]) == set(stability.QUANTITIES), study["orders"]  # every order measured, none at a floor


# --- The checks can fail: a run altered by a little more than rounding.

@pytest.fixture(scope="module")
def h20():
    case = dict(stability.BASE)
    sc = stability.scales(case)
    r, err = stability.solve(SOLVER, case, "hertz", stability.t_end_of(case, sc["t_c"]))
    assert r is not None, err
    return case, r


def failing(case, r):
    checks, _ = stability.invariants(case, r)
    return {c for c, why in checks.items() if why}


def test_invariants_pass_on_the_h20_run(h20):
    assert failing(*h20) == set()


def test_created_energy_fails(h20):
    case, r = h20
    r = copy.deepcopy(r)
    r["E_diss"] *= 1 + 1e-8  # 7e-9 of the impact energy, above its numerical loss at dt = t_c/12 000 (3e-9)
    r["per_impact"][0]["E_diss"] = r["E_diss"]
    assert failing(case, r) == {stability.ENERGY}


def test_momentum_off_fails(h20):
    case, r = h20
    r = dict(r, x2=r["x2"] * (1 + 1e-9))
    assert stability.invariants(case, r)[0]["momentum"]


def test_eps_above_one_fails(h20):
    case, r = h20
    r = copy.deepcopy(r)
    r["per_impact"][0]["eps"] = 1 + 1e-9
    assert stability.EPS in failing(case, r)


def test_force_above_c_v_fails(h20):
    case, r = h20
    r = dict(r, F_peak=case["c"] * case["v0"] * (1 + 1e-9))
    assert stability.FORCE in failing(case, r)


def test_reference_tolerance_is_the_scheme_error():
    """At h20, dt = t_c/100: C2 (dt/t_c)^2 + rounding, and D1 dt/t_c on top
    for the G1 law with N = steps."""
    case = dict(stability.BASE)
    sc = stability.scales(case)
    h = 0.01
    hertz = stability.tolerance(case, "hertz", "eps", h, 0, 0.0)
    g1 = stability.tolerance(case, "g1", "eps", h, 0, 0.0)
    assert math.isclose(hertz, stability.C2["eps"] * h * h + 4 * stability.ROUNDING_ULPS * stability.ULP)
    assert math.isclose(g1 - hertz, stability.D1["eps"] * h)
    assert stability.resolution(dict(case, dt=sc["t_c"] / 100), sc, "eps") == pytest.approx(h)
