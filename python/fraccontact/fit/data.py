"""The measured data's files: a force curve (time [s], force [N]) and a
table of drop tests (height [m], F_max [N], eps [, sigma_F_max [N],
sigma_eps]), each read from CSV and refused, naming the row and column,
where this model cannot be fitted to it."""

import csv
import math

import numpy as np

from .. import model
from .drops import Drops

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
MAX_HEIGHT = 10.0       # a drop height above 10 m in a table is taken for millimetres


class BadInput(Exception):
    """An input this tool cannot use; the message says what is wrong and where."""


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
