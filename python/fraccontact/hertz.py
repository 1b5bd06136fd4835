"""The elastic Hertz impact in closed form (docs/model.md §2): the scales the fit,
the reports and the second implementation in scipy take their steps and
tolerances from. A sphere of mass m meeting a half-space at v with the
Hertz constant k reaches x_max = (5 m v^2 / (4 k))^(2/5) and the force
k x_max^(3/2), and leaves after t_c = (4/5) B(2/5, 1/2) x_max / v."""

import math

# t_c v / x_max: 2 integral_0^1 (1 - u^(5/2))^(-1/2) du = (4/5) B(2/5, 1/2).
CONTACT_TIME = 0.8 * math.gamma(0.4) * math.gamma(0.5) / math.gamma(0.9)


def k_from_materials(R, E_i, nu_i, E_s, nu_s):
    """k = (4/3) E* sqrt(R), 1/E* = (1 - nu_i^2)/E_i + (1 - nu_s^2)/E_s."""
    return 4.0 / 3.0 * math.sqrt(R) / ((1 - nu_i ** 2) / E_i + (1 - nu_s ** 2) / E_s)


def specimen_modulus(k, R, E_i, nu_i, nu_s):
    """E_s from k (k_from_materials solved for it); ValueError when k is
    stiffer than the indenter alone allows."""
    rest = 4.0 * math.sqrt(R) / (3.0 * k) - (1 - nu_i ** 2) / E_i
    if rest <= 0:
        raise ValueError(f"k = {k:.6g} N/m^1.5 is stiffer than the indenter alone allows "
                         f"(E_i = {E_i:g} Pa, R = {R:g} m): no specimen modulus gives it")
    return (1 - nu_s ** 2) / rest


def indentation(k, m, v):
    """x_max, the largest indentation [m]."""
    return (5 * m * v ** 2 / (4 * k)) ** 0.4


def contact_time(k, m, v):
    """t_c, the duration of the contact [s]."""
    return CONTACT_TIME * indentation(k, m, v) / v


def stiffness_for_peak(F_peak, m, v):
    """The k whose elastic impact peaks at F_peak: k x_max^(3/2) =
    k^(2/5) (5 m v^2 / 4)^(3/5) solved for k."""
    return (F_peak / (1.25 * m * v ** 2) ** 0.6) ** 2.5
