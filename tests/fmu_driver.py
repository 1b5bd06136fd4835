"""The FMU driven by variable name (fraccontact.fmu.Slave), and the h20 test
as the tests know it, independently of the C library's defaults."""

import math

from fraccontact.fmu import Slave  # noqa: F401  (the tests' driver)

# The paper's h20 test (docs/model.md §1).
G = 9.81
V0 = math.sqrt(2 * G * 0.020)
M = 0.7437
K = 3.299e8
C = 6080.0


def run_impact(s, H=1e-5, t_end=5e-3):
    """Steps a started drop test until its first impact ends; returns the
    results read from the outputs, the contact time from the free flight that
    follows: x - x2 = v_striker (t - t_sep) with no gravity."""
    while s.get("eps") == 0.0 and s.t < t_end:
        s.step(H)
    v = s.get("v_striker")
    t_sep = s.t - (s.get("x") - s.get("x2")) / v
    return dict(F_peak=s.get("F_peak"), eps=s.get("eps"), x2=s.get("x2"), E_diss=s.get("E_diss"),
                t_contact=t_sep, v_end=v)
