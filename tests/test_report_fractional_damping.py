"""The fractional-damping report's own arithmetic (reports/
fractional_damping.py), against closed forms: the Riemann-Liouville integral of
a piecewise-linear force (its recovery prediction x2 = I^alpha F / c_alpha),
computed independently with mpmath; the kernel error of an exact kernel; the
frequency rule; observed orders. No model runs: milliseconds."""

import math
import os

import mpmath
import numpy as np
import pytest

# The report imports matplotlib, whose C++ exceptions trip ASan's interceptor
# under the sanitizer runtime preloaded into Python (the sanitized build's
# pytest): its arithmetic is Python's alone, tested in the normal build.
if os.environ.get("FRACCONTACT_SANITIZED") == "1":
    pytest.skip("matplotlib under a preloaded sanitizer runtime", allow_module_level=True)

from reports import fractional_damping as fd  # noqa: E402


def rl_exact(f, alpha, t, T):
    """1/Gamma(alpha) int_0^T (t - s)^(alpha-1) f(s) ds in mpmath (50 digits)."""
    mpmath.mp.dps = 50
    return float(mpmath.quad(lambda s: (t - s) ** (alpha - 1) * f(s), [0, T]) / mpmath.gamma(alpha))


def ramp_exact(alpha, t, T):
    """I^alpha of s on [0, T] (0 after) at t >= T in closed form, in mpmath:
    (t (t^a - (t-T)^a)/a - (t^(a+1) - (t-T)^(a+1))/(a+1)) / Gamma(a)."""
    mpmath.mp.dps = 50
    a, t, T = mpmath.mpf(alpha), mpmath.mpf(t), mpmath.mpf(T)
    return float((t * (t ** a - (t - T) ** a) / a - (t ** (a + 1) - (t - T) ** (a + 1)) / (a + 1)) / mpmath.gamma(a))


@pytest.mark.parametrize("alpha", [0.1, 0.25, 0.5, 0.75, 0.9])
def test_riemann_liouville_of_a_constant_and_a_ramp(alpha):
    """Exact for a piecewise-linear F: a unit pulse and a ramp over [0, T],
    at the pulse's end and long after it (where cancellation would show)."""
    T = 1.4e-3
    ts = np.linspace(0.0, T, 1401)
    at = np.array([T, 2 * T, 1.0, 1e3])
    one = fd.riemann_liouville(ts, np.ones_like(ts), alpha, at)
    closed = (at ** alpha - (at - T) ** alpha) / math.gamma(alpha + 1)
    assert np.allclose(one, closed, rtol=1e-9, atol=0)
    ramp = fd.riemann_liouville(ts, ts, alpha, at)
    # rel 2e-9: at t = 1e3 s, 7e5 pulse lengths on, the ramp's integral is a small difference of large
    # terms and keeps fewer digits (measured 1.1e-9 at alpha 0.9; 1e-13 or less at the other times)
    for got, t in zip(ramp, at):
        assert got == pytest.approx(ramp_exact(alpha, t, T), rel=2e-9, abs=0)


def test_riemann_liouville_of_a_half_sine_long_after():
    """A force pulse like an impact's, sampled finely: its integral tends to
    impulse t^(alpha-1)/Gamma(alpha) long after it."""
    alpha, T = 0.5, 1.4e-3
    ts = np.linspace(0.0, T, 14001)
    F = np.sin(np.pi * ts / T)
    got = fd.riemann_liouville(ts, F, alpha, [1e-2, 1.0])
    exact = [rl_exact(lambda s: mpmath.sin(mpmath.pi * s / T), alpha, t, T) for t in (1e-2, 1.0)]
    assert np.allclose(got, exact, rtol=1e-7)
    impulse = 2 * T / np.pi
    # rel 1e-7: the far field expanded about the pulse's centre; its next term is
    # (1 - alpha)(2 - alpha)/2 Var(s)/t^2, Var(s) = T^2 (1/4 - 2/pi^2) for a half sine: 3.5e-8 at t = 1 s
    # (measured 3.1e-8)
    assert got[1] == pytest.approx(impulse / math.gamma(alpha) * (1.0 - T / 2) ** (alpha - 1), rel=1e-7, abs=0)


def test_riemann_liouville_refuses_times_inside_the_samples():
    with pytest.raises(ValueError):
        fd.riemann_liouville([0.0, 1.0], [1.0, 1.0], 0.5, [0.5])


def test_kernel_error_of_a_constant_against_the_kernel():
    """A single b = 0 term a = K(1) against K(tau) = tau^(-1/2)/sqrt(pi) on
    [1, 4]: exact at tau = 1, twice the kernel at tau = 4 (error 1)."""
    alpha = 0.5
    a, b = np.array([fd.exact_kernel(1.0, alpha)]), np.array([0.0])
    assert fd.exact_kernel(4.0, alpha) == pytest.approx(0.5 / math.sqrt(math.pi), rel=1e-15, abs=0)
    assert fd.kernel_error(a, b, alpha, 1.0, 4.0) == pytest.approx(1.0, rel=1e-12, abs=0)
    assert fd.kernel_error(a, b, alpha, 1.0, 1.0 + 1e-9) == pytest.approx(0.0, abs=1e-9, rel=0)
    # One exponential e^(-tau) against tau^(-alpha)/Gamma(1 - alpha) at a single point (a 1-point grid).
    k1 = fd.exact_kernel(1.0, 0.25)
    assert fd.kernel_error(np.array([k1 * math.e]), np.array([1.0]), 0.25, 1.0, 1.0) == pytest.approx(0.0, abs=1e-15, rel=0)


def test_frequency_rule_and_orders():
    assert fd.c_alpha_rule(1.0, 2400.0) == fd.C
    # exact in real numbers (sqrt(2500) = 50, logarithms of exact powers): a few roundings, rel 1e-14
    assert fd.c_alpha_rule(0.5, 2500.0) == pytest.approx(fd.C * 50.0, rel=1e-14, abs=0)
    steps = [8e-7, 4e-7, 2e-7]
    assert fd.order([s ** 2 for s in steps], steps) == pytest.approx([2.0, 2.0], rel=1e-14, abs=0)
    assert fd.log_slope([1.0, 10.0, 100.0], [3.0, 0.3, 0.03]) == pytest.approx(-1.0, rel=1e-14, abs=0)


def test_power_difference_has_no_cancellation():
    """u0^p - u1^p for u0 = u1 (1 + 1e-12): the naive difference loses all digits."""
    u1 = 1e3
    u0 = u1 * (1 + 1e-12)
    got = fd._power_difference(u0, u1, 0.5)
    # against the exact difference of the two doubles (u0 / u1 - 1 is not exactly 1e-12): rel 1e-12 is a
    # few roundings, where the naive difference errs by 1e-4
    with mpmath.workdps(50):
        exact = float(mpmath.sqrt(mpmath.mpf(u0)) - mpmath.sqrt(mpmath.mpf(u1)))
    assert float(got) == pytest.approx(exact, rel=1e-12, abs=0)
    assert float(u0 ** 0.5 - u1 ** 0.5) != pytest.approx(exact, rel=1e-12, abs=0)
