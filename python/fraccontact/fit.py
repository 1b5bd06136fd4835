"""Material identification from drop tests, as the paper does it: find the
Hertz constant k and the dashpot c that reproduce a test's peak force and
restitution coefficient, then the specimen's Young's modulus from k
(MODEL.md §2, §6). Or fit k, c and the contact onset t0 to a whole measured
force-time curve by least squares, with their standard errors and a plot.

  fraccontact fit --F-peak 1004 --eps 0.59 --height 0.020 --m 0.7437 --json
  fraccontact fit --curve test.csv --height 0.020 --m 0.7437 --plot fit.png

The model runs in-process on the package's C library (fraccontact.impact,
fraccontact.simulate), the Hertz law by default.
"""

import argparse
import csv
import json
import math
import os
import pathlib
import sys

import numpy as np
from scipy.optimize import brentq, least_squares

from . import hertz, model

MIN_ROWS = 10           # three parameters and enough residuals left to estimate the noise
MIN_PEAK_SAMPLES = 5    # samples above half the peak force: fewer cannot pin k, c and t0 apart
SPIKE_FACTOR = 5        # no sample of a smooth, resolved pulse is 5 times both its neighbours
SPIKE_NOISE_LEVELS = 10  # ... nor does Gaussian noise reach 5 x 10 = 50 standard deviations
IMPULSE_RANGE = (1 / 3, 3)  # of m v; a rebound gives 1 + eps, between 1 and 2
WHITENESS_SIGMAS = 3    # lag-1 autocorrelation of white residuals is about N(0, 1/n)
STEPS_PER_CONTACT = 4000   # the model's internal step: the Hertz contact time / 4000 (F_peak to ~1e-7)
ROWS_PER_CONTACT = 2000    # the model's force curve: a row every contact time / 2000, interpolated linearly

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
gives 1 to 2 (times in milliseconds, forces in kN, or a wrong --m or
--height); fewer than {MIN_PEAK_SAMPLES} samples above half the peak force.

Standard errors come from the Jacobian and the residuals' variance, which
assumes independent noise. The check of that: the lag-1 autocorrelation r1
of the residuals, about N(0, 1/n) for n independent samples. When
r1 > {WHITENESS_SIGMAS}/sqrt(n) (one-sided, {WHITENESS_SIGMAS} sigma) a warning says the residuals are not
noise-like: the model misses the curve's shape, or the noise is correlated
(filtered, oversampled); either way the true errors are larger.

Output: k [N/m^1.5], c [N s/m], E_s [Pa], the model's F_peak [N] and eps at
the fitted k, c; curve fits add t0 [s] and each value's standard error (±),
the k-c correlation, the rms residual [N] and r1. --json: the same in SI
units, keys k, c, t0, E_s, F_peak, eps (the model's at k, c), sigma_<key>,
correlation, rms_residual, residual_autocorrelation, residuals_noise_like,
v, m, law. Exit status: 0 fitted, 2 bad input or out of the model's reach,
1 the model failed."""


class Unreachable(Exception):
    """No k, c of this model reproduce what was asked."""


class BadInput(Exception):
    """An input this tool cannot use; the message says what is wrong and where."""


def settings(k, c, m, v, law):
    """The model's parameters for one drop test of the fit: its step from
    the Hertz contact time t_c, and time enough for any rebound."""
    t_c = hertz.contact_time(k, m, v)
    return dict(law=law, k=k, c=c, m=m, v=v, dt_max=t_c / STEPS_PER_CONTACT, t_end=1000 * t_c + 1.0)


def run(k, c, m, v, law="hertz"):
    """One impact (fraccontact.Run: .F_peak, .eps, ...)."""
    try:
        return model.impact(**settings(k, c, m, v, law))
    except ValueError as e:
        raise RuntimeError(f"the model refused k = {k:.6g}, c = {c:.6g}: {e}") from None


def force_series(k, c, m, v, law="hertz", interval=None):
    """The model's force curve: times [s] since contact onset and forces [N],
    a row every interval (default t_c / ROWS_PER_CONTACT) and at onset and
    separation."""
    if interval is None:
        interval = hertz.contact_time(k, m, v) / ROWS_PER_CONTACT
    try:
        series = model.simulate(output_interval=interval, **settings(k, c, m, v, law))
    except ValueError as e:
        raise RuntimeError(f"the model refused k = {k:.6g}, c = {c:.6g}: {e}") from None
    return series["t"], series["F"]


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
    f = lambda log_k: run(math.exp(log_k), c, m, v, law).F_peak / F_peak - 1
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
        return run(k_for_peak(F_peak, c, m, v, law), c, m, v, law).eps - eps

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


def csv_rows(path):
    """The file's non-blank rows as (line number, cells); BadInput if it cannot be read as text CSV."""
    try:
        with open(path, newline="", encoding="utf-8-sig") as f:  # -sig: a spreadsheet's byte-order mark
            reader = csv.reader(f)
            return [(reader.line_num, row) for row in reader if any(cell.strip() for cell in row)]
    except OSError as e:
        raise BadInput(f"{path}: cannot read it: {e.strerror}")
    except (UnicodeDecodeError, csv.Error) as e:
        raise BadInput(f"{path}: not a text CSV file ({e})")


def is_number(text):
    try:
        float(text)
        return True
    except ValueError:
        return False


def cell_value(path, line, row, column, name):
    """The finite number in a cell, or BadInput naming the row and column."""
    text = row[column - 1].strip()
    try:
        value = float(text)
    except ValueError:
        raise BadInput(f"{path}: row {line}, column {column} ({name}): "
                       + (f"'{text}' is not a number" if text else "empty, expected a number"))
    if not math.isfinite(value):
        raise BadInput(f"{path}: row {line}, column {column} ({name}): {text} is not a finite number")
    return value


def read_curve(path):
    """Times [s], forces [N] and file row numbers of a CSV's first two
    columns (a header row allowed)."""
    rows = csv_rows(path)
    if not rows:
        raise BadInput(f"{path}: the file is empty; expected rows of time [s], force [N]")
    if not is_number(rows[0][1][0]):
        rows = rows[1:]                                          # the header
    t, F, lines = [], [], []
    for line, row in rows:
        if len(row) < 2:
            raise BadInput(f"{path}: row {line}: one column; expected two comma-separated: time [s], force [N]")
        t.append(cell_value(path, line, row, 1, "time [s]"))
        F.append(cell_value(path, line, row, 2, "force [N]"))
        lines.append(line)
    if len(t) < MIN_ROWS:
        raise BadInput(f"{path}: {len(t)} data rows; at least {MIN_ROWS} are needed to fit k, c and t0")
    return np.array(t), np.array(F), lines


def isolated_spike(F):
    """Index of the first sample more than SPIKE_FACTOR times larger in
    magnitude than both its neighbours and SPIKE_NOISE_LEVELS noise levels,
    or None. The noise level comes from the median step, which a few spikes
    do not move."""
    size = np.abs(F)
    noise = float(np.median(np.abs(np.diff(F)))) / (0.6745 * math.sqrt(2))
    left, right = np.r_[size[1], size[:-1]], np.r_[size[1:], size[-2]]
    floor = np.maximum(np.maximum(left, right), SPIKE_NOISE_LEVELS * noise)
    spikes = np.flatnonzero(size > SPIKE_FACTOR * floor)
    return int(spikes[0]) if spikes.size else None


def check_curve(path, t, F, lines, m, v):
    """BadInput, naming the row or column, for a curve this model cannot be fitted to."""
    backwards = np.flatnonzero(np.diff(t) <= 0)
    if backwards.size:
        i = backwards[0] + 1
        raise BadInput(f"{path}: row {lines[i]}, column 1 (time [s]): {float(t[i])} is not after the previous "
                       f"row's {float(t[i - 1])}; times must increase strictly")
    spike = isolated_spike(F)
    if spike is not None:
        raise BadInput(f"{path}: row {lines[spike]}, column 2 (force [N]): an isolated spike of {F[spike]:g} N, "
                       f"more than {SPIKE_FACTOR} times both neighbours; remove or repair the row")
    largest = int(np.argmax(np.abs(F)))
    if F[largest] == 0:
        raise BadInput(f"{path}: column 2 (force [N]): all forces are zero")
    if F[largest] < 0:
        raise BadInput(f"{path}: column 2 (force [N]): forces have the wrong sign: the largest |F| is "
                       f"{F[largest]:g} N at row {lines[largest]}; compression must be positive")
    ratio = float(np.trapezoid(F, t)) / (m * v)
    if not IMPULSE_RANGE[0] <= ratio <= IMPULSE_RANGE[1]:
        column, hint = (("column 1 (time [s])", "are the times in milliseconds (or microseconds)? They must be seconds")
                        if ratio > 1 else ("column 2 (force [N])", "are the forces in kN? They must be newtons"))
        raise BadInput(f"{path}: {column}: the impulse (integral of F dt) is {ratio:.3g} times m v = "
                       f"{m * v:.4g} N s where a rebound gives 1 to 2: {hint} (or --m, --height are wrong)")
    if np.count_nonzero(F >= 0.5 * F.max()) < MIN_PEAK_SAMPLES:
        raise BadInput(f"{path}: column 1 (time [s]): fewer than {MIN_PEAK_SAMPLES} samples above half the "
                       f"peak force; the curve is sampled too coarsely to fit")


def model_curve(k, c, m, v, t, law):
    """The model's force at the times t since contact onset (zero before it
    and after separation; linear interpolation of a fine series)."""
    t_model, F_model = force_series(k, c, m, v, law)
    return np.interp(t, t_model, F_model, left=0.0, right=0.0)


def half_peak_time(t, F):
    """When F first reaches half its peak, interpolated: a marker of the
    loading edge that noise barely moves."""
    half = 0.5 * F.max()
    i = int(np.argmax(F >= half))
    return t[0] if i == 0 else float(np.interp(half, [F[i - 1], F[i]], [t[i - 1], t[i]]))


def starting_point(t, F, m, v, law):
    """k, c from F_peak and eps (eps from the impulse m v (1 + eps)); t0 by
    lining up the model's loading edge with the curve's."""
    eps0 = min(max(float(np.trapezoid(F, t)) / (m * v) - 1, 0.05), 0.95)
    k0, c0 = fit_peak_and_restitution(float(F.max()), eps0, m, v, law)
    tt = np.linspace(0, 2 * hertz.contact_time(k0, m, v), 20001)
    return k0, c0, half_peak_time(t, F) - half_peak_time(tt, model_curve(k0, c0, m, v, tt, law))


def residual_autocorrelation(r):
    """Lag-1 autocorrelation of the residuals: about N(0, 1/n) for
    independent noise, near 1 when the model misses the curve's shape."""
    r = r - r.mean()
    return float(r[1:] @ r[:-1] / (r @ r))


def fit_curve(t, F, m, v, law="hertz"):
    """Least squares on log k, log c and t0 / t_c (t_c the Hertz time of the
    start: so one relative finite-difference step suits all three)."""
    k0, c0, t0_start = starting_point(t, F, m, v, law)
    t_c = hertz.contact_time(k0, m, v)
    residual = lambda x: model_curve(math.exp(x[0]), math.exp(x[1]), m, v, t - x[2] * t_c, law) - F
    result = least_squares(residual, [math.log(k0), math.log(c0), t0_start / t_c], diff_step=1e-5,
                           xtol=1e-10, ftol=1e-10)
    s2 = float(result.fun @ result.fun) / max(len(t) - 3, 1)
    try:
        cov = s2 * np.linalg.inv(result.jac.T @ result.jac)
    except np.linalg.LinAlgError:
        raise Unreachable("the curve does not determine k, c and t0 (singular Jacobian at the fit)")
    k, c = np.exp(result.x[:2])
    r1 = residual_autocorrelation(result.fun)
    return dict(k=float(k), c=float(c), t0=float(result.x[2] * t_c), sigma_k=float(k * math.sqrt(cov[0, 0])),
                sigma_c=float(c * math.sqrt(cov[1, 1])), sigma_t0=float(t_c * math.sqrt(cov[2, 2])),
                correlation=float(cov[0, 1] / math.sqrt(cov[0, 0] * cov[1, 1])), rms_residual=math.sqrt(s2),
                residual_autocorrelation=r1, residuals_noise_like=r1 <= WHITENESS_SIGMAS / math.sqrt(len(t)),
                cov_log=cov[:2, :2].tolist())


def model_peak_and_restitution(fitted, m, v, law):
    """The model's F_peak and eps at the fitted k, c, with standard errors
    from the covariance of log k, log c, linearised. The derivatives take a
    relative step of 1e-4: the model's error (about 1e-7 at its step) moves
    them by 0.1 %, and the response is linear over it."""
    def outputs(k, c):
        r = run(k, c, m, v, law)
        return np.array([r.F_peak, r.eps])

    k, c, step = fitted["k"], fitted["c"], 1e-4
    at = outputs(k, c)
    jac = np.column_stack([(outputs(k * math.exp(step), c) - at) / step,
                           (outputs(k, c * math.exp(step)) - at) / step])
    sigma = np.sqrt(np.diag(jac @ np.array(fitted["cov_log"]) @ jac.T))
    return dict(F_peak=float(at[0]), sigma_F_peak=float(sigma[0]), eps=float(at[1]), sigma_eps=float(sigma[1]))


def plot_curve(path, t, F, fitted, m, v, law):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from . import atomic
    fig, ax = plt.subplots(figsize=(7, 4.2))
    ax.plot(t * 1e3, F, ".", ms=3, label="measured")
    tt = np.linspace(t.min(), t.max(), 800)
    ax.plot(tt * 1e3, model_curve(fitted["k"], fitted["c"], m, v, tt - fitted["t0"], law), label=(
        f"fitted: k = {with_error(fitted['k'], fitted['sigma_k'], 'N/m^1.5')}, "
        f"c = {with_error(fitted['c'], fitted['sigma_c'], 'N s/m')},\n"
        f"t0 = {with_error(fitted['t0'], fitted['sigma_t0'], 's')}"))
    ax.set(xlabel="time [ms]", ylabel="contact force [N]", title="Measured against fitted force")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    atomic.save_figure(fig, path, dpi=110, metadata={"Software": None})


def significant(x, digits):
    """x to that many significant digits, trailing zeros kept, 'e8' for 'e+08'."""
    mantissa, _, exponent = f"{x:#.{digits}g}".partition("e")
    return mantissa.rstrip(".") + (f"e{int(exponent)}" if exponent else "")


def with_error(value, sigma, unit):
    """'value ± sigma unit', the value to the second significant digit of
    sigma (its further digits are noise); 6 digits when there is no sigma."""
    if sigma is None or not sigma > 0:
        return f"{significant(value, 6)} {unit}".rstrip()
    magnitude = math.floor(math.log10(abs(value))) if value else math.floor(math.log10(sigma))
    digits = max(magnitude - math.floor(math.log10(sigma)) + 2, 1)
    return f"{significant(value, digits)} ± {significant(sigma, 2)} {unit}".rstrip()


def text_report(result):
    """The result as lines of 'name = value ± error unit'."""
    quantity = lambda key, unit: with_error(result[key], result.get(f"sigma_{key}"), unit)
    lines = [f"k      = {quantity('k', 'N/m^1.5')}", f"c      = {quantity('c', 'N s/m')}"]
    if "t0" in result:
        lines.append(f"t0     = {quantity('t0', 's')}   (contact onset on the file's time axis)")
    lines += [f"E_s    = {quantity('E_s', 'Pa')}",
              f"F_peak = {quantity('F_peak', 'N')}   (the model's, at k and c)",
              f"eps    = {quantity('eps', '')}   (the model's, at k and c)"]
    if "t0" in result:
        lines += [f"correlation of k and c = {result['correlation']:.3f}",
                  f"rms residual = {significant(result['rms_residual'], 3)} N",
                  f"lag-1 autocorrelation of the residuals = {result['residual_autocorrelation']:.3f}"]
    lines.append(f"v = {result['v']:.6g} m/s, m = {result['m']:.6g} kg, law {result['law']}")
    return "\n".join(lines)


def finite(text):
    """argparse type: a finite number."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number")
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text} is not a finite number")
    return value


def positive(text):
    """argparse type: a finite number > 0."""
    value = finite(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"{text} is not positive")
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


class OneLineParser(argparse.ArgumentParser):
    """Errors as one line on stderr, exit status 2."""

    def error(self, message):
        self.exit(2, f"fit: {message} (see --help)\n")


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
    what.add_argument("--curve", type=pathlib.Path, metavar="FILE",
                      help="CSV of the measured force: time [s], force [N] (below)")
    parser.add_argument("--eps", type=finite, help="measured restitution coefficient [1] (with --F-peak)")
    speed = parser.add_mutually_exclusive_group(required=True)
    speed.add_argument("--height", type=positive, help="drop height [m]: v = sqrt(2 g h), g = 9.81 m/s^2")
    speed.add_argument("--v", type=positive, help="impact velocity [m/s]")
    parser.add_argument("--m", type=positive, required=True, help="striker mass [kg]")
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
                        help="with --curve: an image of measured against fitted force [N] over time [ms]")
    parser.add_argument("--json", action="store_true", help="print one JSON object (SI units) instead of text")
    return parser


def fit_measured_curve(args, v):
    """The curve fit with its checks, the model's F_peak and eps, and the plot."""
    t, F, lines = read_curve(args.curve)
    check_curve(args.curve, t, F, lines, args.m, v)
    result = fit_curve(t, F, args.m, v, args.law)
    result.update(model_peak_and_restitution(result, args.m, v, args.law))
    if args.plot:
        plot_curve(args.plot, t, F, result, args.m, v, args.law)
    return result


def fit_peak(args, v):
    k, c = fit_peak_and_restitution(args.F_peak, args.eps, args.m, v, args.law)
    check = run(k, c, args.m, v, args.law)
    return dict(k=k, c=c, F_peak=check.F_peak, eps=check.eps)


def add_specimen_modulus(result, args):
    result["E_s"] = specimen_modulus(result["k"], args.R, args.E_i, args.nu_i, args.nu_s)
    if "sigma_k" in result:  # dE_s/dk by a relative step of 1e-6
        dk = 1e-6 * result["k"]
        result["sigma_E_s"] = abs(specimen_modulus(result["k"] + dk, args.R, args.E_i, args.nu_i, args.nu_s)
                                  - result["E_s"]) / dk * result["sigma_k"]


def main(argv=None, prog=None):
    parser = build_parser(prog)
    args = parser.parse_args(argv)
    if args.F_peak is not None and args.eps is None:
        parser.error("--F-peak needs --eps")
    if args.curve is not None and args.eps is not None:
        parser.error("--eps goes with --F-peak, not --curve")
    if args.plot is not None and args.curve is None:
        parser.error("--plot needs --curve")
    v = model.drop_velocity(args.height) if args.height is not None else args.v
    try:
        result = fit_measured_curve(args, v) if args.curve else fit_peak(args, v)
        add_specimen_modulus(result, args)
    except BadInput as e:
        print(f"fit: {e}", file=sys.stderr)
        return 2
    except Unreachable as e:
        print(f"fit: not reachable by this model: {e}", file=sys.stderr)
        return 2
    except RuntimeError as e:
        print(f"fit: {e}", file=sys.stderr)
        return 1
    result.update(v=v, m=args.m, law=args.law)
    result.pop("cov_log", None)
    if not result.get("residuals_noise_like", True):
        print(f"fit: warning: the residuals are not noise-like (lag-1 autocorrelation "
              f"{result['residual_autocorrelation']:.3f} > {WHITENESS_SIGMAS}/sqrt(n)): the model misses the "
              f"curve's shape or the noise is correlated; the standard errors are too small", file=sys.stderr)
    print(json.dumps(result) if args.json else text_report(result))
    return 0

