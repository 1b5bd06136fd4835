"""Material identification from drop tests (fraccontact fit): k and a dashpot
or springpot, and the specimen's Young's modulus, from peak forces and
restitution coefficients or from measured force curves. One module per
concern: data (the CSV files and their checks), runs (the model as the fit
runs it), peak (one test's k and c by root finding), least_squares, drops
(drop tests and the family of solutions), curves (force curves), report
(text and plots) and cli (the command line, fraccontact fit --help)."""

from .cli import build_parser, main
from .curves import Curve, fit_curve, fit_curves
from .data import BadInput, check_curve, read_curve, read_drops
from .drops import K_CAP, Drops, family, fit_drops, solve_fixed_order
from .peak import Unreachable, fit_peak_and_restitution, specimen_modulus
from .report import family_report, text_report
from .runs import SPRINGPOT_STEPS_PER_CONTACT, force_series, run

__all__ = ["BadInput", "Curve", "Drops", "K_CAP", "SPRINGPOT_STEPS_PER_CONTACT", "Unreachable", "build_parser",
           "check_curve", "family", "family_report", "fit_curve", "fit_curves", "fit_drops",
           "fit_peak_and_restitution", "force_series", "main", "read_curve", "read_drops", "run",
           "solve_fixed_order", "specimen_modulus", "text_report"]
