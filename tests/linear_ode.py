"""The exact solution of a linear ODE with constant coefficients, the
reference of a test whose model is linear (the body FMU's spring, damper and
masses). y' = A y + b is y' = A y with the constant b folded in as a last
state held at 1, so y(t) = expm(A t) y(0). The integral of a quadratic form
y^T W y of the state (a damper's work) is linear too: the products P = y y^T
obey P' = A P + P A^T, a linear ODE in P's upper triangle whose eigenvalues
are A's summed in pairs (so it decays where A does; Van Loan's block matrix
instead holds e^(-A^T t), of which a stiff system's cancellation would leave
no digits).

The matrices are built exactly (floats, ints and Fractions taken as the
rationals they are) and exponentiated in mpmath at 50 digits: the reference's
own error is the final rounding to double, half an ulp of each value, on any
machine (no SIMD path enters; tests/test_linear_ode.py checks the digits)."""

from fractions import Fraction

import mpmath

DIGITS = 50


def exact(value):
    """A float, int or Fraction as an mpf, exactly at DIGITS digits (a double's 53 bits are 16)."""
    q = Fraction(value)
    return mpmath.mpf(q.numerator) / q.denominator


def matrix(rows):
    return mpmath.matrix([[exact(e) for e in row] for row in rows])


def state_at(A, y0, t):
    """y(t) for y' = A y, y(0) = y0 (A's rows and y0 of floats, ints or
    Fractions, taken exactly), each entry the exact value rounded once."""
    with mpmath.workdps(DIGITS):
        y = mpmath.expm(matrix(A) * exact(t)) * matrix([[e] for e in y0])
        return [float(e) for e in y]


def quadratic_integral_at(A, W, y0, t):
    """The integral of y^T W y over [0, t] for y' = A y, y(0) = y0 (W
    symmetric): E' = sum_ij W_ij P_ij with P_ij' = sum_k A_ik P_kj + A_jk
    P_ik over the pairs i <= j (P_ji is P_ij), P(0) = y0 y0^T, E(0) = 0;
    rounded once."""
    n = len(y0)
    pairs = [(i, j) for i in range(n) for j in range(i, n)]
    index = {p: r for r, p in enumerate(pairs)}
    entry = lambda i, j: index[(min(i, j), max(i, j))]
    with mpmath.workdps(DIGITS):
        A, W, y0 = matrix(A), matrix(W), [exact(e) for e in y0]
        L = mpmath.zeros(len(pairs) + 1, len(pairs) + 1)
        for r, (i, j) in enumerate(pairs):
            for k in range(n):
                L[r, entry(k, j)] += A[i, k]
                L[r, entry(i, k)] += A[j, k]
            L[len(pairs), r] = W[i, j] * (1 if i == j else 2)
        start = mpmath.matrix([y0[i] * y0[j] for i, j in pairs] + [0])
        return float((mpmath.expm(L * exact(t)) * start)[len(pairs)])
