"""tests/linear_ode.py, the exact reference of the linear models, against
closed forms it does not use: uniform acceleration (rational, so exact), a
damped oscillator and a stiff overdamped one (mpmath's exp, cos, cosh at 50
digits), and the work of a damper on a decaying rate."""

from fractions import Fraction

import mpmath
import pytest

import linear_ode

# Both sides are the exact value rounded once to double, each from a
# different 50-digit computation: equal, or an ulp apart where the exact
# value lies within 1e-50 of a rounding boundary.
ULP = 2.0 ** -52


def test_uniform_acceleration_is_the_rational_closed_form():
    """x'' = g from (x0, v0): x = x0 + v0 t + g t^2 / 2, in Fractions."""
    x0, v0, g, t = 0.25, -3.0, 9.81, 2e-3
    y = linear_ode.state_at([[0, 1, 0], [0, 0, g], [0, 0, 0]], [x0, v0, 1], t)
    x0, v0, g, t = map(Fraction, (x0, v0, g, t))
    assert y == [float(x0 + v0 * t + g * t * t / 2), float(v0 + g * t), 1.0]


@pytest.mark.parametrize("k, c", [(5e4, 300.0), (5e4, 3e4)])  # underdamped, stiffly overdamped
def test_damped_oscillator_is_its_closed_form(k, c):
    """m x'' = -k x - c x' from (x0, v0): x = e^(-beta t) (x0 C + (v0 + beta
    x0) S), C and S the cos/cosh and sin/sinh of the damped rate."""
    m, x0, v0, t = 0.5, 1e-3, 3.0, 4e-3
    y = linear_ode.state_at([[0, 1], [-Fraction(k) / Fraction(m), -Fraction(c) / Fraction(m)]], [x0, v0], t)
    with mpmath.workdps(50):
        k, c, m, x0, v0, t = map(linear_ode.exact, (k, c, m, x0, v0, t))
        beta, w2 = c / (2 * m), k / m
        root = mpmath.sqrt(beta ** 2 - w2 + 0j)  # i w_d underdamped, gamma overdamped
        C, S = mpmath.cosh(root * t).real, (mpmath.sinh(root * t) / root).real
        x = mpmath.exp(-beta * t) * (x0 * C + (v0 + beta * x0) * S)
        v = mpmath.exp(-beta * t) * (v0 * C - (w2 * x0 + beta * v0) * S)
    assert y[0] == pytest.approx(float(x), rel=ULP, abs=0)
    assert y[1] == pytest.approx(float(v), rel=ULP, abs=0)


def test_a_dampers_work_is_the_lost_kinetic_energy():
    """m v' = -c v from v0 (x free): the integral of c v^2 is m v0^2 (1 -
    e^(-2 c t / m)) / 2."""
    m, c, v0, t = 0.5, 300.0, 3.0, 2e-3
    A = [[0, 1], [0, -Fraction(c) / Fraction(m)]]
    E = linear_ode.quadratic_integral_at(A, [[0, 0], [0, c]], [0.0, v0], t)
    with mpmath.workdps(50):
        m, c, v0, t = map(linear_ode.exact, (m, c, v0, t))
        lost = m * v0 ** 2 * -mpmath.expm1(-2 * c * t / m) / 2
    assert E == pytest.approx(float(lost), rel=ULP, abs=0)


def test_a_quadratic_forms_cross_terms_count_twice():
    """x' = v0 from x0: the integral of (x + v)^2 = (u + v0 s)^2, u = x0 +
    v0, is u^2 t + u v0 t^2 + v0^2 t^3 / 3, in Fractions."""
    x0, v0, t = 0.25, -3.0, 2e-3
    E = linear_ode.quadratic_integral_at([[0, 1], [0, 0]], [[1, 1], [1, 1]], [x0, v0], t)
    x0, v0, t = map(Fraction, (x0, v0, t))
    u = x0 + v0
    assert E == float(u * u * t + u * v0 * t * t + v0 * v0 * t ** 3 / 3)
