"""Material identification from drop tests, as the paper does it: find the
Hertz constant k and the damper that reproduce a test's peak force and
restitution coefficient, then the specimen's Young's modulus from k
(docs/model.md §1, §2). Or fit them and the contact onset t0 to a whole measured
force-time curve by least squares, with their standard errors and a plot.
The damper is the dashpot c (--damper 1, the default) or the springpot
F = c_alpha D^alpha x2 (--damper 2, docs/model.md §5: k, c_alpha and its order
alpha, or k and c_alpha with --damper-order fixing alpha). Several drop tests
are fitted at once from a table (--drops: height, F_max, eps per row) or
from several curves (--curve and --height repeated, in the same order).

  fraccontact fit --F-peak 1004 --eps 0.59 --height 0.020 --m 0.7437 --json
  fraccontact fit --curve test.csv --height 0.020 --m 0.7437 --plot fit.png
  fraccontact fit --curve test.csv --height 0.020 --m 0.7437 --damper 2
  fraccontact fit --drops campaign.csv --m 0.7437 --damper 2 --plot drops.png
  fraccontact fit --curve h10.csv --height 0.010 --curve h50.csv --height 0.050 --m 0.7437 --damper 2
  fraccontact fit --F-peak 1004 --eps 0.59 --height 0.020 --m 0.7437 --damper 2 --plot family.png

One drop test's F_peak and eps are two numbers: they fix k and c, but not
k, c_alpha and alpha. The fit says so in one line and prints the family of
solutions instead: for alpha on a grid, the k and c_alpha that reproduce
them (--damper-order picks one member).

The model runs in-process on the package's C library (fraccontact.impact,
fraccontact.impacts, fraccontact.simulate), the Hertz law by default.
"""

import argparse
import json
import os
import pathlib
import sys

import numpy as np

from .. import hertz, model
from ..options import OneLineParser, finite, positive
from . import runs
from .curves import WHITENESS_SIGMAS, Curve, fit_curves
from .data import (IMPULSE_RANGE, MAX_HEIGHT, MIN_PEAK_SAMPLES, MIN_ROWS, SPIKE_FACTOR, SPIKE_NOISE_LEVELS, BadInput,
                   check_curve, read_curve, read_drops)
from .drops import K_CAP, REPRODUCE, Drops, fit_drops
from .least_squares import POOR, RANK_TOLERANCE, poorly_determined
from .peak import Unreachable, fit_peak_and_restitution, specimen_modulus
from .report import family_report, plot_curves, plot_drops, plot_family, text_report

CURVE_HELP = f"""\
The curve (--curve): comma-separated, an optional header row, then one row per
sample: time [s] in column 1, contact force [N] (compression positive) in
column 2; further columns are ignored. t = 0 may lie anywhere: the contact
onset t0 [s] is fitted on the file's time axis. Refused before any fitting,
with the row and column named (exit status 2): a missing, empty or non-text
file; fewer than {MIN_ROWS} data rows; a cell that is not a finite number; times that
do not increase strictly; an isolated spike (a sample more than {SPIKE_FACTOR} times
both its neighbours and {SPIKE_NOISE_LEVELS} noise levels, the noise estimated from the
median step); forces whose largest magnitude is negative (wrong sign); an
impulse (integral of F dt) outside {IMPULSE_RANGE[0]:.2g} to {IMPULSE_RANGE[1]:g} times m v, where a rebound
gives 1 to 2 (a curve that does not hold the whole contact, times in
milliseconds or microseconds, forces in kN, or a wrong --m or --height:
the message says which fits); fewer than {MIN_PEAK_SAMPLES} samples above half the peak force. Several
curves (--curve repeated, each with its --height or --v in the same order)
share k and the damper; each has its own t0, and its residuals are weighed
by their own noise level (from a first, unweighted pass).

The drop tests (--drops): comma-separated, an optional header row, then one
row per test: height [m], F_max [N], eps, and optionally the standard
deviations sigma_F_max [N] and sigma_eps of the two (for every row or for
none). Repeats of a height are separate rows. With the sigmas the residuals
are weighed by them and the standard errors are absolute (chi-square per
degree of freedom printed as a check); without them the relative error of
F_max and the absolute error of eps are taken as equal (1 % of F_max weighs
as 0.01 of eps) and their common size is estimated from the residuals.
Refused, naming the row and column: a cell that is not a finite number, a
height not above 0 or above {MAX_HEIGHT:g} m (millimetres?), F_max not above 0,
eps outside (0, 1) (a percentage?), a sigma not above 0.

Standard errors come from the Jacobian and the residuals' variance, which
assumes independent noise. The check of that: the lag-1 autocorrelation r1
of the residuals, about N(0, 1/n) for n independent samples. When
r1 > {WHITENESS_SIGMAS}/sqrt(n) (one-sided, {WHITENESS_SIGMAS} sigma) a warning says the residuals are not
noise-like: the model misses the curve's shape, or the noise is correlated
(filtered, oversampled); either way the true errors are larger.

Identifiability: fewer data than parameters (one drop test's F_max and eps
for the springpot's three), or a Jacobian whose smallest singular value is
below {RANK_TOLERANCE:g} of its largest (repeats of one height), cannot determine the
parameters: the fit says so in one line, names the undetermined direction,
and prints the family of solutions: for alpha = 1, 0.95, ..., 0.05 the k and
c_alpha that fit best (for one test: that reproduce F_max and eps to
{REPRODUCE:g}), down to the lowest order alpha_min that reaches them with k below
{K_CAP:g} times the elastic Hertz k of the peak force.

Output: k [N/m^1.5], c [N s/m] (dashpot) or c_alpha [N s^alpha/m] and alpha
(springpot), E_s [Pa], the model's F_peak [N] and eps at the fitted values;
curve fits add t0 [s]; fits of more data than parameters add each value's
standard error (±) and their correlations; joint fits list every test.
--json: the same in SI units, keys k, c or c_alpha and alpha, t0, E_s,
F_peak, eps, sigma_<key>, correlation (of k and c or c_alpha), correlations,
identifiable, condition, tests, family, alpha_min, rms_residual,
residual_autocorrelation, residuals_noise_like, v, m, law, damper. Exit
status: 0 fitted (or the family shown), 2 bad input or out of the model's
reach, 1 the model failed."""


# ---------------------------------------------------------------------------------------------------------------
# The command line.


def order(text):
    """argparse type: a springpot order, 0 < alpha <= 1."""
    value = finite(text)
    if not 0 < value <= 1:
        raise argparse.ArgumentTypeError(f"{text} is not a springpot order (0 < alpha <= 1)")
    return value


def poisson_ratio(text):
    """argparse type: a Poisson ratio, -1 < nu <= 0.5 (elastic stability)."""
    value = finite(text)
    if not -1 < value <= 0.5:
        raise argparse.ArgumentTypeError(f"{text} is not a Poisson ratio (-1 < nu <= 0.5)")
    return value


def plot_file(text):
    """argparse type: a path whose folder exists and whose suffix matplotlib
    writes, checked now so that a long fit does not end in a failed save."""
    from matplotlib.backend_bases import FigureCanvasBase
    path = pathlib.Path(text)
    formats = FigureCanvasBase.get_supported_filetypes()
    if not path.parent.is_dir():
        raise argparse.ArgumentTypeError(f"{text}: the folder {path.parent} does not exist")
    if not os.access(path.parent, os.W_OK):
        raise argparse.ArgumentTypeError(f"{text}: the folder {path.parent} is not writable")
    if path.suffix[1:].lower() not in formats:
        raise argparse.ArgumentTypeError(f"{text}: unknown image type '{path.suffix}'; use one of "
                                         f"{', '.join(sorted(formats))}")
    return path


def fmu_file(text):
    """argparse type: a path in an existing folder, checked now so that a long fit does not end in a failed
    export."""
    path = pathlib.Path(text)
    if not path.parent.is_dir():
        raise argparse.ArgumentTypeError(f"{text}: the folder {path.parent} does not exist")
    return path


def data_source(args):
    """What the fit was fitted to, for an exported FMU's description."""
    if args.curve:
        return ", ".join(str(p) for p in args.curve)
    if args.drops is not None:
        return str(args.drops)
    return f"F_peak = {args.F_peak:g} N, eps = {args.eps:g}"


def exported_fmu(args, result):
    """--export-fmu: the fit's contact as an FMU; a line saying so."""
    from ..export import export
    out = export(args.export_fmu, fit=result, source=data_source(args), material=args.material)
    return f"{out['path']}: {len(out['variables'])} of the full FMU's {out['full_variables']} variables"


def default_help(name, what):
    """'what [unit] (default ...)' of a parameter, from the library's table."""
    p = next(p for p in model.parameters() if p["name"] == name)
    return f"{what} [{p['unit']}] (default {p['default']:g})"


def build_parser(prog=None):
    default = model.defaults()
    parser = OneLineParser(prog=prog, description=__doc__, epilog=CURVE_HELP,
                           formatter_class=argparse.RawDescriptionHelpFormatter)
    what = parser.add_mutually_exclusive_group(required=True)
    what.add_argument("--F-peak", type=positive, help="measured peak force [N] (with --eps)")
    what.add_argument("--curve", type=pathlib.Path, metavar="FILE", action="append",
                      help="CSV of the measured force: time [s], force [N] (below); repeat it, each with its "
                           "--height or --v, to fit several curves at once")
    what.add_argument("--drops", type=pathlib.Path, metavar="FILE",
                      help="CSV of drop tests: height [m], F_max [N], eps [, sigma_F_max [N], sigma_eps] (below)")
    parser.add_argument("--eps", type=finite, help="measured restitution coefficient [1] (with --F-peak)")
    parser.add_argument("--height", type=positive, action="append",
                        help="drop height [m]: v = sqrt(2 g h), g = 9.81 m/s^2 (one per --curve)")
    parser.add_argument("--v", type=positive, action="append", help="impact velocity [m/s] (one per --curve)")
    parser.add_argument("--m", type=positive, required=True, help="striker mass [kg]")
    parser.add_argument("--damper", type=int, choices=tuple(runs.DAMPERS), default=1,
                        help="the damper fitted [1]: 1 dashpot (k, c; the default), 2 springpot (k, c_alpha, alpha)")
    parser.add_argument("--damper-order", type=order, metavar="ALPHA",
                        help="with --damper 2: the springpot's order alpha [1], held fixed (k and c_alpha fitted)")
    parser.add_argument("--R", type=positive, default=default["R"], help=default_help("R", "striker tip radius"))
    parser.add_argument("--E-i", type=positive, default=default["E_i"],
                        help=default_help("E_i", "indenter Young's modulus"))
    parser.add_argument("--nu-i", type=poisson_ratio, default=default["nu_i"],
                        help=default_help("nu_i", "indenter Poisson ratio"))
    parser.add_argument("--nu-s", type=poisson_ratio, default=default["nu_s"],
                        help=default_help("nu_s", "specimen Poisson ratio"))
    parser.add_argument("--law", choices=tuple(model.WORDS["law"]), default="hertz",
                        help="spring law of the model fitted (default hertz; g1, hertz, g1x: laws 1, 2, 3)")
    parser.add_argument("--plot", type=plot_file, metavar="FILE",
                        help="an image [png, pdf, ...]: with --curve measured against fitted force, with --drops "
                             "F_max and eps against height, for a family (--damper 2, one test) k, c_alpha, E_s "
                             "against alpha")
    parser.add_argument("--json", action="store_true", help="print one JSON object (SI units) instead of text")
    parser.add_argument("--export-fmu", type=fmu_file, metavar="FILE",
                        help="also write the calibrated contact as an FMU [.fmu] (fraccontact export's drop scene: one "
                             "body, Gauss-Seidel, FMI 2.0; docs/export.md)")
    parser.add_argument("--material", help="with --export-fmu: the material, for the FMU's description")
    return parser


def check_arguments(parser, args):
    """The combinations argparse cannot check, each a one-line usage error."""
    speeds = (args.height or []) + (args.v or [])
    if args.F_peak is not None and args.eps is None:
        parser.error("--F-peak needs --eps")
    if args.eps is not None and args.F_peak is None:
        parser.error("--eps goes with --F-peak, not --curve or --drops")
    if args.height and args.v:
        parser.error("give --height or --v, not both")
    if args.drops is not None and speeds:
        parser.error("--drops takes its heights from the file: no --height or --v")
    if args.F_peak is not None and len(speeds) != 1:
        parser.error("--F-peak needs one --height or --v")
    if args.curve is not None and len(speeds) != len(args.curve):
        parser.error(f"{len(args.curve)} --curve and {len(speeds)} --height/--v: give one --height (or --v) per "
                     "--curve, in the same order")
    if args.damper_order is not None and args.damper != 2:
        parser.error("--damper-order needs --damper 2 (the springpot)")
    if args.plot is not None and args.F_peak is not None and not (args.damper == 2 and args.damper_order is None):
        parser.error("--plot needs --curve or --drops, or --damper 2 with --F-peak (the family)")
    if args.material is not None and args.export_fmu is None:
        parser.error("--material goes with --export-fmu")


def add_specimen_modulus(result, args):
    result["E_s"] = specimen_modulus(result["k"], args.R, args.E_i, args.nu_i, args.nu_s)
    if "sigma_k" in result:  # dE_s/dk by a relative step of 1e-6
        dk = 1e-6 * result["k"]
        result["sigma_E_s"] = abs(specimen_modulus(result["k"] + dk, args.R, args.E_i, args.nu_i, args.nu_s)
                                  - result["E_s"]) / dk * result["sigma_k"]


def family_moduli(fam, args):
    """E_s of each member in the family (None where k is stiffer than the indenter allows, or out of it)."""
    out = []
    for mb in fam["members"]:
        try:
            out.append(hertz.specimen_modulus(mb["k"], args.R, args.E_i, args.nu_i, args.nu_s) if mb["in_family"]
                       else None)
        except ValueError:
            out.append(None)
    return out


def fit_peak(args, v):
    if args.damper == 1:
        k, c = fit_peak_and_restitution(args.F_peak, args.eps, args.m, v, args.law)
        check = runs.run(k, c, args.m, v, args.law)
        return dict(k=k, c=c, F_peak=check.F_peak, eps=check.eps), None
    drops = Drops(v=np.array([v]), F=np.array([args.F_peak]), eps=np.array([args.eps]),
                  heights=None if args.height is None else list(args.height))
    return drops_result(args, drops)


def drops_result(args, drops):
    """fit_drops, checked for reach, with the model's F_peak and eps at the fit of a single test at the top."""
    if not all(0 < e < 1 for e in drops.eps):
        raise Unreachable(f"eps = {float(drops.eps[0]):g}: this model gives 0 < eps < 1")
    result, fitted, x = fit_drops(drops, args.m, args.damper, args.damper_order, args.law)
    if len(drops.v) == 1 and "tests" in result:
        result.update(F_peak=result["tests"][0]["F_peak"], eps=result["tests"][0]["eps"], v=float(drops.v[0]))
        del result["tests"]
    return result, (drops, fitted, x)


def main(argv=None, prog=None):
    parser = build_parser(prog)
    args = parser.parse_args(argv)
    check_arguments(parser, args)
    speeds = [model.drop_velocity(h) for h in args.height] if args.height else (args.v or [])
    warnings = []
    try:
        if args.curve:
            curves = []
            for path, v, i in zip(args.curve, speeds, range(len(speeds))):
                t, F, lines = read_curve(path)
                check_curve(path, t, F, lines, args.m, v)
                curves.append(Curve(t, F, v, args.height[i] if args.height else None, str(path)))
            result, fitted, x = fit_curves(curves, args.m, args.damper, args.damper_order, args.law)
            if len(curves) == 1:
                result["v"] = speeds[0]
            plot = (lambda: plot_curves(args.plot, curves, result, fitted, x))
            for test in result.get("tests", []):
                if not test["residuals_noise_like"]:
                    warnings.append(f"the residuals{' of ' + test['source'] if len(curves) > 1 else ''} are not "
                                    f"noise-like (lag-1 autocorrelation {test['residual_autocorrelation']:.3f} > "
                                    f"{WHITENESS_SIGMAS}/sqrt(n)): the model misses the curve's shape or the noise is "
                                    "correlated; the standard errors are too small")
        elif args.drops is not None:
            result, (drops, fitted, x) = drops_result(args, read_drops(args.drops))
            plot = (lambda: plot_drops(args.plot, drops, result, fitted, x))
        else:
            result, extra = fit_peak(args, speeds[0])
            plot = None
        if result.get("family"):
            result["E_s_family"] = family_moduli(result["family"], args)
            if args.plot:
                plot_family(args.plot, result["family"], [E for E, mb in zip(result["E_s_family"],
                                                          result["family"]["members"]) if mb["in_family"]])
        else:
            if not result.get("identifiable", True):
                raise Unreachable(f"the data do not determine the parameters: {result['reason']}")
            add_specimen_modulus(result, args)
            if args.plot and plot is not None:
                plot()
            poor = poorly_determined(result, ("k", "c", "c_alpha", "alpha"))
            if poor:
                warnings.append(f"{', '.join(poor)} poorly determined (standard error above {POOR:.0%} of the value"
                                f"{'; alpha: above 0.5' if 'alpha' in poor else ''}): more or other data are needed")
            if result.get("chi2") is not None:
                from scipy.stats import chi2 as chi_square
                if result["chi2"] > chi_square.ppf(0.999, result["dof"]):
                    warnings.append(f"chi-square {result['chi2']:.3g} for {result['dof']} degrees of freedom is above "
                                    "its 99.9 % quantile: the model misses the data or the sigmas are too small")
    except BadInput as e:
        print(f"{parser.prog}: {e}", file=sys.stderr)
        return 2
    except Unreachable as e:
        print(f"{parser.prog}: not reachable by this model: {e}", file=sys.stderr)
        return 2
    except RuntimeError as e:
        print(f"{parser.prog}: {e}", file=sys.stderr)
        return 1
    result.setdefault("m", args.m)
    result.setdefault("law", args.law)
    result.setdefault("damper", args.damper)
    if args.F_peak is not None:
        result["v"] = speeds[0]
    for key in ("cov_log", "singular_values"):
        result.pop(key, None)
    if result.get("family"):
        for mb in result["family"]["members"]:
            mb.pop("x", None)
    for w in warnings:
        print(f"{parser.prog}: warning: {w}", file=sys.stderr)
    if args.export_fmu is not None:
        try:
            written = exported_fmu(args, result)
        except ValueError as e:
            print(f"{parser.prog}: --export-fmu {args.export_fmu}: {e}", file=sys.stderr)
            return 2
        print(f"{parser.prog}: wrote {written}", file=sys.stderr)
    if args.json:
        print(json.dumps(result))
    else:
        print(family_report(result) if result.get("family") else text_report(result))
    return 0
