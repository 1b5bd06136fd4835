"""The springpot damper F = c_alpha D^alpha x2 (docs/model.md §5-§6) and
the general spring exponent n, against what is known independently of the C
code: closed forms (the power rule, the fractional Maxwell model's
Mittag-Leffler function computed here with mpmath, the elastic contact time
of k x1^n), the dashpot model at alpha = 1, the GSL reference, identities
(energy, impulse, passivity), the exact kernel, and the other memory.

Every tolerance is derived in a comment from the method's known error:

- memory = 2 (compressed): the fixed step (docs/model.md §11) on the Prony
  modes, each exact for free relaxation and steady flow, so a mode driven at
  a constant rate is exact at every step and pulls the exact force averaged
  over the step; summed over the kernel's modes this gives the rigid
  spring's error in closed form (test 1). Where x2'' != 0 the stiff modes
  (b h > 1) add a term in h^(2 - alpha) or so: an order between 2 - alpha and
  2 as h -> 0 (measured, test 2).
- memory = 1 (full G1 history): the shifted G1 sum (1 + alpha/2) G_n -
  (alpha/2) G_(n-1), second order, with BDF2 for the striker; for x2 = v t
  it is an exact Gamma-function ratio (test 1).
- the kernel tolerance (memory_tolerance, default 1e-6) bounds the kernel's
  relative error on [dt_max, 1000 s], and with it the force's.
"""

import json
import math
import os
import pathlib
import struct
import subprocess

import mpmath
import numpy as np
import pytest
from fmpy.fmi1 import FMICallException
from scipy.special import beta as beta_function
from scipy.special import gamma as gamma_function

import fraccontact

from closed_forms import EPS

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOLVE = os.environ.get("FRACCONTACT_SOLVE", str(ROOT / "build" / "fraccontact-solve"))
IMPACT_KEYS = ("F_peak", "eps", "t_contact", "x2_end", "E_diss")
M_STRIKER, V0 = 0.7437, 0.626418   # the h20 drop test's striker (the defaults)


def reference(*args):
    """GSL's high-accuracy solve of the same drop test (fraccontact-solve
    --reference, rtol 1e-12): the dashpot model with any spring exponent."""
    done = subprocess.run([SOLVE, "--reference", "--json", *map(str, args)], capture_output=True, text=True,
                          timeout=600)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


# The fixed step on an undamped oscillator of frequency w (docs/model.md §11:
# the discrete gradient of a quadratic energy, the implicit midpoint rule)
# advances its phase by 2 atan(w h/2) a step: it lags by (w h)^3/12, and
# keeps the amplitude exactly.
C3 = 1.0 / 12.0

# The driven scene's rate and springpot constant of the closed-form runs.
V = 0.1       # m/s
C_ALPHA = 1e3  # N s^alpha/m


# --------------------------------------------------------------- references

def mittag_leffler_series(alpha, z):
    """E_{alpha,2}(z) = sum_j z^j / Gamma(alpha j + 2) by its defining series
    in mpmath. For z < 0 the terms grow to about exp(|z|^(1/alpha)) before
    they cancel: that many digits more than the 30 kept. alpha is taken as
    the double the model uses (mpf(alpha) is exact)."""
    extra = int(abs(z) ** (1.0 / alpha) / math.log(10)) + 30
    with mpmath.workdps(extra):
        a, z = mpmath.mpf(alpha), mpmath.mpf(z)
        total, j = mpmath.mpf(0), 0
        while True:
            term = z ** j / mpmath.gamma(a * j + 2)
            total += term
            if j > 10 and abs(term) < mpmath.mpf(10) ** (-extra + 5):
                return float(total)
            j += 1


def maxwell_g(alpha, lam, t):
    """t E_{alpha,2}(-lam t^alpha): the inverse Laplace transform of
    s^(alpha-2)/(s^alpha + lam) (docs/model.md §5), by Talbot's contour in
    mpmath at 30 digits. F(t) = k v maxwell_g(t) for the linear spring n = 1
    in series with the springpot driven at v from t = 0."""
    if t <= 0.0:
        return 0.0
    with mpmath.workdps(30):
        a, lam_ = mpmath.mpf(alpha), mpmath.mpf(lam)
        return float(mpmath.invertlaplace(lambda s: s ** (a - 2) / (s ** a + lam_), t, method="talbot"))


def step_average_ratio(alpha, n):
    """F_n / (c v t^(1-alpha)/Gamma(2-alpha)) of the fixed step on the EXACT
    kernel after n steps of a rigid spring driven at v (x2 = v t): the
    kernel t^-alpha/Gamma(1-alpha) is a continuum of modes phi_b' = -b phi_b
    + v, each of which the step keeps exact at a constant rate (it is exact
    for free relaxation and steady flow, docs/model.md §11), and whose pull
    over step n is b^(alpha-1)-weighted (v/b)(1 - (e^(-b t_(n-1)) - e^(-b t_n))/(b h)):
    the exact mode's force averaged over the step. So F_n is the power
    rule's force averaged over [t_(n-1), t_n]:
        ratio = (n^(2-alpha) - (n-1)^(2-alpha)) / ((2 - alpha) n^(1-alpha)).
    The rigid spring is far too stiff for the step (z = h lambda ~ 1e22), so
    the step's force is the spring's at its end (theta = 1 - 2/z), which
    the output F is."""
    return (n ** (2 - alpha) - (n - 1) ** (2 - alpha)) / ((2 - alpha) * n ** (1 - alpha))


def shifted_g1_rigid_ratio(alpha, j):
    """F_j / (c v h^(1-alpha)/Gamma(2-alpha)) of memory = 1 for x2 = v t on
    its grid: G_j = sum_{i<j} w_i x2_(j-i) = v h Gamma(j+1-alpha)/(Gamma(2-alpha) Gamma(j))
    (docs/model.md §4's straight-line sum with order alpha), F_j = c h^-alpha
    ((1 + alpha/2) G_j - (alpha/2) G_(j-1)), and the first step (backward
    Euler, no shift) F_1 = c h^-alpha G_1 = c v h^(1-alpha)."""
    if j == 1:
        return math.gamma(2 - alpha)
    return ((1 + alpha / 2) * math.exp(math.lgamma(j + 1 - alpha) - math.lgamma(j))
            - (alpha / 2) * math.exp(math.lgamma(j - alpha) - math.lgamma(j - 1)))


def observed_order(e_coarse, e_fine):
    return math.log2(abs(e_coarse / e_fine))


@pytest.mark.parametrize("alpha, z", [(0.2, -3.0), (0.3, -3.0), (0.5, -5.0), (0.8, -4.0), (0.5, -0.01)])
def test_mittag_leffler_by_series_and_by_laplace_inversion_agree(alpha, z):
    """Two independent routes to the reference: the series at up to 135
    digits and Talbot's inversion at 30; each rounds once to a double (an ulp
    each; the talbot integral carries about 1e-25): 4 EPS."""
    t = 1.0
    lam = -z
    assert maxwell_g(alpha, lam, t) == pytest.approx(t * mittag_leffler_series(alpha, z), rel=4 * EPS, abs=0)


def test_mittag_leffler_at_alpha_1_is_the_dashpot_exponential():
    """E_{1,2}(-x) = (1 - e^-x)/x: the Maxwell model's c v (1 - e^(-k t/c))."""
    lam, t = 3.0, 0.7
    assert maxwell_g(1.0, lam, t) == pytest.approx(-math.expm1(-lam * t) / lam, rel=4 * EPS, abs=0)
    assert mittag_leffler_series(1.0, -lam * t) * t == pytest.approx(-math.expm1(-lam * t) / lam, rel=4 * EPS, abs=0)


# ------------------------------------------- 1. a rigid spring: x2 = v t

# A linear spring (n = 1, law = 2) of k = 1e30 N/m in series: x1 = F/k is
# 1e-30 of x, so x2 = v t to 1e-27 relative (the fractional Maxwell
# correction Gamma(2-alpha)/Gamma(2-2alpha) (c/k) t^-alpha is 1e-24 at t = 1e-5 s).
RIGID = dict(scene=2, m=0.0, v=V, damper=2, c_alpha=C_ALPHA, spring_exponent=1, law=2, k=1e30)


def rigid_rows(alpha, memory, h, n_end, every, **extra):
    s = fraccontact.simulate(output_interval=every * h, damper_order=alpha, memory=memory, dt_max=h,
                             t_end=n_end * h, **RIGID, **extra)
    t, F = s["t"][1:], s["F"][1:]
    return t, F, np.rint(t / h).astype(int)


def power_rule(alpha, t):
    """docs/model.md §5: F = c_alpha v t^(1-alpha)/Gamma(2-alpha) for x2 = v t."""
    return C_ALPHA * V * t ** (1 - alpha) / math.gamma(2 - alpha)


@pytest.mark.parametrize("alpha", [0.2, 0.5, 0.8])
def test_rigid_spring_compressed_memory_is_the_step_average_of_the_exact_kernel(alpha):
    """memory = 2 against the power rule. Two parts of its error: the
    step's, known exactly (step_average_ratio, the exact kernel); and the
    kernel's sum of exponentials, whose relative error is at most
    memory_tolerance on [dt_max, 1000 s] (test 6). The lumped dashpot eta
    stands for the modes faster than the kernel's cut x/dt_max (x ~ 20),
    which the step takes at their steady viscosity, exact once their
    relaxation, e^(-x) per step at most, is over: from n = 20 it is below
    1e-8. So F/(power rule x the step's ratio) - 1 is within the tolerance
    (1e-6 default). The closed form is then met with the step average's
    lag, ratio - 1 = -(1 - alpha)/(2 n) + O(n^-2)."""
    h, tol = 1e-5, 1e-6
    t, F, n = rigid_rows(alpha, 2, h, 100, 20)
    assert list(n) == [20, 40, 60, 80, 100]
    for ti, Fi, ni in zip(t, F, n):
        ratio = step_average_ratio(alpha, int(ni))
        assert Fi / (power_rule(alpha, ti) * ratio) - 1 == pytest.approx(0, abs=tol, rel=0)
        # ratio's expansion: -(1-alpha)/(2n) + (1-alpha)(-alpha)/(6 n^2) + O(n^-3); the n^-2 term bounds the rest
        assert ratio - 1 == pytest.approx(-(1 - alpha) / (2 * ni), abs=(1 - alpha) / (6 * ni ** 2), rel=0)


@pytest.mark.parametrize("alpha", [0.2, 0.5, 0.8])
def test_rigid_spring_full_history_is_the_shifted_g1_sum(alpha):
    """memory = 1 against the exact Gamma-function value of its own scheme
    (shifted_g1_rigid_ratio) at every step: the G1 sum of j terms is
    compensated (a few ulp), h^alpha and the stage's solve a few more; the
    power rule's F is the difference of two terms (t/h)^alpha ~ 40 times
    larger at j = 100, alpha = 0.8: 40 x 8 EPS ~ 7e-14; the prediction's
    exponents carry an ulp of lgamma(100) = 359 each, 6e-14 (measured
    1.7e-13 in all): 1e-12.
    And against the power rule: the shift cancels G1's 1/j term, leaving
    alpha (1-alpha^2)(2+3 alpha)/24 / j^2 (expanding Gamma(j+a)/Gamma(j)
    to 1/j^2), times 1 + c/j + ...: c = 0.203, 0.536, 0.916 for alpha = 0.2,
    0.5, 0.8 (the exact ratio in mpmath at j = 1e6), at most 0.994 at j >= 10:
    rel = 1/j. The observed order between j and 2j is then 2 + log2((1 +
    c/j)/(1 + c/2j)) ~ 2 + c/(2 j ln 2): |p - 2| <= 1/(j ln 2)."""
    h = 1e-5
    t, F, n = rigid_rows(alpha, 1, h, 100, 1)
    err = {}
    for ti, Fi, ji in zip(t, F, n):
        ji = int(ji)
        predicted = C_ALPHA * V * h ** (1 - alpha) / math.gamma(2 - alpha) * shifted_g1_rigid_ratio(alpha, ji)
        assert Fi == pytest.approx(predicted, rel=1e-12, abs=0)
        err[ji] = Fi / power_rule(alpha, ti) - 1
    lead = alpha * (1 - alpha ** 2) * (2 + 3 * alpha) / 24
    for j in (10, 25, 50):
        assert err[j] == pytest.approx(lead / j ** 2, rel=1.0 / j, abs=0)
        assert observed_order(err[j], err[2 * j]) == pytest.approx(2.0, abs=1.0 / (j * math.log(2)), rel=0)


# ------------------------- 2. a linear spring in series: fractional Maxwell

# n = 1 (law = 2) and the springpot driven at V from t = 0 over T = 2 ms,
# k = 3 c_alpha / T^alpha so that lambda T^alpha = 3: the force has relaxed
# well away from the spring's k v t by the end. memory_tolerance = 1e-10
# keeps the kernel's share (<= 1e-10 of F) far below the discretisation
# errors being measured (>= 1e-9).
MAXWELL_T = 2e-3


def maxwell_k(alpha):
    return 3.0 * C_ALPHA / MAXWELL_T ** alpha


def maxwell_run(alpha, memory, steps, every=MAXWELL_T / 16):
    """F at the rows every T/16 from T/4 to T (read where they fall: memory =
    1 may end a step past t_end, its time a sum of steps), and those times."""
    k = maxwell_k(alpha)
    s = fraccontact.simulate(output_interval=every, scene=2, m=0.0, v=V, damper=2, damper_order=alpha,
                             c_alpha=C_ALPHA, memory=memory, spring_exponent=1, law=2, k=k,
                             dt_max=MAXWELL_T / steps, t_end=MAXWELL_T, memory_tolerance=1e-10)
    keep = s["t"] > MAXWELL_T / 4 - 1e-9
    return s["t"][keep], s["F"][keep]


def maxwell_error(alpha, memory, steps):
    """The largest relative error over [T/4, T] (a norm: the error of either
    memory changes sign somewhere in t, where a pointwise order means nothing)."""
    k = maxwell_k(alpha)
    t, F = maxwell_run(alpha, memory, steps)
    exact = np.array([k * V * maxwell_g(alpha, k / C_ALPHA, ti) for ti in t])
    return np.max(abs(F / exact - 1))


# Bands for the observed order of the largest error over [T/4, T] between
# T/400 and T/800, from theory and what it leaves open:
# - memory = 2: error A h^2 + B h^(2-alpha) (SDIRK2 plus its stiff modes'
#   order reduction where x2'' != 0; test_compressed_memory_error_is_...):
#   an order between 2 - alpha and 2, approaching 2 - alpha; measured 2.00
#   (alpha 0.2), 1.87 (0.5), 1.37 (0.8), 2.00 (alpha = 1: a dashpot, no modes).
# - memory = 1: second order (test 1), approached from below by the start's
#   nonsmooth x2 ~ t^(1+alpha) (alpha 0.5: 1.80, 1.84, 1.88, 1.91 from T/100
#   to T/1600); measured 2.09 (0.2), 1.88 (0.5), 1.99 (0.8), 2.00 (1): [1.8, 2.2].
@pytest.mark.parametrize("memory", [1, 2])
@pytest.mark.parametrize("alpha", [0.2, 0.5, 0.8, 1.0])
def test_linear_spring_meets_the_mittag_leffler_force_at_the_measured_order(alpha, memory):
    """F(t) = k v t E_{alpha,2}(-(k/c_alpha) t^alpha) (docs/model.md §5): an
    error that falls at the scheme's order proves the limit (a wrong closed
    form would leave a floor, and an order near 0); the band's lower edge p
    bounds the error at T/800 by Richardson's (e(T/400) - e(T/800))/(2^p - 1).
    Measured errors at T/800: 1.4e-7 to 6.3e-6 (memory 1, alpha 1)."""
    coarse, fine = maxwell_error(alpha, memory, 400), maxwell_error(alpha, memory, 800)
    low, high = (2 - alpha - 0.1, 2.1) if memory == 2 and alpha < 1 else (1.8, 2.2)
    order = observed_order(coarse, fine)
    print(f"Maxwell alpha {alpha} memory {memory}: max error {coarse:.2e} (T/400), {fine:.2e} (T/800), "
          f"order {order:.2f}")
    assert low <= order <= high


def test_linear_spring_at_alpha_1_is_the_maxwell_exponential():
    """alpha = 1 with memory = 2 is the dashpot (no modes, eta = 1):
    F = c v (1 - e^(-k t/c)) up to SDIRK2's error, whose observed order
    from T/400 to T/800 is 2 to within the next term's O(h) (measured 2.00)."""
    k, c = maxwell_k(1.0), C_ALPHA
    errors = []
    for steps in (400, 800):
        t, F = maxwell_run(1.0, 2, steps)
        errors.append(np.max(abs(F / (c * V * -np.expm1(-k * t / c)) - 1)))
    assert observed_order(*errors) == pytest.approx(2.0, abs=0.05, rel=0)


@pytest.mark.parametrize("alpha", [0.5, 0.8, 0.95])
def test_compressed_memory_error_is_a_h2_plus_b_h_to_2_minus_alpha(alpha):
    """The compressed memory's order, measured on the Maxwell closed form at
    T/2 over six steps T/100 ... T/3200: SDIRK2 has stage order 1, so a
    stiff mode (b h >> 1) tracks x2'/b but misses x2''/b^2; summed over the
    kernel's modes with weight b^(alpha-1) from 1/h up that is
    x2'' h^(2-alpha). The error fits A h^2 + B h^(2-alpha) to a fraction of
    a percent (measured 0.1 %: rounding and the next terms; 2 % allowed),
    and no single power does (h^2 alone misses by 10 % and more).
    This is a measured limitation of memory = 2 (designed second order): as
    h -> 0 its order is 2 - alpha where x2'' != 0."""
    h, e = [], []
    k = maxwell_k(alpha)
    for steps in (100, 200, 400, 800, 1600, 3200):
        t, F = maxwell_run(alpha, 2, steps, every=MAXWELL_T / 2)
        h.append(MAXWELL_T / steps / t[0])
        e.append(F[0] / (k * V * maxwell_g(alpha, k / C_ALPHA, t[0])) - 1)
    h, e = np.array(h), np.array(e)
    basis = np.c_[h ** 2, h ** (2 - alpha)]
    coef, *_ = np.linalg.lstsq(basis / abs(e)[:, None], np.sign(e), rcond=None)
    assert np.all(abs(e / (basis @ coef) - 1) < 0.02), (e, coef)
    only_h2, *_ = np.linalg.lstsq((h ** 2 / abs(e))[:, None], np.sign(e), rcond=None)
    assert np.max(abs(e / (h ** 2 * only_h2[0]) - 1)) > 0.1
    orders = [observed_order(e[i], e[i + 1]) for i in range(len(e) - 1)]
    print(f"alpha {alpha}: compressed memory orders T/100..T/3200:", " ".join(f"{p:.2f}" for p in orders))
    assert orders[-1] < orders[0]          # falling towards 2 - alpha
    assert orders[-1] > 2 - alpha - 0.05


# The drive stops at t1 = T/2 (the FMU's input v set to 0 there, m = 0): x is
# held from then on, and by superposition F = k v [g(t) - g(t - t1)].
# (memory 1's BDF2 restarts with one backward-Euler step when the master
# changes v: found by these tests, its old v used to carry on.)


def driven_slave(slave, alpha, memory, steps):
    return slave(scene=2, m=0.0, v=V, damper=2, damper_order=alpha, c_alpha=C_ALPHA, memory=memory,
                 spring_exponent=1, law=2, k=maxwell_k(alpha), dt_max=MAXWELL_T / steps, memory_tolerance=1e-10)


def relaxation_error(slave, alpha, memory, steps):
    """The largest relative error against superposition over (t1, T], at
    communication points every T/16 (whole multiples of dt_max)."""
    s = driven_slave(slave, alpha, memory, steps)
    k, lam, t1, H = maxwell_k(alpha), maxwell_k(alpha) / C_ALPHA, MAXWELL_T / 2, MAXWELL_T / 16
    worst = 0.0
    for i in range(16):
        if i == 8:
            s.set(v=0.0)
        s.step(H)
        if i >= 8:
            exact = k * V * (maxwell_g(alpha, lam, s.t) - maxwell_g(alpha, lam, s.t - t1))
            worst = max(worst, abs(s.get("F") / exact - 1))
    return worst


@pytest.mark.parametrize("memory", [2, 1])
@pytest.mark.parametrize("alpha", [0.5, 0.8])
def test_relaxation_after_the_drive_stops_is_superposition(slave, alpha, memory):
    """The same bands as the loading above (the drive's stop is a new
    nonsmooth start for the second term); measured (memory 2) orders 1.90
    (alpha 0.5), 1.37 (0.8), errors 1.0e-6 and 2.2e-6 at T/800; memory 1
    (BDF2 restarted at the stop) 2.04 and 2.00, errors 2.2e-6 and 6.9e-6."""
    coarse, fine = relaxation_error(slave, alpha, memory, 400), relaxation_error(slave, alpha, memory, 800)
    order = observed_order(coarse, fine)
    print(f"relaxation alpha {alpha} memory {memory}: max error {coarse:.2e}, {fine:.2e}, order {order:.2f}")
    low, high = (2 - alpha - 0.1, 2.1) if memory == 2 else (1.8, 2.2)
    assert low <= order <= high


@pytest.mark.parametrize("memory", [2, 1])
def test_a_stopped_drive_holds_the_indentation(slave, memory):
    """m = 0 prescribes the rate: after v := 0 the striker stands still,
    v_striker = 0 and x = v t1 whatever the damper's memory does inside:
    x1 and x2 each change by the damper's travel, rounded (an ulp of x2 < x
    per internal step, at most one per 1e-5 s): N EPS after N steps.
    Communication steps of 1 and 10 dt_max."""
    for H in (1e-5, 1e-4):
        s = slave(scene=2, m=0.0, v=V, damper=2, damper_order=0.5, c_alpha=C_ALPHA, memory=memory,
                  spring_exponent=1, law=2, k=1e5, dt_max=1e-5)
        for _ in range(round(1e-3 / H)):
            s.step(H)
        held = s.get("x")
        assert held == pytest.approx(V * 1e-3, rel=1e-12, abs=0)
        s.set(v=0.0)
        for i in range(1, round(1e-3 / H) + 1):
            s.step(H)
            assert s.get("v_striker") == 0.0
            assert s.get("x") == pytest.approx(held, rel=i * H / 1e-5 * EPS, abs=0)


# -------------------------------- 3. alpha = 1: the springpot is the dashpot

OUTPUTS = ["F", "F_avg", "F_peak", "x", "x1", "x2", "v_striker", "eps", "semi_integral"]


@pytest.mark.parametrize("law", [1, 2])
def test_alpha_1_compressed_memory_is_the_dashpot(slave, law):
    """At alpha = 1 the kernel is eta = 1 and no modes (test 6): each fixed
    step's damper rate is (F - 0)/(c_alpha (1 + 0)), the dashpot's F/c,
    so every output of the drop test through the contact and the flight
    after it matches the dashpot model's (damper 1, c = c_alpha) to 1e-9
    (the issue's figure; x2 sums the same stage rates in another order, a
    few ulp; measured 3e-15). E_diss: the next test."""
    common = dict(law=law, dt_max=1e-7)
    springpot = slave(damper=2, damper_order=1.0, c_alpha=6080.0, memory=2, **common)
    dashpot = slave(damper=1, c=6080.0, **common)
    for _ in range(200):   # 2 ms: the contact ends at 1.32 ms
        springpot.step(1e-5)
        dashpot.step(1e-5)
        for name in OUTPUTS:
            assert springpot.get(name) == pytest.approx(dashpot.get(name), rel=1e-9, abs=0), name
    assert springpot.get("eps") > 0


def test_alpha_1_dissipated_energy_is_the_dashpots_to_1e_9():
    """Both count the mean force J/h times the step's travel (the springpot
    used to weigh its stages' F x2', 7.8e-9 away): equal up to rounding."""
    springpot = fraccontact.impact(damper=2, damper_order=1.0, c_alpha=3e5, memory=2, law=2)
    dashpot = fraccontact.impact(damper=1, c=3e5, law=2)
    assert springpot.E_diss == pytest.approx(dashpot.E_diss, rel=1e-9, abs=0)


def test_alpha_1_dissipated_energy_converges_with_the_dashpots():
    """Both counts of E_diss (the dashpot's J^2/(c h), the springpot's stage
    quadrature) are second order: their errors against the GSL reference
    fall 4x per halving (order 2 +- 0.1, measured 2.00 and 1.99) and at
    dt_max = 1e-7 are 1.17e-8 and 3.9e-9 (c = 3e5: little damping): the
    issue's 1e-9 between them is out of reach at the default step."""
    ref = reference("--c", 3e5, "--law", 2)
    for run in (lambda dt: fraccontact.impact(damper=2, damper_order=1.0, c_alpha=3e5, memory=2, law=2, dt_max=dt),
                lambda dt: fraccontact.impact(damper=1, c=3e5, law=2, dt_max=dt)):
        e = [run(dt).E_diss / ref["E_diss"] - 1 for dt in (1e-6, 5e-7)]
        assert observed_order(*e) == pytest.approx(2.0, abs=0.1, rel=0)


def test_alpha_1_full_history_is_second_order_to_the_dashpot_reference():
    """memory = 1 at alpha = 1 is BDF2 (G1 of order 1 is the backward
    difference, its shift makes it BDF2's), not SDIRK2: the dashpot model's
    solution only in the limit. Against the GSL reference, errors at dt_max =
    1e-6, 5e-7, 2.5e-7 fall at least at order 2 (measured: t_contact and
    E_diss 2.0, eps 2.7, x2_end 2.8-3.0, F_peak 1.8 and 2.4: it is sampled
    at the grid's points, the peak between them missed by O(h^2) with the
    grid's phase): every observed order >= 1.7; and the error at 2.5e-7 lies
    within the Richardson bound |Q(h) - Q(h/2)|/(2^1.7 - 1) that such an
    order implies (measured 0.33-0.75 of it; errors 1.6e-9 (x2_end) to
    4.5e-7 (E_diss) relative)."""
    ref = reference("--c", 3e5, "--law", 2)
    runs = [fraccontact.impact(damper=2, damper_order=1.0, c_alpha=3e5, memory=1, law=2, dt_max=dt)
            for dt in (1e-6, 5e-7, 2.5e-7)]
    for key in IMPACT_KEYS:
        q = [getattr(r, key) for r in runs]
        e = [x / ref[key] - 1 for x in q]
        assert observed_order(e[0], e[1]) >= 1.7, (key, e)
        assert observed_order(e[1], e[2]) >= 1.7, (key, e)
        assert abs(e[2]) <= abs(q[1] - q[2]) / abs(ref[key]) / (2 ** 1.7 - 1), (key, e)


# ------------------------ 4. the drop test's identities with a springpot

def spring_k(n):
    """A spring k x1^n as stiff as the h20 test's Hertz spring at x1 = 80 um."""
    return 3.299e8 * 8e-5 ** (1.5 - n)


def equivalent_c_alpha(alpha, c=6080.0, omega=2400.0):
    """A springpot as damping as the h20 dashpot at the impact's frequency
    pi/t_c (the default c_alpha's rule, parameters.c): c_alpha omega^alpha = c omega."""
    return c * omega ** (1 - alpha)


def identity_defects(slave, n, memory, dt_max, H=1e-5, t_end=2.5e-3):
    """Through the impact and the recovery after it (g = 0), at every
    communication point: the energy defect |1/2 m v0^2 - 1/2 m v^2 - k
    x1^(n+1)/(n+1) - E_diss| / (1/2 m v0^2), the impulse defect |m (v0 - v)
    - sum F_avg H| / (m v0), and E_diss, contact."""
    k = spring_k(n)
    s = slave(damper=2, memory=memory, spring_exponent=n, law=2, k=k, dt_max=dt_max)
    E0, impulse, rows = 0.5 * M_STRIKER * V0 ** 2, 0.0, []
    while s.t < t_end - 1e-12:
        s.step(H)
        impulse += s.get("F_avg") * H
        v, x1, E = s.get("v_striker"), s.get("x1"), s.get("E_diss")
        rows.append((abs(0.5 * M_STRIKER * v * v + k * x1 ** (n + 1) / (n + 1) + E - E0) / E0,
                     abs(M_STRIKER * (V0 - v) - impulse) / (M_STRIKER * V0), E, s.get("contact")))
    return np.array(rows)


@pytest.mark.parametrize("memory", [1, 2])
@pytest.mark.parametrize("n", [1.0, 1.5, 2.0])
def test_energy_and_impulse_identities_of_a_springpot_drop(slave, n, memory):
    """1/2 m v0^2 = 1/2 m v^2 + k x1^(n+1)/(n+1) + int F dx2 and m (v0 - v)
    = int F dt (docs/model.md §9, no gravity). Memory 2's fixed step keeps
    the first exactly (docs/model.md §11; E_diss is the work its step does on
    the damper), so its defect is rounding: a few ulp of the energy per
    internal step (2500 at most to 2.5 ms at 1e-6, 5000 at 5e-7; 4 ulp each).
    Memory 1's BDF2 does not: its defect is its error, second order, so the
    largest over the run falls 4x from dt_max = 1e-6 to 5e-7 (order 2 +- 0.2;
    measured 4.3e-6 to 6.0e-6 at 1e-6).
    Impulse: memory 2's velocity update is v - h F/m, exactly the impulse
    F_avg H reports, so it holds it to rounding: an ulp of v0 per internal
    step. Memory 1 reports the trapezoidal impulse while BDF2 moves v: order
    2 as above (measured 2.0, 1.5e-6 to 2.9e-6 at 1e-6)."""
    coarse = identity_defects(slave, n, memory, 1e-6)
    fine = identity_defects(slave, n, memory, 5e-7)
    energy = observed_order(coarse[:, 0].max(), fine[:, 0].max())
    print(f"n {n} memory {memory}: energy defect {coarse[:, 0].max():.2e} -> {fine[:, 0].max():.2e} "
          f"(order {energy:.2f}), impulse defect {coarse[:, 1].max():.2e}")
    if memory == 2:
        assert coarse[:, 0].max() <= 4 * 2500 * EPS and fine[:, 0].max() <= 4 * 5000 * EPS
        assert coarse[:, 1].max() <= 2500 * EPS
        assert fine[:, 1].max() <= 5000 * EPS
    else:
        assert energy == pytest.approx(2.0, abs=0.2, rel=0)
        assert observed_order(coarse[:, 1].max(), fine[:, 1].max()) == pytest.approx(2.0, abs=0.2, rel=0)
    assert coarse[-1, 3] == 0 and fine[-1, 3] == 0   # the impact ended


@pytest.mark.parametrize("memory", [1, 2])
@pytest.mark.parametrize("n", [1.0, 1.5, 2.0])
@pytest.mark.parametrize("alpha", [0.2, 0.5, 0.9])
def test_a_springpot_is_passive(slave, alpha, n, memory):
    """int F dx2 >= 0 at every communication point (the kernel is completely
    monotone: a Maxwell network of positive springs and dashpots, test 6,
    stores at most what was put in). Unlike a dashpot's it may fall, by what
    the springpot gives back while x2 falls under load (measured at most
    44-47 % of its peak at alpha 0.2, 9-11 % at 0.5, 0.1 % at 0.9, alike for
    both memories); after the separation F = 0 and it stays fixed, bit for
    bit. c_alpha as damping as the h20 dashpot at the impact's frequency."""
    k = spring_k(n)
    s = slave(damper=2, damper_order=alpha, c_alpha=equivalent_c_alpha(alpha), memory=memory, spring_exponent=n,
              law=2, k=k, dt_max=1e-6)
    E, contact = [], []
    while s.t < 2.5e-3 - 1e-12:
        s.step(1e-5)
        E.append(s.get("E_diss"))
        contact.append(s.get("contact"))
    E = np.array(E)
    assert np.all(E >= 0)
    separated = contact.index(False, contact.index(True))
    assert np.all(E[separated:] == E[separated])
    print(f"alpha {alpha} n {n} memory {memory}: E_diss falls by at most {largest_fall(E):.3f} of its peak")


def largest_fall(E):
    return np.max(np.maximum.accumulate(E) - E) / E.max()


@pytest.mark.parametrize("memory", [1, 2])
def test_what_a_springpot_gives_back_shrinks_to_nothing_at_alpha_1(slave, memory):
    """The energy a springpot stores and returns (the fall of int F dx2)
    comes from its spring-like part: the fall shrinks as alpha grows (the
    loss angle alpha pi/2 grows; measured 0.46, 0.10, 0.0009) and vanishes
    at alpha = 1, exactly: memory 2's stages add F x2' = F^2/c >= 0; memory
    1 adds (F_j + F_(j-1))/2 (x2_j - x2_(j-1)), and its shifted G1 of order
    1 is BDF2, x2_j - x2_(j-1) = (2/3) h F_j/c + (x2_(j-1) - x2_(j-2))/3 >= 0
    by induction while F >= 0."""
    falls = []
    for alpha in (0.2, 0.5, 0.9, 1.0):
        s = slave(damper=2, damper_order=alpha, c_alpha=equivalent_c_alpha(alpha), memory=memory, law=2,
                  dt_max=1e-6)
        E = []
        while s.t < 2.5e-3 - 1e-12:
            s.step(1e-5)
            E.append(s.get("E_diss"))
        falls.append(largest_fall(np.array(E)))
    assert falls[0] > falls[1] > falls[2] > falls[3]
    assert falls[3] == 0.0


def test_a_dashpots_dissipation_never_falls(slave):
    """The dashpot dissipates F^2/c >= 0 at every step: E_diss never falls."""
    s = slave(damper=1)
    previous = 0.0
    for _ in range(200):
        s.step(1e-5)
        assert s.get("E_diss") >= previous
        previous = s.get("E_diss")


# -------------- 5. orders of convergence of an h20 springpot impact

def springpot_impact(memory, dt_max, **extra):
    """The paper's h20 drop test with the default springpot (alpha 0.5,
    c_alpha 3e5), the closed-form spring (law 2: no step-count effect),
    kernel tolerance 1e-10 (its error far below the ones measured)."""
    return fraccontact.impact(damper=2, memory=memory, dt_max=dt_max, law=2, **{"memory_tolerance": 1e-10, **extra})


@pytest.fixture(scope="module")
def fine_impacts():
    """Each memory's fine-step result, the other's reference: memory 1 at
    6.25e-8 and 3.125e-8 s extrapolated (its order 2 measured: differences
    fall 4.0x), memory 2 at 7.8125e-9 s (error ~3e-11 by its measured order)."""
    m1 = [springpot_impact(1, dt) for dt in (6.25e-8, 3.125e-8)]
    m1_limit = {key: getattr(m1[1], key) + (getattr(m1[1], key) - getattr(m1[0], key)) / 3
                for key in ("F_peak", "eps", "t_contact", "E_diss")}
    return {1: m1_limit, 2: springpot_impact(2, 7.8125e-9)}


def impact_orders(memory, reference, keys, steps):
    errors = {key: [] for key in keys}
    for dt in steps:
        r = springpot_impact(memory, dt)
        for key in keys:
            ref = reference[key] if isinstance(reference, dict) else getattr(reference, key)
            errors[key].append(getattr(r, key) / ref - 1)
    for key in keys:
        e = errors[key]
        print(f"memory {memory} {key}: errors", " ".join(f"{x:.2e}" for x in e), " orders",
              " ".join(f"{observed_order(e[i], e[i + 1]):.2f}" for i in range(len(e) - 1)))
    return errors


def test_compressed_memory_impact_converges_to_the_full_history(fine_impacts):
    """memory 2 against memory 1's extrapolated fine result (which agrees
    with memory 2's own finest to 1e-10 in these figures). Its error is
    A h^2 + B h^(3/2) (alpha = 0.5, test 2), so the observed order lies near
    [1.5, 2], below 1.5 while the two terms still cancel; measured from
    dt_max 2.5e-7 to 6.25e-8: F_peak 1.33, 1.42 and E_diss 1.44, 1.47 rising
    to 1.5, t_contact 1.89, 1.81 falling to it: band [1.2, 2.1]. (eps crosses
    zero near 3e-7 s and is left out: its error is below 1e-9 there.)"""
    errors = impact_orders(2, fine_impacts[1], ("F_peak", "t_contact", "E_diss"), (2.5e-7, 1.25e-7, 6.25e-8))
    for key, e in errors.items():
        for i in range(2):
            # E_diss counts the mean force times the travel, and the fixed
            # step's peak force lies on its energy's exact balance: their
            # errors fall faster here (measured orders 2.53, 3.37 for E_diss,
            # 3.96 for F_peak, the last near the reference's 1e-10), so only
            # the floor is asserted for them.
            high = math.inf if key in ("E_diss", "F_peak") else 2.1
            assert 1.2 <= observed_order(e[i], e[i + 1]) <= high, (key, e)


def test_full_history_impact_converges_to_the_compressed_memory(fine_impacts):
    """memory 1 against memory 2's fine result: second order, measured from
    dt_max 5e-7 to 1.25e-7: eps 1.93, 1.95, t_contact 2.07, 1.94, E_diss
    2.02, 2.02: band [1.8, 2.2]. F_peak is sampled at memory 1's grid
    points (no located peak): its error adds up to F (pi h/t_c)^2/8 that
    moves with the grid's phase (printed, not asserted: measured 6.0e-7,
    1.3e-7, 4.1e-8, orders 2.25, 1.62; F_peak is checked at the default step
    by the next test)."""
    steps = (5e-7, 2.5e-7, 1.25e-7)
    errors = impact_orders(1, fine_impacts[2], ("eps", "t_contact", "E_diss", "F_peak"), steps)
    for key in ("eps", "t_contact", "E_diss"):
        e = errors[key]
        for i in range(2):
            assert 1.8 <= observed_order(e[i], e[i + 1]) <= 2.2, (key, e)


def test_the_memories_agree_at_the_default_step():
    """The issue's figure: F_peak and eps of both memories within 1e-4 at the
    default dt_max (1e-7) and memory_tolerance (1e-6). The difference is
    bounded by the kernel's error (the force's relative error <= the
    tolerance, test 1) plus both schemes' errors at 1e-7 (at most 4e-8
    relative by the orders above): 1.04e-6 (measured 1.5e-8 and 8.5e-9)."""
    m1 = fraccontact.impact(damper=2, memory=1, law=2)
    m2 = fraccontact.impact(damper=2, memory=2, law=2)
    for key in ("F_peak", "eps", "t_contact"):
        assert getattr(m2, key) == pytest.approx(getattr(m1, key), rel=1.04e-6, abs=0), key


def test_full_history_reports_the_dent_at_the_separation(fine_impacts):
    """x2_end of memory 1 against memory 2's (which locates the separation
    and stops there): second order, so within 1e-6 at dt_max = 5e-7 (memory
    1's other figures are within 3e-7 there). (Memory 1 ends a contact at the
    grid point after the separation; x2 is continued to the separation from
    the contact's side, where it is smooth.)"""
    r = springpot_impact(1, 5e-7)
    assert r.x2_end == pytest.approx(fine_impacts[2].x2_end, rel=1e-6, abs=0)


def test_full_history_locates_the_separation_at_second_order_at_small_alpha():
    """memory 1's t_contact and x2_end at alpha = 0.05 on the linear spring
    (the stability report's case "n 1, alpha 0.05": k and c_alpha as there,
    rounded) at dt = t_c/1000, /2000, /4000 against memory 2 at t_c/1e5 with
    its kernel to 1e-10 (its error K2 h^2 with K2 ~ 1, docs/stability.md:
    ~1e-10, a thousandth of memory 1's at t_c/4000): both converge at the
    order 2 (measured 2.00, 2.00 for t_contact, 2.02, 1.99 for x2_end): band
    [1.9, 2.2]. Past the separation F = 0 and x2 recovers with a second
    derivative ~ (t - t_s)^(alpha - 1): a secant across the separation's step
    erred at the order 1 + alpha with a constant that moves with the
    separation's place in the step (measured orders 0.77, 2.37 for t_contact
    and 0.82, 2.36 for x2_end)."""
    params = dict(damper=2, damper_order=0.05, spring_exponent=1.0, k=5.3347e6, c_alpha=9.8879e6, law=2)
    t_c = math.pi * math.sqrt(0.7437 / params["k"])  # the default m's elastic contact time on k
    reference = fraccontact.impact(memory=2, dt_max=t_c / 1e5, memory_tolerance=1e-10, **params)
    runs = [fraccontact.impact(memory=1, dt_max=t_c / n, **params) for n in (1000, 2000, 4000)]
    for key in ("t_contact", "x2_end"):
        e = [getattr(r, key) / getattr(reference, key) - 1 for r in runs]
        for i in range(2):
            assert 1.9 <= observed_order(e[i], e[i + 1]) <= 2.2, (key, e)


# ------------------------------------- 6. the compressed kernel's own error

SPAN = 1e3  # the kernel holds its tolerance from dt_max to 1000 s (contact.h)


def kernel_error(alpha, tol, dt_max, points=20000):
    """The largest relative error of sum_i a_i exp(-b_i tau) against
    tau^-alpha/Gamma(1-alpha) on a log grid of `points` over [dt_max, 1000 s]
    (the error oscillates with the trapezoidal rule's period du in log rate,
    0.2-0.6: 20000 points over 10 decades put 60-200 in each period, and
    40000 find the same maximum to 1e-3 of it), and M."""
    a, b, eta = fraccontact.memory_kernel(damper=2, damper_order=alpha, memory_tolerance=tol, dt_max=dt_max)
    tau = np.logspace(math.log10(dt_max), math.log10(SPAN), points)
    approx = np.exp(-np.outer(tau, b)) @ a
    exact = tau ** -alpha / gamma_function(1 - alpha)
    return np.max(abs(approx / exact - 1)), len(a)


@pytest.mark.parametrize("tol", [1e-4, 1e-6, 1e-9])
@pytest.mark.parametrize("alpha", [0.001, 0.05, 0.3, 0.5, 0.8, 0.95, 0.999])
def test_the_kernel_holds_its_tolerance_over_the_span(alpha, tol):
    """The kernel's relative error on [dt_max, 1000 s] at the default dt_max
    (1e-7, a span of 1e10) is within memory_tolerance: measured 0.40 to 0.74
    of it (soe.c gives a third of it to each of the rule's aliasing, the fast
    cut and the lumped spring). M for these: 28-41 (1e-4), 48-61 (1e-6),
    87-94 (1e-9)."""
    error, M = kernel_error(alpha, tol, 1e-7)
    print(f"alpha {alpha} tol {tol:g}: M = {M}, max relative error {error:.2e} ({error / tol:.2f} of tol)")
    assert error <= tol
    assert kernel_error(alpha, tol, 1e-7, 40000)[0] == pytest.approx(error, rel=1e-3, abs=0)


@pytest.mark.parametrize("alpha", [0.05, 0.5, 0.999])
def test_the_kernel_is_a_passive_maxwell_network(alpha):
    """Every term a positive spring c_alpha a_i with a positive dashpot
    c_alpha a_i/b_i (b_i > 0, falling), the last a lone spring (b = 0), and a
    positive lumped dashpot eta: a passive network (test 4's E_diss >= 0).
    The rates are the trapezoidal rule's nodes e^u, equally spaced in log."""
    a, b, eta = fraccontact.memory_kernel(damper=2, damper_order=alpha)
    assert np.all(a > 0) and eta > 0
    assert b[-1] == 0.0 and np.all(b[:-1] > 0) and np.all(np.diff(b) < 0)
    ratios = np.log(b[:-2] / b[1:-1])
    assert np.all(ratios == pytest.approx(ratios[0], rel=1e-12, abs=0))


def test_at_alpha_1_the_kernel_is_the_dashpot():
    a, b, eta = fraccontact.memory_kernel(damper=2, damper_order=1.0)
    assert len(a) == 0 and eta == 1.0


@pytest.mark.parametrize("alpha", [0.01, 0.03])
def test_the_kernel_holds_at_the_loosest_tolerance(alpha):
    """(Found by this test: the kernel's bounds were solved by fixed-point
    iterations whose logarithms went negative here, giving NaN terms.)"""
    error, M = kernel_error(alpha, 1e-2, 1e-7)
    assert error <= 1e-2


def test_the_number_of_modes_grows_like_the_log_of_the_span():
    """The rule's nodes are du apart in log rate over [about 1/dt_max,
    about tol^(1/(1+alpha))/1000 s]: M = ln(1000 s/dt_max)/du + a constant,
    so ten times the span adds ln(10)/du modes, up to one for where the
    ends fall (alpha 0.5, tol 1e-6: du = 0.21, 10.8 per decade)."""
    a, b, _ = fraccontact.memory_kernel(damper=2, damper_order=0.5, memory_tolerance=1e-6)
    du = math.log(b[0] / b[1])
    counts = [len(fraccontact.memory_kernel(damper=2, damper_order=0.5, memory_tolerance=1e-6,
                                            dt_max=10.0 ** -e)[0]) for e in range(2, 10)]
    for fewer, more in zip(counts, counts[1:]):
        assert abs(more - fewer - math.log(10) / du) <= 1.0, counts


# docs/model.md §6: the published number of exponentials for tau^(-1/2) on
# [delta, T] (Jiang, Zhang, Zhang & Zhang 2017), by relative accuracy and
# delta/T; ours spans [dt_max, 1000 s], so dt_max = 1000 delta/T. Measured
# (alpha 0.5, ours counting the lumped spring; the lumped dashpot eta has no
# state):
#   accuracy   delta/T:  1e-3      1e-4      1e-6      1e-8
#   1e-6       published 32        37        48        59
#              ours      32        36        43        50
#   1e-9       published 45        53        69        85
#              ours      57        62        73        83
#   1e-12      published 58        68        90        111
#              ours      88        95        109       123
# Ours is within the published counts + 10 % at 1e-6 (fewer from 1e-4 on)
# and at 1e-9 for delta/T <= 1e-6, not elsewhere: the slow end's lumped spring must reach rates down to
# tol^(1/(1+alpha))/T, which costs ln(1/tol)/((1+alpha) du) nodes, and du
# itself shrinks like 1/ln(1/tol); the published method's Gauss-Jacobi
# quadrature on dyadic intervals does not pay that. At least a 10 % margin
# is asked where the span ratios match; the cells it misses are xfail
# (strict), so an improvement of the kernel shows.
PUBLISHED = {1e-6: (32, 37, 48, 59), 1e-9: (45, 53, 69, 85), 1e-12: (58, 68, 90, 111)}
SPAN_RATIOS = (1e-3, 1e-4, 1e-6, 1e-8)
PUBLISHED_MISSED = {(1e-9, 1e-3), (1e-9, 1e-4), (1e-12, 1e-3), (1e-12, 1e-4), (1e-12, 1e-6), (1e-12, 1e-8)}


@pytest.mark.parametrize("tol, ratio", [
    pytest.param(tol, ratio, marks=pytest.mark.xfail(strict=True, reason=(
        "ours needs more modes than the published count + 10 % at this accuracy and span (table above)")))
    if (tol, ratio) in PUBLISHED_MISSED else (tol, ratio)
    for tol in PUBLISHED for ratio in SPAN_RATIOS])
def test_modes_against_the_published_counts(tol, ratio):
    published = PUBLISHED[tol][SPAN_RATIOS.index(ratio)]
    error, M = kernel_error(0.5, tol, SPAN * ratio)
    print(f"tau^-1/2, accuracy {tol:g}, delta/T {ratio:g}: M = {M} (published {published}), error {error:.2e}")
    assert error <= tol
    assert M <= 1.1 * published


# ------------------------------------------------------ 7. FMU behaviour

STATE_OUTPUTS = ["F", "F_avg", "F_peak", "x", "x1", "x2", "v_striker", "E_diss", "eps", "semi_integral"]


def bits(s):
    return [struct.pack("<d", s.get(name)) for name in STATE_OUTPUTS] + [s.get("contact")]


def run_bits(s, n, H=1e-5):
    rows = []
    for _ in range(n):
        s.step(H)
        rows.append(bits(s))
    return rows


@pytest.mark.parametrize("phase, before", [("mid-contact", 50), ("recovery", 200)])
@pytest.mark.parametrize("memory", [1, 2])
def test_state_round_trip_continues_bit_for_bit(slave, memory, phase, before):
    """Get/set in the instance and serialize/deserialize into a new one of
    other settings (a dashpot: the state brings the springpot and its
    memory), mid-contact (0.5 ms) and while the dent recovers (2 ms; the
    contact ends at 1.42 ms): the next 60 communication steps are the same
    bits."""
    a = slave(damper=2, memory=memory, dt_max=1e-6)
    run_bits(a, before)
    t = a.t
    state = a.fmu.getFMUstate()
    blob = a.fmu.serializeFMUstate(state)
    print(f"memory {memory} {phase}: state {len(blob)} B at t = {t:.2e} s")
    expected = run_bits(a, 60)
    assert expected[0][-1] is (phase == "mid-contact")
    a.fmu.setFMUstate(state)
    a.t = t
    assert run_bits(a, 60) == expected
    a.fmu.freeFMUstate(state)
    b = slave(damper=1, c=1000.0, law=2)
    b.fmu.setFMUstate(b.fmu.deSerializeFMUstate(blob))
    b.t = t
    assert run_bits(b, 60) == expected


def test_state_sizes(slave):
    """The compressed memory's state has one size however long the run
    (measured 808 B at dt_max = 1e-6, M = 58 modes: the modes' stretches and
    the damper's rate beside the dashpot's 332 B), within the issue's 4 KiB;
    the full history's grows by a double per internal step since t = 0."""
    def size(s):
        return len(s.fmu.serializeFMUstate(s.fmu.getFMUstate()))
    compressed = slave(damper=2, memory=2, dt_max=1e-6, g=9.81, v=0.05)
    sizes = [size(compressed)]
    for H in (5e-4, 3e-3, 0.1):   # in contact, recovering, after impacts under gravity
        compressed.step(H)
        sizes.append(size(compressed))
    assert len(set(sizes)) == 1 and sizes[0] <= 4096, sizes
    full = slave(damper=2, memory=1, dt_max=1e-6)
    full.step(5e-4)
    at_500 = size(full)
    full.step(1.5e-3)
    assert size(full) - at_500 == 8 * 1500
    print(f"state: dashpot {size(slave())} B, compressed {sizes[0]} B, full history {at_500} B after 500 steps")


def test_full_history_refuses_a_step_off_its_grid_and_stays_usable(slave):
    """memory = 1 steps on the grid of dt_max: a communication step that is
    not a whole number of them is fmi2Error, naming memory = 1 and dt_max;
    nothing moves, and the instance then runs on exactly as one that never
    saw the call."""
    s = slave(damper=2, memory=1, dt_max=1e-6)
    run_bits(s, 3)
    before = bits(s)
    with pytest.raises(FMICallException):
        s.fmu.doStep(currentCommunicationPoint=s.t, communicationStepSize=1.5e-6)
    assert "memory = 1" in s.last_error() and "dt_max" in s.last_error(), s.last_error()
    assert bits(s) == before
    twin = slave(damper=2, memory=1, dt_max=1e-6)   # (made after: fmpy logs to the newest instance)
    run_bits(twin, 3)
    assert run_bits(s, 20, H=2e-6) == run_bits(twin, 20, H=2e-6)


def test_full_history_refuses_to_outgrow_its_limit(slave):
    """At most 1048576 steps of history (contact.h): an advance past them is
    refused before it starts, naming the limit and memory = 2."""
    s = slave(damper=2, memory=1, dt_max=1e-6)
    with pytest.raises(FMICallException):
        s.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=(1048576 + 1) * 1e-6)
    assert "1048576" in s.last_error() and "memory = 2" in s.last_error(), s.last_error()
    assert s.get("x") == 0.0
    s.step(1e-5)
    assert s.get("F") > 0


@pytest.mark.parametrize("name, value, shown", [
    ("damper", 3, "damper = 3"), ("damper", 0, "damper = 0"),
    ("damper_order", 0.0, "damper_order = 0"), ("damper_order", 1.5, "damper_order = 1.5"),
    ("damper_order", math.nan, "damper_order = nan"), ("damper_order", -0.5, "damper_order = -0.5"),
    ("c_alpha", 0.0, "c_alpha = 0"), ("c_alpha", -3e5, "c_alpha = -300000"), ("c_alpha", math.inf, "c_alpha = inf"),
    ("memory", 3, "memory = 3"), ("memory", 0, "memory = 0"),
    ("memory_tolerance", 1.0, "memory_tolerance = 1"), ("memory_tolerance", 0.0, "memory_tolerance = 0"),
    ("spring_exponent", 0.5, "spring_exponent = 0.5")])
def test_bad_springpot_parameters_are_refused_by_name(slave, name, value, shown):
    """fmi2Error, the variable and its value named, the old value kept, and
    the instance still runs an impact."""
    s = slave(start=False)
    s.enter()
    before = s.get(name)
    with pytest.raises(FMICallException):
        s.set(**{name: value})
    assert shown in s.last_error(), s.last_error()
    assert s.get(name) == before
    s.fmu.exitInitializationMode()
    for _ in range(200):
        s.step(1e-5)
    assert s.get("eps") > 0


@pytest.mark.parametrize("alpha", [9.99e-4, 1e-10, 1e-130])
def test_the_compressed_memory_refuses_an_order_below_its_kernels_range(slave, alpha):
    """Below alpha = 0.001, where test_the_kernel_holds_its_tolerance_over_the_span
    stops, the compressed memory is refused naming damper_order and the
    memory that takes it (its kernel's terms went non-finite towards 1e-30);
    the full G1 memory runs such an order, a spring within rounding: no
    energy gained beyond the rounding of the impact's energy."""
    with pytest.raises(ValueError, match=rf"damper_order = {alpha:g} is invalid: .*alpha >= 0.001.*memory = 1"):
        fraccontact.impact(damper=2, damper_order=alpha)
    full = fraccontact.impact(damper=2, damper_order=alpha, memory=1)
    energy = 0.5 * fraccontact.defaults()["m"] * fraccontact.defaults()["v"] ** 2
    assert full.E_diss >= -64 * EPS * energy and full.eps <= 1.0
    s = slave(start=False, damper=2)
    s.enter()
    with pytest.raises(FMICallException):
        s.set(damper_order=alpha)
    assert "damper_order" in s.last_error() and "memory = 1" in s.last_error(), s.last_error()
    s.set(memory=1, damper_order=alpha)  # the instance stays usable: the full memory takes the order


def test_too_many_modes_are_refused_naming_the_tolerance(slave):
    """A kernel of more than 160 modes (tolerance 1e-12 over a span of 1e15
    needs about 200) is refused, naming memory_tolerance."""
    s = slave(start=False, damper=2, memory=2, dt_max=1e-12)
    s.enter()
    with pytest.raises(FMICallException):
        s.set(memory_tolerance=1e-12)
        s.fmu.exitInitializationMode()
    assert "memory_tolerance" in s.last_error() and "160" in s.last_error(), s.last_error()


@pytest.mark.parametrize("order", ["k first", "n first"])
def test_k_0_is_hertz_only(slave, order):
    """k = 0 derives the Hertz constant of a sphere (n = 1.5): with n = 2
    it is refused, in either order, naming both."""
    s = slave(start=False)
    s.enter()
    first, second = ({"k": 0.0}, {"spring_exponent": 2.0}) if order == "k first" else \
        ({"spring_exponent": 2.0}, {"k": 0.0})
    s.set(**first)
    with pytest.raises(FMICallException):
        s.set(**second)
    message = s.last_error()
    assert "k = 0" in message and "spring_exponent = 2" in message, message


@pytest.mark.parametrize("damper, memory", [(1, 2), (2, 1), (2, 2)])
def test_the_dent_recovers_after_a_springpot_impact_and_stays_after_a_dashpot(slave, damper, memory):
    """After the separation F = 0: a springpot's D^alpha x2 = 0 forces x2
    to fall (the dent recovers, both memories, monotonically); a dashpot's
    x2' = F/c = 0 holds it, bit for bit."""
    s = slave(damper=damper, memory=memory, dt_max=1e-6)
    while s.get("eps") == 0.0:
        s.step(1e-5)
    x2 = []
    for _ in range(100):
        s.step(1e-4)
        x2.append(s.get("x2"))
    if damper == 1:
        assert len(set(x2)) == 1
    else:
        assert np.all(np.diff(x2) < 0) and x2[-1] < 0.5 * x2[0] and x2[-1] > 0


# Repeated impacts under gravity: the h20 striker at 0.05 m/s, g = 9.81,
# bounces three times in 23 ms (contacts of 2.3-2.6 ms, flights of 7-8 ms),
# each contact starting where the striker meets the recovered dent.
GRAVITY = dict(damper=2, law=2, g=9.81, v=0.05)


def bounces(slave, memory, dt_max, H=1e-5, t_end=0.0235):
    """eps of each finished impact, and x2 and v_striker every 0.5 ms."""
    s = slave(memory=memory, dt_max=dt_max, **GRAVITY)
    eps, samples, last = [], [], 0.0
    for i in range(1, round(t_end / H) + 1):
        s.step(H)
        if s.get("eps") != last:
            last = s.get("eps")
            eps.append(last)
        if i % 50 == 0:
            samples.append((s.get("x2"), s.get("v_striker")))
    return np.array(eps), np.array(samples)


def test_repeated_impacts_under_gravity_agree_between_the_memories(slave):
    """Both memories through three impacts and the recoveries between them,
    communication steps of 1e-5 s (which bound memory 2's recovery steps,
    see the next test), dt_max = 2e-6 and 1e-6. Each memory's error is at
    least first order (measured second), so at 1e-6 it is at most its
    change from 2e-6: the memories differ by no more than the sum of their
    changes, per quantity (eps of each impact, x2 and v over the run).
    Measured: the memories' difference is 0.30-0.40 of that bound."""
    runs = {(memory, dt): bounces(slave, memory, dt) for memory in (1, 2) for dt in (2e-6, 1e-6)}
    assert all(len(runs[key][0]) == 3 for key in runs)
    for i in (0, 1):   # eps, then the samples
        change = sum(abs(runs[memory, 2e-6][i] - runs[memory, 1e-6][i]) for memory in (1, 2))
        difference = abs(runs[1, 1e-6][i] - runs[2, 1e-6][i])
        if i == 1:   # over the run: x2 and v each against their largest change
            change = change.max(axis=0)
        assert np.all(difference <= change), (difference, change)
        print("impacts' eps" if i == 0 else "x2, v samples", "difference / bound:",
              np.max(difference / change, axis=0))


def test_repeated_impacts_converge_whatever_the_communication_step():
    """The library's run (no communication steps): memory 2 against memory
    1, at dt_max 2e-6 and 1e-6, by the same bound as above, on the impacts'
    eps and onset times. (Found by this test: the recovery's steps of 1/8 of
    the time since separation left the second eps 4.7e-6 off whatever
    dt_max; at 1/64 it is 1.2e-7 off memory 1's extrapolated value.)"""
    runs = {(memory, dt): fraccontact.impact(memory=memory, dt_max=dt, impacts=3, **GRAVITY).per_impact
            for memory in (1, 2) for dt in (2e-6, 1e-6)}
    for key in ("eps", "t_onset"):
        value = {k: np.array([getattr(i, key) for i in v]) for k, v in runs.items()}
        change = sum(abs(value[memory, 2e-6] - value[memory, 1e-6]) for memory in (1, 2))
        assert np.all(abs(value[1, 1e-6] - value[2, 1e-6]) <= change), key


# ------------------ 8. a general spring exponent n (with the dashpot)

@pytest.mark.parametrize("n", [1.0, 2.0])
def test_spring_exponent_against_the_gsl_reference(n):
    """F = k x1^n with the dashpot (h20's c = 6080) against GSL's solve of
    the same ODE (fraccontact-solve --reference --spring-exponent n, rtol
    1e-12): the fixed step's error C h^2 (1 + O(h/t_c)), h/t_c ~ 7e-4, so from
    dt_max = 1e-6 to 5e-7 every figure's error falls 4x: order 2 +- 0.05
    (measured 1.99-2.01; errors at 1e-6 from 5.7e-8, F_peak n = 1, to
    1.2e-6, E_diss n = 2)."""
    k = spring_k(n)
    ref = reference("--spring-exponent", n, "--law", 2, "--k", repr(k))
    runs = [fraccontact.impact(spring_exponent=n, k=k, law=2, dt_max=dt) for dt in (1e-6, 5e-7)]
    for key in IMPACT_KEYS:
        e = [getattr(r, key) / ref[key] - 1 for r in runs]
        assert observed_order(*e) == pytest.approx(2.0, abs=0.05, rel=0), (key, e)


@pytest.mark.parametrize("n", [1.0, 2.0, 2.5])
def test_g1_law_for_a_general_exponent_has_the_straight_line_ratio(slave, n):
    """docs/model.md §3: x1^n = Gamma(n+1) D^-(n-1) x1, and G1 on N intervals
    gives k x1^n Gamma(N+n)/(Gamma(N) N^n) (the straight line's sum, §4).
    Driven at v with a rigid dashpot (c = 1e20: x1 = v t to 1e-17), N =
    internal steps since onset (10 per communication step): the ratio is
    1 for n = 1, 1 + 1/N for n = 2 (exact), and from mpmath at 30 digits for
    2.5. x1 sums up to 400 steps (400 ulp), F = k x1^n carries n times that
    and pow's ulp: 1e-13 as in test_fmu_physics."""
    v, k = 0.5, spring_k(n)
    s = slave(scene=2, m=0.0, v=v, c=1e20, law=1, k=k, spring_exponent=n, dt_max=1e-7)
    for step in range(1, 41):
        s.step(1e-6)
        N, x1 = 10 * step, v * step * 1e-6
        with mpmath.workdps(30):
            ratio = float(mpmath.gamma(N + n) / (mpmath.gamma(N) * mpmath.mpf(N) ** n))
        assert ratio == pytest.approx({1.0: 1.0, 2.0: 1 + 1 / N}.get(n, ratio), rel=4 * EPS, abs=0)
        assert s.get("F") == pytest.approx(k * x1 ** n * ratio, rel=1e-13, abs=0)
        assert s.get("semi_integral") == pytest.approx(x1 ** n * ratio / math.gamma(n + 1), rel=1e-13, abs=0)


@pytest.mark.parametrize("n", [1.0, 1.5, 2.0])
def test_elastic_contact_time_of_a_power_law_spring(n):
    """c = 1e20: the dashpot does not move (x2 ~ F t/c ~ 1e-20 m), the
    contact is elastic: energy gives x_max = ((n+1) m v0^2/(2k))^(1/(n+1)),
    and t_c = 2 int_0^x_max dx/v(x) = 2/(n+1) B(1/(n+1), 1/2) x_max/v0.
    The fixed step on an oscillator of frequency w lags by C3 (w h)^3 a step
    and keeps its energy exactly (docs/model.md §11). So for n = 1 (w^2 =
    k/m) the contact time is t_c (1 + C3 (w h)^2), up to the last, partial
    step's share, one step's lag in pi/(w h) steps: w h/pi = 6e-4 of the
    lag, rel 1e-3; eps is 1 to rounding (2 ulp a step, about 2600 steps:
    1e-12), and F_max = k x_max to the same and the peak's location
    (1e-15 of a step): 1e-9 as before.
    For n > 1 w grows with x1 up to w_max^2 = n k x_max^(n-1)/m: the lag is
    at most C3 (w_max h)^2."""
    k, h = spring_k(n), 1e-6
    r = fraccontact.impact(spring_exponent=n, k=k, law=2, c=1e20, dt_max=h)
    x_max = ((n + 1) * M_STRIKER * V0 ** 2 / (2 * k)) ** (1 / (n + 1))
    t_c = 2 / (n + 1) * beta_function(1 / (n + 1), 0.5) * x_max / V0
    lag = r.t_contact / t_c - 1
    theta_max = math.sqrt(n * k * x_max ** (n - 1) / M_STRIKER) * h
    print(f"n {n}: t_c error {lag:.3e}, bound C3 (w_max h)^2 = {C3 * theta_max ** 2:.3e}, eps - 1 = {r.eps - 1:.2e}")
    if n == 1.0:
        assert lag == pytest.approx(C3 * theta_max ** 2, rel=1e-3, abs=0)
        assert r.eps == pytest.approx(1.0, abs=1e-12, rel=0)
        assert r.F_peak == pytest.approx(k * x_max, rel=1e-9, abs=0)
    else:
        assert 0 < lag <= C3 * theta_max ** 2


def test_the_bench_times_the_impacts_the_library_computes():
    """fraccontact-bench springpot (docs/fractional_damping.md's cost table)
    steps the h20 impact in calls of 100 internal steps, as an FMU does, with
    the default dt_max = 0 among its cases: it must end (a call of 100 steps
    of dt_max = 0 advanced nothing and never ended), and give the library's
    figures, the same internal steps in the same order (to the last bit)."""
    bench = os.environ.get("FRACCONTACT_BENCH", str(ROOT / "build" / "fraccontact-bench"))
    done = subprocess.run([bench, "springpot", "1e3"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    h20 = json.loads(done.stdout)["h20"]
    springpot = dict(damper=2, damper_order=0.5, c_alpha=3e5, dt_max=1e-7)
    assert h20["dashpot"]["F_peak"] == fraccontact.impact(dt_max=1e-7).F_peak
    assert h20["compressed"]["F_peak"] == fraccontact.impact(**springpot).F_peak
    assert h20["full"]["F_peak"] == fraccontact.impact(memory=1, **springpot).F_peak


@pytest.mark.parametrize("tolerance", [1e-6, 1e-8])
def test_the_controlled_bench_times_the_impacts_the_library_computes(tolerance):
    """fraccontact-bench controlled (docs/benchmarks.md, the springpot under
    error control) times the error-controlled h20 impact of each damper: the
    library's impact, the same steps and figures to the last bit."""
    bench = os.environ.get("FRACCONTACT_BENCH", str(ROOT / "build" / "fraccontact-bench"))
    done = subprocess.run([bench, "controlled", f"{tolerance:g}"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    timed = json.loads(done.stdout)
    for name, damper in (("dashpot", 1), ("springpot", 2)):
        r = fraccontact.impact(law=2, damper=damper, tolerance=tolerance)
        assert timed[name]["steps"] == r.steps, name
        for figure in ("F_peak", "eps", "t_contact", "x2_end", "E_diss"):
            assert timed[name][figure] == getattr(r, figure), (name, figure)
