"""The fast subset of the stability matrix (reports/stability/; the full
matrix is docs/stability.md): extreme dashpots, foam and steel, 0.1 mm/s to
30 m/s, 1 g to 1 t, steps from 1 ns to longer than the contact, N = 1e6,
rest under gravity, a gap, repeated impacts; each with the G1 and the Hertz
law in fixed steps and "adaptive" (the Hertz law, tolerance 1e-6, the
case's dt as the cap dt_max). Every run passes every check
(finite, no tension, 0 <= eps <= 1, momentum, no energy created beyond
rounding, F <= c v_max ((n + 1) c v_max for fixed steps), the GSL
reference where the step resolves the contact; every figure of an
adaptive run, within its error control's bound): dashpot.KNOWN lists no
finding; the h20 convergence study measures the constants the reference
tolerances use."""

import copy
import dataclasses
import math
import os
import pathlib
import warnings

import pytest

from reports.stability import core, dashpot, springpot, springpot_report

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOLVER = pathlib.Path(os.environ.get("FRACCONTACT_SOLVE", ROOT / "build" / "fraccontact-solve"))
CASES = [(name, case) for name, case in dashpot.matrix() if name in dashpot.FAST]


class KnownFinding(UserWarning):
    """A check the model fails, listed in dashpot.KNOWN (docs/stability.md)."""


def test_the_fast_subset_is_all_there():
    assert len(CASES) == len(dashpot.FAST)


def test_no_run_is_a_known_finding():
    """The fixed step never creates energy and keeps its force's bound
    (docs/model.md §11): no run of the matrix is let fail a check."""
    assert dashpot.KNOWN == {}


def test_known_findings_name_real_runs_and_checks():
    names = {name for name, _ in dashpot.matrix()}
    for (name, law), checks in dashpot.KNOWN.items():
        assert name in names and law in dashpot.LAWS, (name, law)
        assert checks <= set(dashpot.CHECKS) and checks, checks


@pytest.mark.parametrize("law", dashpot.LAWS)
@pytest.mark.parametrize("name, case", CASES, ids=[name for name, _ in CASES])
def test_case_passes_every_check(name, case, law):
    row = dashpot.check(SOLVER, case, law, name)
    assert not row["unexpected"], row["unexpected"]
    if row["known"]:
        warnings.warn(KnownFinding(f"{name} (law {law}): " + "; ".join(row["failures"])))


@pytest.mark.parametrize("law", ["hertz", "g1"])
def test_convergence_at_h20(law):
    """Second order (Hertz), first order (G1, N = steps) against the
    reference, with constants within those the matrix's tolerances use."""
    name, case = next((n, c) for n, c in dashpot.CONVERGENCE if n in dashpot.FAST_CONVERGENCE)
    study = dashpot.convergence(SOLVER, name, case, law)
    assert not study["failures"], study["failures"]
    assert set(study["orders"]) == set(dashpot.QUANTITIES), study["orders"]  # every order measured, none at a floor


# --- The checks can fail: a run altered by a little more than rounding.

@pytest.fixture(scope="module")
def h20():
    case = dict(dashpot.BASE)
    sc = dashpot.scales(case)
    r, err = dashpot.solve(SOLVER, case, "hertz", core.t_end_of(case, sc["t_c"]))
    assert r is not None, err
    return case, r


def failing(case, r):
    checks, _ = dashpot.invariants(case, r)
    return {c for c, why in checks.items() if why}


def test_invariants_pass_on_the_h20_run(h20):
    assert failing(*h20) == set()


def test_created_energy_fails(h20):
    case, r = h20
    r = copy.deepcopy(r)
    r["E_diss"] *= 1 + 1e-8  # 7e-9 of the impact energy, above its numerical loss at dt = t_c/12 000 (3e-9)
    r["per_impact"][0]["E_diss"] = r["E_diss"]
    assert failing(case, r) == {dashpot.ENERGY}


def test_momentum_off_fails(h20):
    case, r = h20
    r = dict(r, x2=r["x2"] * (1 + 1e-9))
    assert dashpot.invariants(case, r)[0]["momentum"]


def test_eps_above_one_fails(h20):
    case, r = h20
    r = copy.deepcopy(r)
    r["per_impact"][0]["eps"] = 1 + 1e-9
    assert dashpot.EPS in failing(case, r)


def test_force_above_the_fixed_steps_bound_fails(h20):
    """(n + 1) c v_max for fixed steps (n = 3/2 here), c v_max for the adaptive ones (below)."""
    case, r = h20
    assert dashpot.FIXED_FORCE == 2.5
    assert dashpot.FORCE in failing(case, dict(r, F_peak=2.5 * case["c"] * case["v0"] * (1 + 1e-9)))
    assert dashpot.FORCE not in failing(case, dict(r, F_peak=2.5 * case["c"] * case["v0"] * (1 - 1e-9)))


def test_reference_tolerance_is_the_scheme_error():
    """At h20, dt = t_c/100: C2 (dt/t_c)^2 + rounding, and D1 dt/t_c on top
    for the G1 law with N = steps."""
    case = dict(dashpot.BASE)
    sc = dashpot.scales(case)
    h = 0.01
    hertz = dashpot.tolerance(case, "hertz", "eps", h, 0, 0.0)
    g1 = dashpot.tolerance(case, "g1", "eps", h, 0, 0.0)
    assert math.isclose(hertz, dashpot.C2["eps"] * h * h + 4 * core.ROUNDING_ULPS * core.ULP)
    assert math.isclose(g1 - hertz, dashpot.D1["eps"] * h)
    # dt / t_c = 1/100 with a rounding or two: rel 1e-14
    assert dashpot.resolution(dict(case, dt=sc["t_c"] / 100), sc, "eps") == pytest.approx(h, rel=1e-14, abs=0)


# --- The adaptive variant: its bounds, and its checks can fail.

def test_adaptive_reference_tolerance_is_the_error_control():
    """K (accepted steps) x tolerance + the reference's error + rounding,
    whatever dt (the cap) is: not the fixed scheme's C2 (dt/T)^2."""
    case = dict(dashpot.BASE, dt=1e-2)
    floor = 1e-12
    for q, K in dashpot.ADAPTIVE_K.items():
        tol = dashpot.tolerance(case, dashpot.ADAPTIVE, q, 8.0, 21, floor)
        assert math.isclose(tol, K * 21 * dashpot.ADAPTIVE_TOLERANCE + floor + 25 * core.ROUNDING_ULPS
                            * core.ULP)


@pytest.fixture(scope="module")
def h20_adaptive():
    """h20, the adaptive steps capped at 1e-2 (8 contact times): about 20 steps."""
    case = dict(dashpot.BASE, dt=1e-2)
    sc = dashpot.scales(case)
    r, err = dashpot.solve(SOLVER, case, dashpot.ADAPTIVE, core.t_end_of(case, sc["t_c"]))
    assert r is not None, err
    assert 10 <= r["steps"] <= 40, r["steps"]  # error-controlled, not 1e-2 steps nor 1e-7 ones
    return case, r


def test_adaptive_run_is_compared_on_every_figure(h20_adaptive):
    """Capped at 8 t_c, every figure still compared, within a few times the
    tolerance per step (measured: at most 1.2e-5, E_diss, in 21 steps)."""
    case, _ = h20_adaptive
    row = dashpot.check(SOLVER, case, dashpot.ADAPTIVE, "dt = 0.01")
    assert set(row["compared"]) == set(dashpot.QUANTITIES), row["compared"]
    assert not row["failures"], row["failures"]
    assert all(e <= 20 * dashpot.ADAPTIVE_TOLERANCE for e, _ in row["compared"].values()), row["compared"]


def adaptive_failing(case, r):
    checks, _ = dashpot.invariants(case, r, dashpot.ADAPTIVE)
    return {c for c, why in checks.items() if why}


def test_adaptive_energy_allows_the_error_control_and_no_more(h20_adaptive):
    """The energy check allows ADAPTIVE_ENERGY (steps) x tolerance of the
    impact's energy for the adaptive steps, not for the fixed ones."""
    case, r = h20_adaptive
    assert adaptive_failing(case, r) == set()
    E = 0.5 * case["m"] * case["v0"] ** 2
    bound = dashpot.ADAPTIVE_ENERGY * r["steps"] * dashpot.ADAPTIVE_TOLERANCE * E
    for share, fails in ((0.5, False), (1.5, True)):
        more = copy.deepcopy(r)
        more["E_diss"] += share * bound - (r["E_diss"] + 0.5 * case["m"] * r["v"] ** 2 - E)  # created: share x bound
        more["per_impact"][0]["E_diss"] = more["E_diss"]
        assert (dashpot.ENERGY in adaptive_failing(case, more)) == fails, share
        assert dashpot.ENERGY in failing(case, more)  # the fixed scheme's check: rounding only


def test_adaptive_invariants_otherwise_unchanged(h20_adaptive):
    """Momentum to rounding, eps <= 1, F <= c v_max: no allowance for the
    adaptive steps."""
    case, r = h20_adaptive
    assert dashpot.invariants(case, dict(r, x2=r["x2"] * (1 + 1e-9)), dashpot.ADAPTIVE)[0]["momentum"]
    bad = copy.deepcopy(r)
    bad["per_impact"][0]["eps"] = 1 + 1e-9
    assert dashpot.EPS in adaptive_failing(case, bad)
    assert dashpot.FORCE in adaptive_failing(case, dict(r, F_peak=case["c"] * case["v0"] * (1 + 1e-9)))


# --- The springpot (damper = 2): its fast subset, its study, and checks that can fail.

SP_CASES = [(name, case) for name, case in springpot.matrix() if name in springpot.FAST]


class ReportedDefect(UserWarning):
    """A check the model fails, listed in springpot.DEFECTS: a defect reported to the model's owners."""


def test_springpot_fast_subset_is_all_there():
    assert len(SP_CASES) == len(springpot.FAST)


def test_no_springpot_run_is_a_known_finding():
    """Memory 1 locates the separation inside its step (docs/model.md §7):
    no springpot run is let fail a check as a known finding (a defect
    reported to the model's owners is listed in springpot.DEFECTS)."""
    assert springpot.KNOWN == {}


def test_springpot_listed_findings_name_real_runs_and_checks():
    names = {name for name, _ in springpot.matrix()}
    for (name, memory), checks in {**springpot.KNOWN, **springpot.DEFECTS}.items():
        assert name in names and memory in (1, 2), (name, memory)
        assert checks and set(checks) <= set(springpot.CHECKS), checks
        assert set(checks.values()) <= set(springpot_report.FINDINGS), checks
    assert not set(springpot.KNOWN) & set(springpot.DEFECTS)


@pytest.mark.parametrize("name, case", SP_CASES, ids=[name for name, _ in SP_CASES])
def test_springpot_case_passes_every_check(name, case):
    """Both memories: finite, x2 >= 0, passivity, 0 <= eps <= 1, no energy
    created, the energy identity, and the memories agree; except the runs
    listed in springpot.KNOWN and DEFECTS, which must fail exactly so."""
    for row in springpot.check(case, name):
        assert not row["unexpected"], (row["memory"], row["unexpected"])
        if row["known"]:
            kind = ReportedDefect if (name, row["memory"]) in springpot.DEFECTS else KnownFinding
            warnings.warn(kind(f"{name} (memory {row['memory']}): " + "; ".join(row["failures"])))


@pytest.mark.parametrize("name", sorted(springpot.FAST_CONVERGENCE))
def test_springpot_convergence(name):
    """Both memories against the reference on dt = t_c/20 ... t_c/2560,
    within the constants the matrix uses; memory 1 approaching the second
    order from below (1.70 to 2.09 measured in these regimes)."""
    case = dict(springpot.CONVERGENCE)[name]
    study = springpot.convergence(name, case)
    assert not study["failures"], study["failures"]
    for memory in (1, 2):
        assert {"F_peak", "eps", "t_contact", "E_diss"} <= set(study["constants"][memory]), study["constants"]
    assert all(o > 1.6 for o in study["orders"][1].values()), study["orders"][1]


def test_compressed_memory_error_follows_the_lumped_moment():
    """The finding springpot_report.ORDER_FINDING: at alpha = 0.9 memory 2's E_diss error
    is the kernel's lost first moment lambda, which falls as dt^(2 - alpha),
    against memory 1 extrapolated (second order) as the reference."""
    case = dict(springpot.BASE, alpha=0.9)
    sc = springpot.scales(case)
    fine, coarse = [springpot.simulate(springpot.parameters(case, 1, sc["t_c"] / n, 1.0))[0].per_impact[0].E_diss
                    for n in (16384, 8192)]
    exact = fine + (fine - coarse) / 3
    ratios, lams = [], []
    for n in (10240, 40960):  # where lambda (1.3e-7, 2.8e-8) outweighs memory 2's h^2 term
        E = springpot.simulate(springpot.parameters(case, 2, sc["t_c"] / n, 1.0))[0].per_impact[0].E_diss
        lams.append(springpot.lumped_lambda(case, sc["t_c"] / n, sc["t_c"]))
        ratios.append((E / exact - 1) / lams[-1])
    assert all(0.8 < r < 1.1 for r in ratios), ratios  # measured 0.91, 0.96
    assert math.log(lams[0] / lams[1]) / math.log(4) == pytest.approx(2 - 0.9, abs=0.05, rel=0)


@pytest.fixture(scope="module")
def springpot_run():
    """The h20 springpot (alpha 0.5, law hertz), both memories at dt = 1e-6."""
    case = dict(springpot.BASE, dt=1e-6)
    runs = springpot.memory_runs(case)
    for p, r, rows, why in runs.values():
        assert r is not None, why
    return case, runs


def sp_failing(case, r, rows, memory=2, h=1e-6 / 1.23e-3):
    checks, _ = springpot.invariants(case, r, rows, memory, h)
    return {c for c, why in checks.items() if why}


def test_springpot_invariants_pass(springpot_run):
    case, runs = springpot_run
    for memory, (p, r, rows, _) in runs.items():
        assert sp_failing(case, r, rows, memory) == set()
    assert springpot.agreement(case, runs[1][:3], runs[2][:3])[0] == ""


def test_springpot_negative_dent_fails(springpot_run):
    case, runs = springpot_run
    _, r, rows, _ = runs[2]
    rows = dict(rows, x2=rows["x2"].copy())
    rows["x2"][len(rows["x2"]) // 2] = -1e-9 * rows["x2"].max()
    assert sp_failing(case, r, rows) == {springpot.DENT}


def test_springpot_active_damper_fails(springpot_run):
    case, runs = springpot_run
    _, r, rows, _ = runs[2]
    rows = dict(rows, E_diss=rows["E_diss"].copy())
    rows["E_diss"][1] = -1e-9 * rows["E_diss"].max()
    assert springpot.PASSIVE in sp_failing(case, r, rows)


def test_springpot_created_energy_and_identity_fail(springpot_run):
    case, runs = springpot_run
    _, r, rows, _ = runs[2]
    faster = dict(rows, v=rows["v"] * (1 + 1e-9))  # the striker leaves with 2e-9 more energy than it had
    assert springpot.ENERGY in sp_failing(case, r, faster)
    more = dict(rows, E_diss=rows["E_diss"] * (1 + 1e-5))  # 1e-5 of the work above what the state holds
    assert sp_failing(case, r, more) == {springpot.IDENTITY}


def test_springpot_eps_out_of_range_fails(springpot_run):
    case, runs = springpot_run
    _, r, rows, _ = runs[2]
    for eps in (1 + 1e-9, -1e-9):
        bad = dataclasses.replace(r, per_impact=[dataclasses.replace(r.per_impact[0], eps=eps)])
        assert sp_failing(case, bad, rows) == {springpot.EPS}


def test_springpot_memories_disagreeing_fails(springpot_run):
    """Memory 1's F_peak 3e-5 off: its tolerance at dt = t_c/1230 is 1.1e-5 (K1 h1^2) + 1.7e-6 (K2 (h2^2 +
    lambda)) + 1e-6 (the kernel's tolerance)."""
    case, runs = springpot_run
    p1, r1, rows1, _ = runs[1]
    off = dataclasses.replace(r1, per_impact=[dataclasses.replace(r1.per_impact[0],
                                                                  F_peak=r1.per_impact[0].F_peak * (1 + 3e-5))])
    why, _ = springpot.agreement(case, (p1, off, rows1), runs[2][:3])
    assert why.startswith("F_peak off"), why


def test_springpot_memories_disagreeing_on_the_dent_left_fails(springpot_run):
    """Memory 1's x2_end 1e-4 of the largest x2 off: its tolerance at dt = t_c/1230 is 3.2e-5 (K1 h1^2,
    K1 = 48) + 1.0e-5 (K2 (h2^2 + lambda), K2 = 14) + 1e-6 (the kernel's tolerance), 4.3e-5; the two
    memories' own x2_end agree within it."""
    case, runs = springpot_run
    p1, r1, rows1, _ = runs[1]
    shift = 1e-4 * float(abs(runs[2][2]["x2"]).max())
    off = dataclasses.replace(r1, per_impact=[dataclasses.replace(r1.per_impact[0],
                                                                  x2_end=r1.per_impact[0].x2_end + shift)])
    why, _ = springpot.agreement(case, (p1, off, rows1), runs[2][:3])
    assert why.startswith("x2_end off"), why
    assert springpot.agreement(case, runs[1][:3], runs[2][:3])[0] == ""
