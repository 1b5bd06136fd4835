"""Material identification from drop tests, as the paper does it: find the
Hertz constant k and the damper that reproduce a test's peak force and
restitution coefficient, then the specimen's Young's modulus from k
(MODEL.md §2, §6). Or fit them and the contact onset t0 to a whole measured
force-time curve by least squares, with their standard errors and a plot.
The damper is the dashpot c (--damper 1, the default) or the springpot
F = c_alpha D^alpha x2 (--damper 2, MODEL.md §7: k, c_alpha and its order
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
import csv
import dataclasses
import json
import math
import os
import pathlib
import sys

import numpy as np
from scipy.optimize import brentq, least_squares

from . import hertz, model
from .options import OneLineParser, finite, positive

MIN_ROWS = 10           # three parameters and enough residuals left to estimate the noise
MIN_PEAK_SAMPLES = 5    # samples above half the peak force: fewer cannot pin k, c and t0 apart
SPIKE_FACTOR = 5        # no sample of a smooth, resolved pulse is 5 times both its neighbours
SPIKE_NOISE_LEVELS = 10  # ... nor does Gaussian noise reach 5 x 10 = 50 standard deviations
IMPULSE_RANGE = (1 / 3, 3)  # of m v; a rebound gives 1 + eps, between 1 and 2
# An impulse off by a unit's factor (IMPULSE_RANGE times it) is blamed on that unit: times in ms or us make it
# 1e3 or 1e6 times too large, forces in kN 1e3 times too small.
UNIT_FACTORS = ((1e3, "column 1 (time [s])", "are the times in milliseconds? They must be seconds"),
                (1e6, "column 1 (time [s])", "are the times in microseconds? They must be seconds"),
                (1e-3, "column 2 (force [N])", "are the forces in kN? They must be newtons"))
END_FRACTION = 0.1      # a whole contact starts and ends near F = 0: an end above 10 % of the peak is cut off
WHITENESS_SIGMAS = 3    # lag-1 autocorrelation of white residuals is about N(0, 1/n)
STEPS_PER_CONTACT = 4000   # the model's internal step: the Hertz contact time / 4000 (F_peak to ~1e-7)
ROWS_PER_CONTACT = 2000    # the model's force curve: a row every contact time / 2000, interpolated linearly
# The springpot's step (compressed memory): the Hertz contact time / 1000. Measured against dt -> 0
# (t_c / 40000, kernel tolerance 1e-10) for alpha 0.05 to 1 at 5, 20 and 100 mm: F_peak within 9.4e-7
# relative, eps within 8.2e-7 (t_c / 4000: 1.8e-7 both), far below any drop test's scatter.
SPRINGPOT_STEPS_PER_CONTACT = 1000
CONTACTS_PER_RUN = 50   # a run of the fit stops after 50 Hertz contact times; an impact still going counts eps = 0
ALPHA_LOWEST = 0.01     # the fitted order's lower bound (alpha -> 0 is a spring: nothing dissipated)
K_CAP = 1e5             # k at most this many times the elastic Hertz k of the peak force: beyond it the spring is rigid
FAMILY_ALPHAS = tuple(round(0.05 * i, 2) for i in range(20, 0, -1))  # 1.00, 0.95, ..., 0.05
START_ALPHAS = (1.0, 0.8, 0.6, 0.4, 0.2)   # candidate orders a free-order fit starts from (the best of them)
CONTINUATION = 0.1      # a family member is solved from its neighbour at most 0.1 away in alpha
REPRODUCE = 1e-8        # a family member reproduces F_peak (relative) and eps (absolute) to this
ALPHA_MIN_BISECTIONS = 10   # the family's lowest order to 0.05 / 2^10 = 5e-5
# Finite-difference step of the Jacobian in ln k, ln c, alpha and t0 / t_c. The figures are smooth in the
# parameters to 1e-10 (second differences over steps of 2.5e-5), so forward differences are good to ~1e-5.
STEP = 1e-5
# Singular values of the Jacobian (columns: ln k, ln c, alpha, t0 / t_c) below 1e-3 of the largest are not
# told from zero: the forward differences carry relative errors of ~1e-5, and the data set is then as good
# as rank-deficient (a parameter's standard error 1000 times the best one's).
RANK_TOLERANCE = 1e-3
POOR = 0.5              # a relative standard error above 50 % (alpha: above 0.5) is called poorly determined
MAX_HEIGHT = 10.0       # a drop height above 10 m in a table is taken for millimetres
DAMPERS = {1: "dashpot", 2: "springpot"}

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


class Unreachable(Exception):
    """No parameters of this model reproduce what was asked."""


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
        where, hint = impulse_hint(F, lines, ratio)
        raise BadInput(f"{path}: {where}: the impulse (integral of F dt) is {ratio:.3g} times m v = "
                       f"{m * v:.4g} N s where a rebound gives 1 to 2: {hint}")
    if np.count_nonzero(F >= 0.5 * F.max()) < MIN_PEAK_SAMPLES:
        raise BadInput(f"{path}: column 1 (time [s]): fewer than {MIN_PEAK_SAMPLES} samples above half the "
                       f"peak force; the curve is sampled too coarsely to fit")


def impulse_hint(F, lines, ratio):
    """Where a wrong impulse comes from, and what to check: a curve that
    does not hold the whole contact (its first or last force above
    END_FRACTION of the peak), else a unit whose factor explains the ratio,
    else the striker's mass and speed."""
    peak = float(F.max())
    for i, end in ((0, "starts"), (-1, "ends")):
        if F[i] > END_FRACTION * peak:
            return (f"row {lines[i]}, column 2 (force [N])",
                    f"the curve {end} at {F[i]:.4g} N, {F[i] / peak:.0%} of its peak: it must hold the whole "
                    "contact, from before its onset to after the separation")
    for factor, column, hint in UNIT_FACTORS:
        if IMPULSE_RANGE[0] <= ratio / factor <= IMPULSE_RANGE[1]:
            return column, hint
    return ("columns 1 and 2", "no unit (ms or us for the times, kN for the forces) explains it: are --m and "
            "--height (or --v) this test's, and the columns the time [s] and the force [N]?")


def half_peak_time(t, F):
    """When F first reaches half its peak, interpolated: a marker of the
    loading edge that noise barely moves."""
    half = 0.5 * F.max()
    i = int(np.argmax(F >= half))
    return t[0] if i == 0 else float(np.interp(half, [F[i - 1], F[i]], [t[i - 1], t[i]]))


def residual_autocorrelation(r):
    """Lag-1 autocorrelation of the residuals: about N(0, 1/n) for
    independent noise, near 1 when the model misses the curve's shape."""
    r = r - r.mean()
    return float(r[1:] @ r[:-1] / (r @ r))


# ---------------------------------------------------------------------------------------------------------------
# The models fitted (dashpot: k, c; springpot: k, c_alpha, alpha) on one fixed step, and the least squares.


@dataclasses.dataclass(frozen=True)
class Model:
    """What is fitted, and the fit's fixed numerics. A parameter vector x is
    (ln(k / k_ref), ln(c_tau / c_ref)) and, for a springpot of free order,
    alpha. c_tau = c_alpha tau^(1 - alpha) is the dashpot whose impedance
    equals the springpot's at the frequency 1/tau (tau: the Hertz contact
    time at the start), which keeps c and alpha apart: c_alpha's unit changes
    with alpha. The step dt_max is the same for every parameter set of a fit:
    the compressed memory's kernel depends on it, and a step following k
    would move the figures by the model's error between neighbouring sets."""
    m: float
    law: str
    damper: int          # 1 dashpot, 2 springpot
    alpha: float | None  # the springpot's order held fixed; None: fitted
    k_ref: float         # [N/m^1.5]
    c_ref: float         # [N s/m]
    tau: float           # [s]
    dt_max: float        # [s]
    t_end: float         # [s]

    @property
    def free_alpha(self):
        return self.damper == 2 and self.alpha is None

    @property
    def size(self):
        return 3 if self.free_alpha else 2

    @property
    def names(self):
        """The reported parameters: k, c or k, c_alpha, alpha (alpha only when fitted)."""
        return ("k", "c") if self.damper == 1 else ("k", "c_alpha", "alpha") if self.free_alpha else ("k", "c_alpha")

    def with_alpha(self, alpha):
        """The springpot of this fit with its order fixed at alpha."""
        return dataclasses.replace(self, damper=2, alpha=float(alpha))

    def order(self, x):
        x = np.asarray(x, dtype=float)
        return x[..., 2] if self.free_alpha else 1.0 if self.damper == 1 else self.alpha

    def vector(self, k, c_tau, alpha=None):
        """x from k [N/m^1.5], c_tau [N s/m] and (free order) alpha."""
        x = [math.log(k / self.k_ref), math.log(c_tau / self.c_ref)]
        return np.array(x + [alpha] if self.free_alpha else x)

    def values(self, x):
        """{k, c} or {k, c_alpha, alpha} of x (arrays for a stack of x)."""
        x = np.asarray(x, dtype=float)
        k, c_tau = self.k_ref * np.exp(x[..., 0]), self.c_ref * np.exp(x[..., 1])
        if self.damper == 1:
            return dict(k=k, c=c_tau)
        alpha = self.order(x)
        return dict(k=k, c_alpha=c_tau * self.tau ** (alpha - 1.0), alpha=alpha)

    def library(self, x):
        """The library's parameters for x (or a stack of x)."""
        p = dict(law=self.law, m=self.m, dt_max=self.dt_max, t_end=self.t_end, **self.values(x))
        if self.damper == 2:
            p.update(damper=2, memory=2, damper_order=p.pop("alpha"))
        return p

    def k_elastic(self, F_peak, v):
        return hertz.stiffness_for_peak(F_peak, self.m, v)

    def bounds(self, k_cap):
        """Lower and upper bounds of x: k up to k_cap, alpha in [ALPHA_LOWEST, 1]."""
        lower, upper = [math.log(1e-3), -30.0], [math.log(k_cap / self.k_ref), 30.0]
        if self.free_alpha:
            lower.append(ALPHA_LOWEST)
            upper.append(1.0)
        return np.array(lower), np.array(upper)

    def transform(self):
        """d(ln k, ln c or ln c_alpha, alpha) / dx: ln c_alpha = ln c_tau + (alpha - 1) ln tau."""
        T = np.eye(self.size)
        if self.free_alpha:
            T[1, 2] = math.log(self.tau)
        return T


def make_model(m, law, damper, alpha, k0, c0, velocities):
    """The fit's model: the references k0, c0 (a dashpot fit of one test),
    tau and the step from the elastic Hertz contact times at k0."""
    times = [hertz.contact_time(k0, m, v) for v in velocities]
    steps = STEPS_PER_CONTACT if damper == 1 else SPRINGPOT_STEPS_PER_CONTACT
    return Model(m=m, law=law, damper=damper, alpha=alpha if damper == 2 else None, k_ref=k0, c_ref=c0,
                 tau=hertz.contact_time(k0, m, float(np.median(velocities))), dt_max=min(times) / steps,
                 t_end=CONTACTS_PER_RUN * max(times))


def described(values):
    return ", ".join(f"{name} = {float(value):.6g}" for name, value in values.items())


def figures(fitted, X, v):
    """F_peak [N] and eps of each parameter set (the rows of X) at each impact
    velocity of v [m/s]: two arrays (len(X), len(v)), in one library call. A
    first impact not ended by t_end counts as its largest force and eps = 0."""
    X, v = np.atleast_2d(np.asarray(X, dtype=float)), np.atleast_1d(np.asarray(v, dtype=float))
    params = {name: (value[:, None] if np.ndim(value) else value) for name, value in fitted.library(X).items()}
    try:
        r = model.impacts(v=v[None, :], **params)
    except (ValueError, RuntimeError) as e:
        raise RuntimeError(f"the model refused a parameter set of the fit: {e}") from None
    ended = np.isfinite(r["F_peak"])
    return np.where(ended, r["F_peak"], r["end"]["F_peak"]), np.where(ended, r["eps"], 0.0)


def series(fitted, x, v, interval):
    """The model's force curve at x and v: times [s] since contact onset and
    forces [N], a row every interval and at onset and separation."""
    try:
        s = model.simulate(output_interval=interval, v=v, **fitted.library(x))
    except (ValueError, RuntimeError) as e:
        raise RuntimeError(f"the model refused {described(fitted.values(x))}: {e}") from None
    return s["t"], s["F"]


def least_squares_fit(residuals, x0, lower, upper):
    """least_squares on the residual vectors residuals(X) of a stack of
    parameter vectors (evaluated together: one library call where the data
    allow), with a forward-difference Jacobian of step STEP in every
    component (each an O(1) quantity: logarithms, alpha, t0 / t_c)."""
    cache = {}

    def evaluate(points):
        missing = [p for p in points if p.tobytes() not in cache]
        if missing:
            for p, r in zip(missing, residuals(np.array(missing))):
                cache[p.tobytes()] = r
        return np.array([cache[p.tobytes()] for p in points])

    def fun(x):
        return evaluate([np.array(x, dtype=float)])[0]

    def jac(x):
        x = np.array(x, dtype=float)
        h = np.where(x + STEP > upper, -STEP, STEP)
        points = [x] + [x + h[j] * np.eye(len(x))[j] for j in range(len(x))]
        R = evaluate(points)
        return ((R[1:] - R[0]) / h[:, None]).T

    x0 = np.clip(np.asarray(x0, dtype=float), lower + 1e-9, upper - 1e-9)
    result = least_squares(fun, x0, jac=jac, bounds=(lower, upper), x_scale=1.0, xtol=1e-11, ftol=1e-12,
                           gtol=1e-12, max_nfev=400)
    result.jac = jac(result.x)   # at the solution itself (trf's last Jacobian may be a step behind)
    return result


def identifiability(J, fitted, extra=()):
    """Whether the Jacobian J (weighted residuals by x and then the extra
    parameters, e.g. t0 / t_c) can determine them: dict(identifiable,
    reason, condition, singular_values), the reason naming the undetermined
    combination of the reported parameters (ln k, ln c or ln c_alpha, alpha)."""
    names = list(fitted.names) + list(extra)
    n, p = J.shape
    if n < p:
        return dict(identifiable=False, reason=f"{n} data for {p} parameters ({', '.join(names)})",
                    condition=math.inf, singular_values=[])
    _, s, Vt = np.linalg.svd(J, full_matrices=False)
    condition = float(s[0] / s[-1]) if s[-1] > 0 else math.inf
    out = dict(identifiable=True, reason="", condition=condition, singular_values=s.tolist())
    if not s[-1] > RANK_TOLERANCE * s[0]:
        rank = int(np.count_nonzero(s > RANK_TOLERANCE * s[0]))
        direction = np.r_[fitted.transform() @ Vt[-1][:fitted.size], Vt[-1][fitted.size:]]
        direction /= np.abs(direction).max()
        shown = [(name, d) for name, d in zip(names, direction) if abs(d) >= 0.005]
        change = " : ".join(("d alpha" if name == "alpha" else f"d ln {name}") for name, _ in shown)
        out.update(identifiable=False, reason=f"the Jacobian has rank {rank} of {p} (condition number "
                   f"{condition:.3g}): a change {change} = {' : '.join(f'{d:+.2f}' for _, d in shown)} "
                   "leaves the fit unchanged")
    return out


def reported(fitted, x, cov_x):
    """The fitted values with their standard errors and correlations from the
    covariance of x (None: no errors)."""
    values = {name: float(value) for name, value in fitted.values(x).items()}
    out = dict(values)
    if fitted.damper == 2 and not fitted.free_alpha:
        out["alpha_fixed"] = True
    if cov_x is None:
        return out
    T = fitted.transform()
    cov = T @ cov_x[:fitted.size, :fitted.size] @ T.T     # of ln k, ln c (or ln c_alpha), alpha
    sd = np.sqrt(np.diag(cov))
    for i, name in enumerate(fitted.names):
        out[f"sigma_{name}"] = float(sd[i] if name == "alpha" else values[name] * sd[i])
    corr = cov / np.outer(sd, sd)
    out["correlation"] = float(corr[0, 1])
    if fitted.free_alpha:
        out["correlations"] = {f"{a},{b}": float(corr[i, j]) for i, a in enumerate(fitted.names)
                               for j, b in enumerate(fitted.names) if i < j}
    out["cov_log"] = cov.tolist()
    return out


def poorly_determined(result, names):
    """The names whose relative standard error exceeds POOR (alpha: absolute)."""
    poor = []
    for name in names:
        sigma = result.get(f"sigma_{name}")
        if sigma is not None and sigma > POOR * (1.0 if name == "alpha" else abs(result[name])):
            poor.append(name)
    return poor


# ---------------------------------------------------------------------------------------------------------------
# Drop tests: F_max and eps at one or more heights.


@dataclasses.dataclass
class Drops:
    """Measured drop tests: impact velocities [m/s], heights [m] (None where
    a velocity was given), F_max [N], eps, their standard deviations (None:
    unknown, estimated from the residuals) and the rows they came from."""
    v: np.ndarray
    F: np.ndarray
    eps: np.ndarray
    sigma_F: np.ndarray | None = None
    sigma_eps: np.ndarray | None = None
    heights: list | None = None
    lines: list | None = None

    @property
    def absolute(self):
        return self.sigma_F is not None

    def scales(self):
        """Divisors of the F and eps residuals: the sigmas, or F (relative) and 1."""
        return (self.sigma_F, self.sigma_eps) if self.absolute else (self.F, np.ones_like(self.eps))

    def subset(self, i):
        """The tests at the indices i."""
        i = np.atleast_1d(i)
        array = lambda a: None if a is None else a[i]
        listed = lambda a: None if a is None else [a[j] for j in i]
        return Drops(self.v[i], self.F[i], self.eps[i], array(self.sigma_F), array(self.sigma_eps),
                     listed(self.heights), listed(self.lines))

    def central(self):
        """Index of the test at the median velocity."""
        return int(np.argsort(self.v)[len(self.v) // 2])


def drop_residuals(fitted, drops):
    """residuals(X) of the drop tests: (F_model - F) / scale_F, (eps_model - eps) / scale_eps per test."""
    sF, se = drops.scales()

    def residuals(X):
        F, eps = figures(fitted, X, drops.v)
        return np.hstack([(F - drops.F) / sF, (eps - drops.eps) / se])
    return residuals


def dashpot_start(F_peak, eps, m, v, law):
    """k, c of the dashpot that reproduce one test (nested root finding)."""
    return fit_peak_and_restitution(F_peak, eps, m, v, law)


def solve_fixed_order(fitted, drops, x0, k_cap):
    """Least squares of the drop tests at a fixed order (two parameters) from
    x0: (x, rms of the scaled residuals, k at the cap)."""
    lower, upper = fitted.bounds(k_cap)
    result = least_squares_fit(drop_residuals(fitted, drops), x0, lower, upper)
    return result.x, float(np.sqrt(np.mean(result.fun ** 2))), bool(result.x[0] > upper[0] - 1e-6)


def family(base, drops, alphas=FAMILY_ALPHAS, bisect=True):
    """For each springpot order alpha (from 1 down; 1 always), the k and
    c_alpha that fit the drop tests best, each solved from its neighbour
    (continuation in steps of at most CONTINUATION, from the dashpot's fit
    of the central test). A member is in the family when it fits as well as
    the best member (for one test: reproduces F_max and eps to REPRODUCE)
    with k below the cap (K_CAP times the elastic Hertz k of the central
    test's F_max). alpha_min, the lowest order in the family, by bisection.
    Returns dict(members: [dict(alpha, k, c_alpha, F_peak, eps, rms,
    k_capped, in_family, x)], alpha_min, k_cap, tolerance)."""
    i = drops.central()
    k_cap = K_CAP * base.k_elastic(drops.F[i], drops.v[i])
    tolerance = REPRODUCE * (max(float(np.max(drops.F / drops.sigma_F)), float(np.max(1 / drops.sigma_eps)))
                             if drops.absolute else 1.0)
    orders = sorted({float(a) for a in alphas} | {1.0}, reverse=True)
    solved, x, alpha_now = {}, np.zeros(2), 1.0
    for alpha in orders:
        while alpha_now - alpha > CONTINUATION + 1e-12:   # intermediate orders keep the continuation close
            alpha_now = round(alpha_now - CONTINUATION, 10)
            xi, _, capped = solve_fixed_order(base.with_alpha(alpha_now), drops, x, k_cap)
            x = x if capped else xi
        solved[alpha] = solve_fixed_order(base.with_alpha(alpha), drops, x, k_cap)
        if not solved[alpha][2]:
            x = solved[alpha][0]
        alpha_now = alpha
    reached = [rms for _, rms, capped in solved.values() if not capped]
    best = min(reached) if reached else math.inf

    def inside(s):
        return (not s[2]) and s[1] <= best + tolerance
    members = [member(base.with_alpha(a), drops, *solved[a], inside(solved[a])) for a in orders]
    in_family = [a for a in sorted(solved) if inside(solved[a])]
    alpha_min = in_family[0] if in_family else None
    below = [a for a in sorted(solved) if in_family and a < in_family[0]]
    if bisect and below:     # between the lowest member and the order below it
        lo, hi, x_hi = below[-1], in_family[0], solved[in_family[0]][0]
        for _ in range(ALPHA_MIN_BISECTIONS):
            mid = 0.5 * (lo + hi)
            s = solve_fixed_order(base.with_alpha(mid), drops, x_hi, k_cap)
            if inside(s):
                hi, x_hi = mid, s[0]
            else:
                lo = mid
        alpha_min = hi
    return dict(members=members, alpha_min=alpha_min, alpha_min_bounded=bool(bisect and below), k_cap=k_cap,
                tolerance=tolerance)


def member(fitted, drops, x, rms, capped, in_family):
    F, eps = figures(fitted, [x], drops.v)
    values = {name: float(value) for name, value in fitted.values(x).items()}
    return dict(alpha=fitted.alpha, k=values["k"], c_alpha=values["c_alpha"], F_peak=F[0].tolist(),
                eps=eps[0].tolist(), rms=rms, k_capped=capped, in_family=bool(in_family), x=x.tolist())


def start_point(base, drops, score=None):
    """x to start a fit of several tests from: the dashpot's exact fit of the
    central test (x = 0); for a springpot of free order, the member of that
    test's family at START_ALPHAS that scores best on all the data (score(x)
    -> cost; by default the drop tests' squared residuals); of fixed order,
    that test's member at the order."""
    if base.damper == 1:
        return np.zeros(2)
    one = drops.subset(drops.central())
    if not base.free_alpha:
        last = family(base, one, [base.alpha], bisect=False)["members"][-1]
        return np.array(last["x"]) if last["in_family"] else np.zeros(2)
    fam = family(base, one, START_ALPHAS, bisect=False)
    candidates = [np.r_[mb["x"], mb["alpha"]] for mb in fam["members"] if mb["in_family"]]
    if not candidates:
        return np.r_[0.0, 0.0, 1.0]
    if score is None:
        costs = np.sum(drop_residuals(base, drops)(np.array(candidates)) ** 2, axis=1)
    else:
        costs = [score(c) for c in candidates]
    return candidates[int(np.argmin(costs))]


def exact_member(base, drops):
    """One test and as many parameters (dashpot, or springpot of fixed order):
    x reproducing its F_max and eps; Unreachable when none does."""
    if base.damper == 1:
        return np.zeros(2)                     # the references are the central test's exact dashpot fit
    fam = family(base, drops, [base.alpha])
    last = fam["members"][-1]
    if not last["in_family"]:
        lowest = f" (the lowest order that reaches them is {fam['alpha_min']:.4g})" if fam["alpha_min"] else ""
        raise Unreachable(f"F_peak = {drops.F[0]:g} N and eps = {drops.eps[0]:g} at v = {drops.v[0]:.6g} m/s are out "
                          f"of reach of a springpot of order {base.alpha:g} with k below {fam['k_cap']:.3g} N/m^1.5"
                          + lowest)
    return np.array(last["x"])


def fit_drops(drops, m, damper=1, alpha=None, law="hertz"):
    """k and the damper fitted to the drop tests at once (least squares on
    F_max and eps, weighed as Drops.scales says), with standard errors and
    the identifiability check. For data that cannot identify them (fewer data
    than parameters, or a rank-deficient Jacobian), result["family"] holds the
    family of solutions. Returns (result, model, x)."""
    i = drops.central()
    k0, c0 = dashpot_start(drops.F[i], drops.eps[i], m, drops.v[i], law)
    base = make_model(m, law, damper, alpha, k0, c0, drops.v)
    n_data = 2 * len(drops.v)
    out = dict(damper=damper, law=law, m=m, n_tests=len(drops.v), n_data=n_data, n_params=base.size,
               absolute=drops.absolute)
    if n_data < base.size:
        ident = identifiability(np.zeros((n_data, base.size)), base)
        out.update(identifiable=False, reason=ident["reason"], family=family(base, drops))
        return out, base, None
    if n_data == base.size:                    # solved exactly: no standard errors
        x = exact_member(base, drops)
        out.update(reported(base, x, None), identifiable=True, tests=test_rows(base, drops, x, None))
        return out, base, x
    lower, upper = base.bounds(K_CAP * base.k_elastic(drops.F[i], drops.v[i]))
    result = least_squares_fit(drop_residuals(base, drops), start_point(base, drops), lower, upper)
    ident = identifiability(result.jac, base)
    dof = n_data - base.size
    rss = float(result.fun @ result.fun)
    s2 = 1.0 if drops.absolute else rss / dof
    out.update(identifiable=ident["identifiable"], reason=ident["reason"], condition=ident["condition"],
               singular_values=ident["singular_values"], dof=dof)
    out.update(chi2=rss) if drops.absolute else out.update(residual_scale=math.sqrt(s2))
    if not ident["identifiable"]:
        out.update(reported(base, result.x, None), family=family(base, drops) if damper == 2 else None)
        return out, base, result.x
    cov_x = s2 * np.linalg.inv(result.jac.T @ result.jac)
    out.update(reported(base, result.x, cov_x), tests=test_rows(base, drops, result.x, cov_x),
               at_bound=bool(base.free_alpha and result.x[2] >= 1.0 - 1e-9))
    return out, base, result.x


def test_rows(fitted, drops, x, cov_x):
    """Per test: height, v, measured F_max and eps (and sigmas), the model's
    (with standard errors from cov_x)."""
    F, eps = figures(fitted, [x], drops.v)
    rows = []
    sF = sE = None
    if cov_x is not None:
        X = [x] + [x + STEP * e for e in np.eye(len(x))]
        Fs, Es = figures(fitted, X, drops.v)
        GF, GE = (Fs[1:] - Fs[0]) / STEP, (Es[1:] - Es[0]) / STEP     # d(.)/dx, (p, n)
        sF = np.sqrt(np.einsum("in,ij,jn->n", GF, cov_x, GF))
        sE = np.sqrt(np.einsum("in,ij,jn->n", GE, cov_x, GE))
    for j in range(len(drops.v)):
        row = dict(height=None if drops.heights is None else drops.heights[j], v=float(drops.v[j]),
                   F_max=float(drops.F[j]), eps_measured=float(drops.eps[j]), F_peak=float(F[0, j]),
                   eps=float(eps[0, j]))
        if drops.absolute:
            row.update(sigma_F_max=float(drops.sigma_F[j]), sigma_eps_measured=float(drops.sigma_eps[j]))
        if sF is not None:
            row.update(sigma_F_peak=float(sF[j]), sigma_eps=float(sE[j]))
        if drops.lines is not None:
            row["row"] = drops.lines[j]
        rows.append(row)
    return rows


# ---------------------------------------------------------------------------------------------------------------
# Force curves: one or more, each with its own contact onset t0.


@dataclasses.dataclass
class Curve:
    """A measured force curve: times [s], forces [N], the impact velocity
    [m/s], its drop height [m] (or None) and where it came from."""
    t: np.ndarray
    F: np.ndarray
    v: float
    height: float | None = None
    source: str = ""


def curve_residuals(fitted, curves, weights):
    """residuals(X) of the curves, X = (model parameters, t0_i / t_c_i): the
    weighted differences model - measured, the model's series computed once
    per model parameter set (a t0 step only shifts it)."""
    p = fitted.size
    t_c = [hertz.contact_time(fitted.k_ref, fitted.m, c.v) for c in curves]
    cache = {}

    def one(x):
        key = x[:p].tobytes()
        if key not in cache:
            cache[key] = [series(fitted, x[:p], c.v, tc / ROWS_PER_CONTACT) for c, tc in zip(curves, t_c)]
        parts = []
        for i, (c, tc, (tm, Fm), w) in enumerate(zip(curves, t_c, cache[key], weights)):
            parts.append(w * (np.interp(c.t - x[p + i] * tc, tm, Fm, left=0.0, right=0.0) - c.F))
        return np.concatenate(parts)

    return (lambda X: np.array([one(x) for x in X])), t_c


def align_onsets(fitted, x, curves, t_c):
    """t0_i / t_c_i lining up the model's loading edge at x with each curve's."""
    out = []
    for c, tc in zip(curves, t_c):
        tt = np.linspace(0, 2 * tc, 20001)
        tm, Fm = series(fitted, x, c.v, tc / ROWS_PER_CONTACT)
        out.append((half_peak_time(c.t, c.F) - half_peak_time(tt, np.interp(tt, tm, Fm, left=0.0, right=0.0))) / tc)
    return np.array(out)


def impulse_restitution(c, m):
    """eps from the curve's impulse m v (1 + eps), kept within [0.05, 0.95]."""
    return min(max(float(np.trapezoid(c.F, c.t)) / (m * c.v) - 1, 0.05), 0.95)


def fit_curves(curves, m, damper=1, alpha=None, law="hertz"):
    """k and the damper fitted to one or more force curves at once, each with
    its own onset t0; several curves are weighed by their own noise (the rms
    residual of a first, unweighted pass). Returns (result, model, x)."""
    drops = Drops(v=np.array([c.v for c in curves]), F=np.array([float(c.F.max()) for c in curves]),
                  eps=np.array([impulse_restitution(c, m) for c in curves]))
    i = drops.central()
    k0, c0 = dashpot_start(drops.F[i], drops.eps[i], m, drops.v[i], law)
    base = make_model(m, law, damper, alpha, k0, c0, drops.v)
    p, n = base.size, len(curves)
    weights = np.ones(n)
    residuals, t_c = curve_residuals(base, curves, weights)

    def score(x):
        t0 = align_onsets(base, x, curves, t_c)
        r = residuals(np.array([np.r_[x, t0]]))[0]
        return float(r @ r)
    x_model = start_point(base, drops, score if base.free_alpha else None)
    x0 = np.r_[x_model, align_onsets(base, x_model, curves, t_c)]
    lower, upper = base.bounds(K_CAP * base.k_elastic(drops.F[i], drops.v[i]))
    lower, upper = np.r_[lower, np.full(n, -np.inf)], np.r_[upper, np.full(n, np.inf)]
    result = least_squares_fit(residuals, x0, lower, upper)
    sizes = np.array([len(c.t) for c in curves])
    N = int(sizes.sum())
    if n > 1:   # weigh each curve by its own noise, and fit again from there
        parts = np.split(result.fun, np.cumsum(sizes)[:-1])
        noise = np.array([math.sqrt(float(r @ r) / len(r) * N / (N - p - n)) for r in parts])
        weights = 1.0 / noise
        residuals, _ = curve_residuals(base, curves, weights)
        result = least_squares_fit(residuals, result.x, lower, upper)
    names = list(base.names) + [f"t0_{j + 1}" if n > 1 else "t0" for j in range(n)]
    ident = identifiability(result.jac, base, names[p:])
    s2 = float(result.fun @ result.fun) / max(N - p - n, 1)
    out = dict(damper=damper, law=law, m=m, n_tests=n, n_data=N, n_params=p + n, identifiable=ident["identifiable"],
               reason=ident["reason"], condition=ident["condition"], singular_values=ident["singular_values"])
    try:
        cov_x = s2 * np.linalg.inv(result.jac.T @ result.jac)
    except np.linalg.LinAlgError:
        cov_x = None
    if not ident["identifiable"] or cov_x is None:
        out.update(reported(base, result.x[:p], None), identifiable=False,
                   reason=ident["reason"] or "the Jacobian is singular")
        return out, base, result.x
    out.update(reported(base, result.x[:p], cov_x))
    parts = np.split(result.fun, np.cumsum(sizes)[:-1])
    F, eps = figures(base, [result.x[:p]], drops.v)
    X = [result.x[:p]] + [result.x[:p] + STEP * e for e in np.eye(p)]
    Fs, Es = figures(base, X, drops.v)
    GF, GE = (Fs[1:] - Fs[0]) / STEP, (Es[1:] - Es[0]) / STEP
    cov_m = cov_x[:p, :p]
    tests = []
    for j, c in enumerate(curves):
        r = parts[j] / weights[j]                          # in newtons
        r1 = residual_autocorrelation(r)
        tests.append(dict(source=c.source, height=c.height, v=c.v, t0=float(result.x[p + j] * t_c[j]),
                          sigma_t0=float(t_c[j] * math.sqrt(cov_x[p + j, p + j])),
                          rms_residual=float(np.sqrt(np.mean(r ** 2))), residual_autocorrelation=r1,
                          residuals_noise_like=bool(r1 <= WHITENESS_SIGMAS / math.sqrt(len(r))),
                          F_max=float(c.F.max()), F_peak=float(F[0, j]),
                          sigma_F_peak=float(math.sqrt(GF[:, j] @ cov_m @ GF[:, j])), eps=float(eps[0, j]),
                          sigma_eps=float(math.sqrt(GE[:, j] @ cov_m @ GE[:, j]))))
    out["tests"] = tests
    out["at_bound"] = bool(base.free_alpha and result.x[2] >= 1.0 - 1e-9)
    if n == 1:   # one curve: its figures at the top, as before
        out.update({key: tests[0][key] for key in ("t0", "sigma_t0", "F_peak", "sigma_F_peak", "eps", "sigma_eps",
                                                   "residual_autocorrelation", "residuals_noise_like")})
        out["rms_residual"] = math.sqrt(s2)
    return out, base, result.x


def fit_curve(t, F, m, v, law="hertz", damper=1, alpha=None):
    """One curve: k, c (or c_alpha and alpha) and t0 with standard errors
    (fit_curves of one curve); Unreachable when the curve cannot determine them."""
    result, _, _ = fit_curves([Curve(np.asarray(t, dtype=float), np.asarray(F, dtype=float), v)], m, damper, alpha, law)
    if not result["identifiable"]:
        raise Unreachable(f"the curve does not determine the parameters: {result['reason']}")
    return result


# ---------------------------------------------------------------------------------------------------------------
# The drop-test table.


def read_drops(path):
    """Drops from a CSV of height [m], F_max [N], eps [, sigma_F_max [N],
    sigma_eps] (a header row allowed); BadInput naming the row and column."""
    rows = csv_rows(path)
    if not rows:
        raise BadInput(f"{path}: the file is empty; expected rows of height [m], F_max [N], eps")
    if not is_number(rows[0][1][0]):
        rows = rows[1:]                                          # the header
    if not rows:
        raise BadInput(f"{path}: 0 data rows; expected rows of height [m], F_max [N], eps")
    names = ("height [m]", "F_max [N]", "eps", "sigma_F_max [N]", "sigma_eps")
    table, lines, with_sigmas = [], [], None
    for line, row in rows:
        while row and not row[-1].strip():
            row = row[:-1]                                       # trailing empty cells
        if len(row) < 3:
            raise BadInput(f"{path}: row {line}: {len(row)} column{'s' if len(row) != 1 else ''}; expected three "
                           "comma-separated: height [m], F_max [N], eps (then optionally sigma_F_max [N], sigma_eps)")
        if len(row) == 4:
            raise BadInput(f"{path}: row {line}, column 5 (sigma_eps): missing; give both sigmas or neither")
        sigmas = len(row) >= 5
        if with_sigmas is None:
            with_sigmas, first = sigmas, line
        elif sigmas != with_sigmas:
            raise BadInput(f"{path}: row {line}: {'has' if sigmas else 'lacks'} the sigma columns 4 and 5, row "
                           f"{first} {'lacks' if sigmas else 'has'} them; give them for every row or for none")
        values = [cell_value(path, line, row, j + 1, names[j]) for j in range(5 if sigmas else 3)]
        height, F, eps = values[:3]
        if not height > 0:
            raise BadInput(f"{path}: row {line}, column 1 (height [m]): {height:g} is not above 0")
        if height > MAX_HEIGHT:
            raise BadInput(f"{path}: row {line}, column 1 (height [m]): {height:g} m is above {MAX_HEIGHT:g} m: "
                           "millimetres? Heights are metres")
        if not F > 0:
            raise BadInput(f"{path}: row {line}, column 2 (F_max [N]): {F:g} is not above 0")
        if not 0 < eps < 1:
            hint = ": a percentage? eps is a fraction" if 1 < eps < 100 else ""
            raise BadInput(f"{path}: row {line}, column 3 (eps): {eps:g} is not between 0 and 1{hint}")
        for j in (3, 4):
            if sigmas and not values[j] > 0:
                raise BadInput(f"{path}: row {line}, column {j + 1} ({names[j]}): {values[j]:g} is not above 0")
        table.append(values)
        lines.append(line)
    a = np.array(table)
    heights = a[:, 0].tolist()
    return Drops(v=np.array([model.drop_velocity(h) for h in heights]), F=a[:, 1], eps=a[:, 2],
                 sigma_F=a[:, 3] if with_sigmas else None, sigma_eps=a[:, 4] if with_sigmas else None,
                 heights=heights, lines=lines)


# ---------------------------------------------------------------------------------------------------------------
# Plots.


def pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def save(fig, path):
    from . import atomic
    fig.tight_layout()
    atomic.save_figure(fig, path, dpi=110, metadata={"Software": None})


def parameters_label(result):
    """'k = ... , c = ...' (or c_alpha, alpha) with errors, for a legend."""
    parts = [f"k = {with_error(result['k'], result.get('sigma_k'), 'N/m^1.5')}"]
    if "c" in result:
        parts.append(f"c = {with_error(result['c'], result.get('sigma_c'), 'N s/m')}")
    else:
        parts.append(f"c_alpha = {with_error(result['c_alpha'], result.get('sigma_c_alpha'), 'N s^alpha/m')}")
        parts.append(f"alpha = {with_error(result['alpha'], result.get('sigma_alpha'), '')}".rstrip())
    return ",\n".join(parts)


def plot_curves(path, curves, result, fitted, x):
    """Measured against fitted force [N] over time [ms], every curve."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.2))
    p = fitted.size
    for j, (c, test) in enumerate(zip(curves, result["tests"])):
        dots = ax.plot(c.t * 1e3, c.F, ".", ms=3, label=f"measured {c.source}" if len(curves) > 1 else "measured")
        tt = np.linspace(c.t.min(), c.t.max(), 800)
        tc = hertz.contact_time(fitted.k_ref, fitted.m, c.v)
        tm, Fm = series(fitted, x[:p], c.v, tc / ROWS_PER_CONTACT)
        ax.plot(tt * 1e3, np.interp(tt - test["t0"], tm, Fm, left=0.0, right=0.0), color="k" if len(curves) == 1
                else dots[0].get_color(), lw=1, label="fitted" if j == 0 else None)
    ax.set(xlabel="time [ms]", ylabel="contact force [N]", title="Measured against fitted force")
    ax.text(0.98, 0.97, parameters_label(result), transform=ax.transAxes, ha="right", va="top", fontsize=8)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    save(fig, path)


def plot_drops(path, drops, result, fitted, x):
    """F_max and eps against drop height, measured and fitted."""
    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    heights = np.array(drops.heights if drops.heights is not None else drops.v ** 2 / (2 * 9.81))
    h = np.linspace(0.5 * heights.min(), 1.1 * heights.max(), 60)
    F, eps = figures(fitted, [x], [model.drop_velocity(a) for a in h])
    sF, sE = (drops.sigma_F, drops.sigma_eps) if drops.absolute else (None, None)
    for ax, measured, sigma, line, label in ((axes[0], drops.F, sF, F[0], "peak force F_max [N]"),
                                             (axes[1], drops.eps, sE, eps[0], "restitution coefficient eps")):
        ax.errorbar(heights * 1e3, measured, yerr=sigma, fmt="o", ms=4, label="measured")
        ax.plot(h * 1e3, line, label="fitted")
        ax.set(xlabel="drop height [mm]", ylabel=label)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    axes[1].text(0.98, 0.97, parameters_label(result), transform=axes[1].transAxes, ha="right", va="top", fontsize=8)
    fig.suptitle(f"Drop tests fitted at once ({DAMPERS[fitted.damper]}, m = {fitted.m:g} kg)")
    save(fig, path)


def plot_family(path, fam, E_s):
    """The family of solutions: k, c_alpha and E_s against alpha."""
    plt = pyplot()
    rows = [mb for mb in fam["members"] if mb["in_family"]]
    a = np.array([mb["alpha"] for mb in rows])
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.8))
    series_ = ((axes[0], [mb["k"] for mb in rows], "k [N/m^1.5]"),
               (axes[1], [mb["c_alpha"] for mb in rows], "c_alpha [N s^alpha/m]"),
               (axes[2], [np.nan if e is None else e / 1e9 for e in E_s], "E_s [GPa]"))
    for ax, values, label in series_:
        ax.semilogy(a, values, "o-", ms=4)
        if fam["alpha_min"] is not None:
            ax.axvline(fam["alpha_min"], color="grey", ls=":", label=f"alpha_min = {fam['alpha_min']:.3f}")
        ax.set(xlabel="springpot order alpha", ylabel=label)
        ax.grid(alpha=0.3, which="both")
    axes[0].legend(fontsize=8)
    fig.suptitle("One drop test, three parameters: every member reproduces F_max and eps")
    save(fig, path)


# ---------------------------------------------------------------------------------------------------------------
# Output.


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
    lines = [f"k      = {quantity('k', 'N/m^1.5')}"]
    if "c" in result:
        lines.append(f"c      = {quantity('c', 'N s/m')}")
    else:
        lines.append(f"c_alpha = {quantity('c_alpha', 'N s^alpha/m')}")
        lines.append(f"alpha  = {quantity('alpha', '')}" + ("   (fixed: --damper-order)" if result.get("alpha_fixed")
                                                            else "   (at its bound 1: the dashpot)"
                                                            if result.get("at_bound") else ""))
    if "t0" in result:
        lines.append(f"t0     = {quantity('t0', 's')}   (contact onset on the file's time axis)")
    lines.append(f"E_s    = {quantity('E_s', 'Pa')}")
    if "F_peak" in result:
        lines += [f"F_peak = {quantity('F_peak', 'N')}   (the model's, at the fitted values)",
                  f"eps    = {quantity('eps', '')}   (the model's, at the fitted values)"]
    second = "c" if "c" in result else "c_alpha"
    if "correlation" in result:
        lines.append(f"correlation of k and {second} = {result['correlation']:.3f}")
    if "correlations" in result:
        lines.append("correlations: " + ", ".join(f"{pair.replace(',', '-')} {value:.3f}"
                                                  for pair, value in result["correlations"].items()))
    if result.get("condition") is not None and (result.get("n_tests", 1) > 1 or "correlations" in result):
        lines.append(f"identifiable: {result['n_data']} data for {result['n_params']} parameters, condition number "
                     f"of the Jacobian {result['condition']:.3g}")
    if "rms_residual" in result:
        lines += [f"rms residual = {significant(result['rms_residual'], 3)} N",
                  f"lag-1 autocorrelation of the residuals = {result['residual_autocorrelation']:.3f}"]
    if "residual_scale" in result:
        lines.append(f"residual scale = {significant(result['residual_scale'], 3)} (relative F_max, absolute eps; "
                     f"{result['dof']} degrees of freedom)")
    if "chi2" in result:
        lines.append(f"chi-square = {significant(result['chi2'], 3)} for {result['dof']} degrees of freedom")
    if result.get("n_tests", 1) > 1 and "tests" in result:
        lines += test_table(result["tests"])
    lines.append(f"v = {result['v']:.6g} m/s, m = {result['m']:.6g} kg, law {result['law']}, damper "
                 f"{result.get('damper', 1)} ({DAMPERS[result.get('damper', 1)]})" if "v" in result else
                 f"m = {result['m']:.6g} kg, law {result['law']}, damper {result['damper']} "
                 f"({DAMPERS[result['damper']]})")
    return "\n".join(lines)


def test_table(tests):
    """The tests of a joint fit, one line each, measured beside the model's."""
    curves = "t0" in tests[0]
    if curves:
        head = ["height [m]", "v [m/s]", "t0 [s]", "rms [N]", "F_max [N]", "F_peak [N] (model)", "eps (model)"]
    else:
        head = ["height [m]", "v [m/s]", "F_max [N]", "F_peak [N] (model)", "eps", "eps (model)"]
    rows = []
    for t in tests:
        height = "-" if t.get("height") is None else f"{t['height']:.6g}"
        model_ = [with_error(t["F_peak"], t.get("sigma_F_peak"), ""), with_error(t["eps"], t.get("sigma_eps"), "")]
        if curves:
            rows.append([height, f"{t['v']:.6g}", with_error(t["t0"], t["sigma_t0"], ""),
                         significant(t["rms_residual"], 3), significant(t["F_max"], 6), *model_])
        else:
            rows.append([height, f"{t['v']:.6g}", with_error(t["F_max"], t.get("sigma_F_max"), ""), model_[0],
                         with_error(t["eps_measured"], t.get("sigma_eps_measured"), ""), model_[1]])
    widths = [max(len(r[j]) for r in rows + [head]) for j in range(len(head))]
    return ["  ".join(cell.rjust(w) for cell, w in zip(r, widths)) for r in [head] + rows]


def family_report(result):
    """The one-line verdict, then the family's table."""
    fam, one = result["family"], result["n_tests"] == 1
    lines = [f"not identifiable: {result['reason']}; " + (
        "for each alpha below, k and c_alpha reproduce F_max and eps (a one-parameter family):" if one else
        "for each alpha below, the best k and c_alpha; those marked * fit equally well (a one-parameter family):")]
    last = f"{'F_peak [N]':>11}  {'eps':>8}" if one else f"{'rms residual':>12}"
    lines.append(f"{'alpha':>5}  {'k [N/m^1.5]':>12}  {'c_alpha [N s^alpha/m]':>21}  {'E_s [Pa]':>9}  {last}")
    for mb, E_s in zip(fam["members"], result["E_s_family"]):
        if not mb["in_family"]:
            why = "needs k above the cap (a rigid spring)" if mb["k_capped"] else f"fits worse (rms {mb['rms']:.3g})"
            lines.append(f"{mb['alpha']:5.2f}  out of reach: {why}")
            continue
        figures_ = (f"{significant(mb['F_peak'][0], 6):>11}  {mb['eps'][0]:8.6f}" if one else
                    f"{significant(mb['rms'], 4):>12}")
        lines.append(f"{mb['alpha']:5.2f}{'' if one else '*'}  {significant(mb['k'], 6):>12}  "
                     f"{significant(mb['c_alpha'], 6):>21}  {'-' if E_s is None else significant(E_s, 4):>9}  {figures_}")
    if fam["alpha_min"] is not None and fam["alpha_min_bounded"]:
        lines.append(f"alpha_min = {fam['alpha_min']:.4f}: below it no k up to {fam['k_cap']:.3g} N/m^1.5 "
                     f"({K_CAP:g} x the elastic Hertz k of F_max: a rigid spring) {'reaches them' if one else 'fits as well'}")
    if any(E is None and mb["in_family"] for E, mb in zip(result["E_s_family"], fam["members"])):
        lines.append("E_s '-': k stiffer than the indenter alone allows (no specimen modulus gives it)")
    lines.append("--damper-order picks one member; several heights (--drops) or a force curve (--curve) identify alpha")
    lines.append(f"m = {result['m']:.6g} kg, law {result['law']}, damper 2 (springpot)")
    return "\n".join(lines)


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
    parser.add_argument("--damper", type=int, choices=tuple(DAMPERS), default=1,
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
        check = run(k, c, args.m, v, args.law)
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
    if args.json:
        print(json.dumps(result))
    else:
        print(family_report(result) if result.get("family") else text_report(result))
    return 0
