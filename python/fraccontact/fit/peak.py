"""One drop test's k and dashpot c, as the paper finds them: the pair that
reproduces the test's peak force and restitution coefficient, by nested root
finding on the model; and the specimen's Young's modulus from k."""

import math

from scipy.optimize import brentq

from .. import hertz
from . import runs


class Unreachable(Exception):
    """No parameters of this model reproduce what was asked."""


def specimen_modulus(k, R, E_i, nu_i, nu_s):
    """E_s from k (hertz.specimen_modulus); Unreachable when no E_s gives k."""
    try:
        return hertz.specimen_modulus(k, R, E_i, nu_i, nu_s)
    except ValueError as e:
        raise Unreachable(str(e)) from None


def k_for_peak(F_peak, c, m, v, law):
    """The k that gives the peak force F_peak with dashpot c. F_peak(k) rises
    with k towards c v (a rigid spring leaves the dashpot alone), so it is
    reachable only below that."""
    if F_peak >= c * v:
        raise Unreachable(f"F_peak = {F_peak:g} N needs c > F_peak / v = {F_peak / v:g} N s/m")
    k0 = hertz.stiffness_for_peak(F_peak, m, v)                  # Hertz, no dashpot
    f = lambda log_k: runs.run(math.exp(log_k), c, m, v, law).F_peak / F_peak - 1
    lo, hi = math.log(k0) - 1, math.log(k0) + 1
    while f(lo) > 0:
        lo -= 2
    while f(hi) < 0:
        hi += 2
        if hi > math.log(k0) + 60:
            raise Unreachable(f"F_peak = {F_peak:g} N is out of reach with c = {c:g} N s/m")
    return math.exp(brentq(f, lo, hi, xtol=1e-11, rtol=1e-11))


def fit_peak_and_restitution(F_peak, eps, m, v, law="hertz"):
    """k, c reproducing F_peak and eps. For each c, k follows from F_peak; eps
    then rises with c, from 0 (a soft dashpot never lets go) towards 1."""
    if not (0 < eps < 1):
        raise Unreachable(f"eps = {eps:g}: this model gives 0 < eps < 1")
    if not (F_peak > 0 and m > 0 and v > 0):
        raise Unreachable("F_peak, the mass and the impact velocity must be positive")

    def eps_error(log_c):
        c = math.exp(log_c)
        return runs.run(k_for_peak(F_peak, c, m, v, law), c, m, v, law).eps - eps

    lo = math.log(F_peak / v) + 0.02                              # just above c v = F_peak
    hi = lo + 2
    while eps_error(hi) < 0:
        hi += 2
        if hi > lo + 60:
            raise Unreachable(f"eps = {eps:g} is out of reach with F_peak = {F_peak:g} N")
    if eps_error(lo) > 0:
        raise Unreachable(f"eps = {eps:g} is too small for F_peak = {F_peak:g} N at v = {v:g} m/s: even the "
                          f"softest dashpot that reaches F_peak rebounds more")
    c = math.exp(brentq(eps_error, lo, hi, xtol=1e-10, rtol=1e-10))
    return k_for_peak(F_peak, c, m, v, law), c
