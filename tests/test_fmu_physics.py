"""The force through the FMU against what is known independently of it:
closed forms (MODEL.md §2-§4) and a high-accuracy solve of the same ODE
with scipy."""

import math

import numpy as np
import pytest
from scipy_contact import solve_drop

from fmu_driver import C, K, M, run_impact

GAMMA_5_2 = 0.75 * math.sqrt(math.pi)


def g1_line_ratio(N):
    """Gamma(N + 3/2) / (Gamma(N) N^(3/2)), MODEL.md §4, by Python's lgamma."""
    return math.exp(math.lgamma(N + 1.5) - math.lgamma(N) - 1.5 * math.log(N))


def hertz_k(R, E_i, nu_i, E_s, nu_s):
    return 4.0 / 3.0 * math.sqrt(R) / ((1 - nu_i ** 2) / E_i + (1 - nu_s ** 2) / E_s)


def reference_drop(k, c, m, v0, method="DOP853", rtol=1e-13):
    """The drop test's ODE by scipy (scripts/scipy_contact.py), independent
    of the C code: F_peak, eps, t_contact, x2, E_diss of the first impact."""
    r = solve_drop(k, c, m, v0, method=method, rtol=rtol)
    return {key: r[key] for key in ("F_peak", "eps", "t_contact", "x2", "E_diss")}


# --- driven scene: constant rate, rigid dashpot -> x1 = v t exactly ---------

def driven(slave, law, g1_nodes=0, k=K, **extra):
    v, H = 0.5, 1e-6
    s = slave(scene=2, m=0.0, v=v, c=1e20, law=law, g1_nodes=g1_nodes, k=k, dt_max=1e-7, **extra)
    rows = []
    for n in range(1, 41):
        s.step(H)
        rows.append((n * H, 10 * n, s.get("F"), s.get("semi_integral"), s.get("x1")))
    return v, rows


# x1 is a sum of up to 400 steps of v h: rounding ~1e-13 relative; the dashpot
# (c = 1e20) moves by F t / c ~ 1e-22 m against x1 ~ 1e-5 m.
DRIVEN_RTOL = 1e-11


def test_driven_hertz_law_is_k_x1_to_the_3_2(slave):
    v, rows = driven(slave, law=2)
    for t, N, F, semi, x1 in rows:
        assert x1 == pytest.approx(v * t, rel=DRIVEN_RTOL)
        assert F == pytest.approx(K * (v * t) ** 1.5, rel=DRIVEN_RTOL)
        assert semi == pytest.approx((v * t) ** 1.5 / GAMMA_5_2, rel=DRIVEN_RTOL)


def test_driven_g1_law_has_the_straight_line_error(slave):
    """N = internal steps since onset: 10 per communication step of 1 us."""
    v, rows = driven(slave, law=1)
    for t, N, F, semi, x1 in rows:
        assert F == pytest.approx(K * (v * t) ** 1.5 * g1_line_ratio(N), rel=DRIVEN_RTOL)
        assert semi == pytest.approx((v * t) ** 1.5 / GAMMA_5_2 * g1_line_ratio(N), rel=DRIVEN_RTOL)
    # The first-order error of MODEL.md §4: 1 + 3/(8N) to O(N^-2).
    t, N, F, _, _ = rows[-1]
    assert F / (K * (v * t) ** 1.5) - 1 == pytest.approx(3 / (8 * N), rel=5 / N)


def test_driven_g1_law_with_fixed_nodes(slave):
    v, rows = driven(slave, law=1, g1_nodes=7)
    for t, N, F, semi, x1 in rows:
        assert F == pytest.approx(K * (v * t) ** 1.5 * g1_line_ratio(7), rel=DRIVEN_RTOL)


def test_k_zero_derives_k_from_the_materials(slave):
    materials = dict(R=6.35e-3, E_i=210e9, nu_i=0.3, E_s=2.64e9, nu_s=0.4)
    k = hertz_k(**materials)
    v, rows = driven(slave, law=2, k=0.0, **materials)
    for t, N, F, semi, x1 in rows:
        assert F == pytest.approx(k * (v * t) ** 1.5, rel=DRIVEN_RTOL)
    # MODEL.md §6: the paper's E_s = 2.64 GPa is consistent with its k.
    assert k == pytest.approx(K, rel=2e-3)


# --- drop test --------------------------------------------------------------

def test_elastic_limit_matches_hertz_closed_forms(slave):
    """c -> infinity: pure Hertz impact (MODEL.md §2)."""
    s = slave(law=2, c=1e15)
    v0 = s.get("v")
    x_max = (5 * M * v0 ** 2 / (4 * K)) ** 0.4
    H, x1_max = 1e-6, 0.0
    while s.get("eps") == 0.0:
        s.step(H)
        x1_max = max(x1_max, s.get("x1"))
    r = run_impact(s)
    # The scheme errs by ~(dt/t_c)^2 ~ 1e-8; sampling x1 every H misses its
    # maximum by at most (pi H / t_c)^2 / 8 ~ 7e-7; the closed-form contact
    # time's constant is given to 6 digits.
    assert r["F_peak"] == pytest.approx(K * x_max ** 1.5, rel=1e-7)
    assert x1_max == pytest.approx(x_max, rel=2e-6)
    assert r["t_contact"] == pytest.approx(2.94327 * x_max / v0, rel=5e-6)
    assert r["eps"] == pytest.approx(1.0, abs=1e-7)


@pytest.fixture(scope="module")
def h20_reference():
    return reference_drop(K, C, M, math.sqrt(2 * 9.81 * 0.020))


def test_reference_is_converged(h20_reference):
    """The reference itself: an implicit method (Radau) at rtol 1e-12, with
    its own error estimate, agrees with it to 1e-9, far inside the 1e-6 the
    FMU is held to."""
    radau = reference_drop(K, C, M, math.sqrt(2 * 9.81 * 0.020), method="Radau", rtol=1e-12)
    for key in ("F_peak", "eps", "t_contact", "x2", "E_diss"):
        assert radau[key] == pytest.approx(h20_reference[key], rel=1e-9), key


@pytest.mark.parametrize("H", [1e-5, 3.3e-6])
def test_drop_hertz_law_matches_the_reference(slave, h20_reference, H):
    """Law 2 at the defaults (dt_max = 1e-7): the scheme's second-order error
    is ~(dt/t_c)^2 = 6e-9 with t_c = 1.3 ms; the issue's 1e-5 bound leaves a
    wide margin, so we hold it to 1e-6. The communication step (1e-5, and a
    step that is no multiple of dt_max) must not matter."""
    s = slave(law=2, v=math.sqrt(2 * 9.81 * 0.020))
    r = run_impact(s, H=H)
    for key in ("F_peak", "eps", "t_contact", "x2", "E_diss"):
        assert r[key] == pytest.approx(h20_reference[key], rel=1e-6), key


def test_drop_momentum_identity(slave):
    """x2_end = m v0 (1 + eps) / c holds to rounding for both laws: the scheme
    keeps the linear invariant m v + c x2 exactly."""
    for law in (1, 2):
        s = slave(law=law)
        v0 = s.get("v")
        r = run_impact(s)
        assert r["x2"] == pytest.approx(M * v0 * (1 + r["eps"]) / C, rel=1e-12)


def test_drop_g1_law_with_fixed_nodes_matches_its_reference(slave):
    """With N fixed the G1 law is Hertz with k Gamma(N+3/2)/(Gamma(N) N^1.5):
    the same ODE, so the same reference and the same tolerance."""
    N = 10
    s = slave(law=1, g1_nodes=N)
    v0 = s.get("v")
    ref = reference_drop(K * g1_line_ratio(N), C, M, v0)
    r = run_impact(s)
    for key in ("F_peak", "eps", "t_contact", "x2", "E_diss"):
        assert r[key] == pytest.approx(ref[key], rel=1e-6), key


def test_drop_g1_law_converges_to_hertz_at_first_order(slave, h20_reference):
    """N = steps since onset: the G1 error 3/(8N) shrinks with the step, so
    law 1 approaches law 2 linearly in dt_max."""
    errors = []
    for dt in (4e-7, 2e-7, 1e-7):
        s = slave(law=1, dt_max=dt, v=math.sqrt(2 * 9.81 * 0.020))
        errors.append(abs(run_impact(s)["F_peak"] / h20_reference["F_peak"] - 1))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(orders - 1) < 0.1), (errors, orders)


def test_energy_balance_through_the_outputs(slave):
    """1/2 m v0^2 = 1/2 m v^2 + (2/5) k x1^(5/2) + E_diss at every
    communication point, to the scheme's O(dt^2) ~ 1e-8."""
    s = slave(law=2)
    v0 = s.get("v")
    E0 = 0.5 * M * v0 ** 2
    while s.t < 2e-3:
        s.step(2e-5)
        x1 = s.get("x1")
        E = 0.5 * M * s.get("v_striker") ** 2 + 0.4 * K * x1 ** 2.5 + s.get("E_diss")
        assert E == pytest.approx(E0, rel=1e-7)
