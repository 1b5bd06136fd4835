"""What the tests compare with, computed here and not by the C code: the
closed forms of docs/model.md and the accuracy measured for the scheme."""

import math
from fractions import Fraction

EPS = 2.0 ** -52  # machine epsilon, the ulp of 1.0 (twice the unit roundoff)
GAMMA_5_2 = 0.75 * math.sqrt(math.pi)

# The elastic Hertz contact time (docs/model.md §2): t_c = 2 (x_max/v0) ∫₀¹ (1 − u^(5/2))^(−1/2) du;
# with w = u^(5/2) the integral is (2/5) B(2/5, 1/2), so t_c = (4/5) B(2/5, 1/2) x_max/v0
# (2.9432751843247...; tests/test_fmu_physics.py checks the integral by quadrature).
HERTZ_TC = 0.8 * math.gamma(0.4) * math.gamma(0.5) / math.gamma(0.9)

# What the drop test's results may differ from a converged solve of the same
# ODE at dt_max = 1e-7 (the default): the fixed step is second order, its
# error ~(dt/t_c)^2 = 5.8e-9 times a constant per quantity. Measured (h20,
# N = 10 fixed, and g = 9.81 with a 2 mm gap, all alike to two digits, against
# fraccontact-solve --reference): F_peak 3.9e-9, eps 7.0e-9, t_contact 4.8e-9,
# x2 2.6e-9, E_diss 7.1e-9; the tolerances are 3x those.
SCHEME_RTOL = dict(F_peak=1.2e-8, eps=2.1e-8, t_contact=1.5e-8, x2=8e-9, E_diss=2.2e-8)

_RATIONAL = [None, Fraction(1)]


def g1_line_ratio(N):
    """Gamma(N + 3/2) / (Gamma(N) N^(3/2)), docs/model.md §4, to a few ulp.

    Gamma(N + 3/2) / (Gamma(5/2) Gamma(N)) = prod_{j=1}^{N-1} (j + 3/2) / j
    is rational: Python's Fraction keeps it exact and float() rounds it once;
    the rest (Gamma(5/2) = 3 sqrt(pi)/4, N^(3/2)) costs four more roundings.
    (exp(lgamma(N + 3/2) - lgamma(N) - 1.5 ln N) errs by an ulp of
    ln Gamma(N) ~ N ln N: 3e-13 at N = 400, which would hide errors below it;
    test_rational_ratio_agrees_with_lgamma checks the two agree to that.)"""
    while len(_RATIONAL) <= N:
        n = len(_RATIONAL)  # Gamma(n + 3/2)/Gamma(n) = Gamma(n + 1/2)/Gamma(n - 1) * (n + 1/2)/(n - 1)
        _RATIONAL.append(_RATIONAL[-1] * Fraction(2 * n + 1, 2 * (n - 1)))
    return float(_RATIONAL[N]) * GAMMA_5_2 / (N * math.sqrt(N))


def extrapolated_ratio(N):
    """Richardson's extrapolation of the G1 ratio r(N) = 1 + a1/N + a2/N^2 +
    ... from N and M = floor(N/2) intervals: N r(N) - M r(M) = (N - M) +
    a2 (1/N - 1/M) + ..., so (N r(N) - M r(M)) / (N - M) drops the 1/N term
    for odd N as for even (where it is 2 r(N) - r(N/2)). N = 1 has no
    coarser grid: r(1)."""
    M = N // 2
    if M < 1:
        return g1_line_ratio(N)
    return (N * g1_line_ratio(N) - M * g1_line_ratio(M)) / (N - M)


def hertz_k(R, E_i, nu_i, E_s, nu_s):
    """docs/model.md §2: k = (4/3) E* sqrt(R), 1/E* = (1 - nu_i^2)/E_i + (1 - nu_s^2)/E_s."""
    return 4.0 / 3.0 * math.sqrt(R) / ((1 - nu_i ** 2) / E_i + (1 - nu_s ** 2) / E_s)
