"""Error-controlled internal steps (`tolerance` > 0): Kvaerno's 5(4) ESDIRK
against scipy's solution of the same ODE (independent of the C code), the
momentum and energy identities, the FMU at a communication step, bad values,
and the laws and scenes it applies to."""

import math

import pytest

import fraccontact
from fmu_driver import C, K, M, V0, run_impact
from test_fmu_physics import reference_drop

FIGURES = ("F_peak", "eps", "t_contact", "x2_end")


@pytest.fixture(scope="module")
def reference():
    r = reference_drop(K, C, M, V0)
    return dict(F_peak=r["F_peak"], eps=r["eps"], t_contact=r["t_contact"], x2_end=r["x2"], E_diss=r["E_diss"])


def adaptive(tolerance, **params):
    return fraccontact.impact(law="hertz", k=K, c=C, m=M, v=V0, tolerance=tolerance, dt_max=1e-3, **params)


@pytest.mark.parametrize("tolerance", [1e-4, 1e-6, 1e-8, 1e-10])
def test_every_figure_within_the_steps_times_the_tolerance(reference, tolerance):
    """`tolerance` bounds each step's error relative to the indentation (and
    the speed), so the global error is at most their sum: steps x tolerance.
    Measured: 3 to 13 times the tolerance with 10 to 110 steps."""
    r = adaptive(tolerance)
    for figure in FIGURES:
        assert getattr(r, figure) == pytest.approx(reference[figure], rel=r.steps * tolerance, abs=0), figure


def test_the_error_falls_with_the_tolerance(reference):
    """Order 5: a thousandth of the tolerance takes about 1000^(1/5) = 4 times
    the steps and gives about a thousandth of the error (measured: at least 300
    times less in each figure)."""
    loose, tight = adaptive(1e-6), adaptive(1e-9)
    assert 2 * loose.steps < tight.steps < 8 * loose.steps
    for figure in FIGURES:
        loose_error, tight_error = (abs(getattr(r, figure) / reference[figure] - 1) for r in (loose, tight))
        assert tight_error < loose_error / 100, figure


def test_momentum_and_energy_balance():
    """The dashpot's travel is its impulse over c, and the striker's speed
    falls by the impulse over m (x2_end = m v0 (1 + eps) / c) to rounding over
    the sums of about 50 steps; the energy m v0^2 / 2 goes into the rebound
    and E_diss, the dissipation quadrature of order 5 within the tolerance
    per step."""
    r = adaptive(1e-8)
    assert r.x2_end == pytest.approx(M * V0 * (1 + r.eps) / C, rel=1e-13, abs=0)
    assert 0.5 * M * V0 ** 2 == pytest.approx(0.5 * M * (r.eps * V0) ** 2 + r.E_diss, rel=r.steps * 1e-8, abs=0)


def test_far_fewer_steps_than_fixed_ones_at_the_same_accuracy(reference):
    """Fixed SDIRK2 steps need dt_max 2.5e-6 s (527 steps) for F_peak within
    1e-6; the error-controlled steps meet 1e-6 on all four figures in about
    35. The tolerance bounds each step's error, and over the contact's dozen
    or so smooth steps of one sign those add up: measured on this impact the
    figures come within 15 times the tolerance (eps, the speed's sum, the
    largest), so 1e-6 takes tolerance 1e-6 / 20."""
    r = adaptive(5e-8)
    assert r.steps < 60
    for figure in FIGURES:
        assert getattr(r, figure) == pytest.approx(reference[figure], rel=1e-6, abs=0), figure


def test_steps_stay_under_dt_max(reference):
    """The cap holds: with dt_max = 1e-6 s a 1.3 ms contact takes at least 1316
    steps whatever the tolerance, and is as accurate as uncapped."""
    r = fraccontact.impact(law="hertz", k=K, c=C, m=M, v=V0, tolerance=1e-6, dt_max=1e-6)
    assert r.steps >= reference["t_contact"] / 1e-6
    assert r.F_peak == pytest.approx(reference["F_peak"], rel=r.steps * 1e-6, abs=0)


@pytest.mark.parametrize("law", ["g1", "g1x"])
def test_g1_laws_with_fixed_nodes_are_the_hertz_law_with_their_stiffness(law):
    """With g1_nodes = N the G1 laws are a Hertz spring of stiffness k times
    MODEL.md §4's ratio (tests/closed_forms.py computes it independently), so
    their error-controlled impact is the Hertz law's at that k, step for step."""
    from closed_forms import extrapolated_ratio, g1_line_ratio
    N = 50
    ratio = g1_line_ratio(N) if law == "g1" else extrapolated_ratio(N)
    g1 = fraccontact.impact(law=law, g1_nodes=N, k=K, c=C, m=M, v=V0, tolerance=1e-7, dt_max=1e-3)
    hertz = fraccontact.impact(law="hertz", k=K * ratio, c=C, m=M, v=V0, tolerance=1e-7, dt_max=1e-3)
    for figure in FIGURES:
        assert getattr(g1, figure) == pytest.approx(getattr(hertz, figure), rel=1e-12, abs=0), figure


def test_the_soft_dashpot_is_stiff_and_stays_stable():
    """c = 50 N s/m: the dashpot relaxes in about 1e-5 s while the contact
    creeps on for 0.3 s; the L-stable steps grow far beyond the relaxation
    time (few steps) and the force stays between 0 and its peak, which scipy's
    Radau (an independent implicit solver) agrees with to the tolerance times
    the steps."""
    from fraccontact.scipy_contact import solve_drop
    r = fraccontact.impact(law="hertz", k=K, c=50.0, m=M, v=3.0, tolerance=1e-6, dt_max=1e-3, t_end=0.01)
    ref = solve_drop(K, 50.0, M, 3.0, method="Radau", rtol=1e-11, t_end=0.01)
    assert r.steps < 200
    assert r.end.F_peak == pytest.approx(ref["F_peak"], rel=r.steps * 1e-6, abs=0)


@pytest.mark.parametrize("value, rule", [
    (-1e-6, "must be 0"), (float("nan"), "must be 0"), (0.1, "must be 0"), (1e-13, "must be 0")])
def test_bad_tolerances_are_refused_naming_the_value(value, rule):
    with pytest.raises(ValueError, match=r"tolerance = .* is invalid: .*" + rule):
        fraccontact.impact(law="hertz", tolerance=value)


@pytest.mark.parametrize("params, why", [
    (dict(law="g1"), "g1_nodes = 0"), (dict(law="hertz", scheme="central"), "central"),
    (dict(law="hertz", damper=2), "springpot")])
def test_where_steps_stay_fixed_it_warns_and_changes_nothing(params, why):
    """The G1 laws with N = steps since onset (their error is defined by the
    step count), the central scheme and the springpot keep fixed steps of
    dt_max: a warning names the tolerance, and the run is the fixed one."""
    assert fraccontact.warning(tolerance=1e-6, **params).startswith("tolerance = 1e-06 has no effect")
    assert why in fraccontact.warning(tolerance=1e-6, **params)
    fixed, ignored = fraccontact.impact(**params), fraccontact.impact(tolerance=1e-6, **params)
    assert (ignored.F_peak, ignored.eps, ignored.steps) == (fixed.F_peak, fixed.eps, fixed.steps)


def test_driven_at_a_constant_rate_the_rigid_limit_is_exact():
    """Driven scene, m = 0, a stiff dashpot: x1 = v t until the force
    reaches c v; with v held the stage equations are exact in v, so the
    elastic indentation creeps to (c v / k)^(2/3) (the dashpot's steady state)."""
    v = 0.01
    run = fraccontact.impact(law="hertz", scene="driven", m=0.0, v=v, k=K, c=C, tolerance=1e-8, dt_max=1e-3,
                             t_end=0.05)
    assert run.end.x1 == pytest.approx((C * v / K) ** (2 / 3), rel=1e-6, abs=0)


def test_fmu_at_a_communication_step_of_1e_5(slave, reference):
    """The issue's figure: tolerance 1e-6 with steps up to the communication
    step (1e-5 s) keeps F_peak, eps and x2 within 1e-6 of the reference; the
    FMU's contact time from its free flight after separation (fmu_driver)."""
    s = slave(law=2, tolerance=1e-6, dt_max=1e-5, v=V0)
    r = run_impact(s, H=1e-5)
    assert r["F_peak"] == pytest.approx(reference["F_peak"], rel=1e-6, abs=0)
    assert r["eps"] == pytest.approx(reference["eps"], rel=1e-6, abs=0)
    assert r["x2"] == pytest.approx(reference["x2_end"], rel=1e-6, abs=0)
    assert r["t_contact"] == pytest.approx(reference["t_contact"], rel=1e-6, abs=0)


def test_fmu_state_carries_the_step_control(slave):
    """A state saved mid-contact and restored into a second instance continues
    exactly as the first (the proposed next step is part of the state)."""
    a = slave(law=2, tolerance=1e-7, dt_max=1e-4, v=V0)
    for _ in range(30):
        a.step(1e-5)
    state = a.fmu.serializeFMUstate(a.fmu.getFMUstate())
    b = slave(law=2, tolerance=1e-7, dt_max=1e-4, v=V0)
    b.fmu.setFMUstate(b.fmu.deSerializeFMUstate(state))
    b.t = a.t
    for _ in range(200):
        a.step(1e-5)
        b.step(1e-5)
    for name in ("F", "F_peak", "x2", "v_striker", "eps", "E_diss"):
        assert b.get(name) == a.get(name), name
