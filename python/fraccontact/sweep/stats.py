"""Statistics of a Monte Carlo campaign, reduced inside the tasks: each task
summarises every numeric column of its partition, over the impacts that
succeeded and where the figure exists (an impact that did not end by t_end
has no eps), and the summaries merge on the workers, so that the client
receives one small summary and reads no partition:

- the count, mean and sum of squared deviations of each task, merged in
  the tasks' order by Chan, Golub and LeVeque's pairwise update: the mean
  and the sample standard deviation, the same bits whatever the workers
  and the order their summaries merge in; the smallest and the largest;
- a histogram on dyadic bins of the doubles' order-preserving 64-bit keys:
  bin b at shift s holds the keys b 2^s to (b + 1) 2^s - 1, so that two
  histograms merge exactly (the finer one's bins summed into the
  coarser's), the shift the smallest that keeps a column's bins at most
  2^BITS. Keys grow with the exponent and then the mantissa: the bins are
  uniform within a binade and logarithmic across binades, so that a column
  spanning decades costs little resolution.

The 5, 50 and 95 % percentiles are numpy's linear interpolation between two
order statistics, each found in its bin by the counts and placed inside it
by its rank, as though the bin's values were evenly spread. Each order
statistic lies in its bin, clipped to the column's smallest and largest
(and, for an integer column, to the integers inside): a percentile is
within `bound` of numpy's, the widths of the bins it interpolates between,
weighted as it weighs them; sweep.json gives that bound for each column.
A bin that holds one value (a constant column, an integer column's
integers) gives it exactly. The plot's histograms group the same bins."""

from dataclasses import dataclass

import numpy as np

QUANTILES = (0.05, 0.5, 0.95)
BITS = 15
SIGN = np.uint64(1 << 63)


def key(x, out=None):
    """Each double's key: unsigned integers in the doubles' order (the
    sign bit set for the positive, every bit flipped for the negative);
    written into out when given."""
    bits = np.ascontiguousarray(x, dtype=np.float64).view(np.uint64)
    k = np.bitwise_or(bits, SIGN, out=out)
    negative = np.signbit(x)
    if negative.any():
        k[negative] = ~bits[negative]
    return k


def doubles(k):
    """The doubles of keys."""
    k = np.asarray(k, dtype=np.uint64)
    return np.where(k >> np.uint64(63) == 1, k & ~SIGN, ~k).view(np.float64)


def fitting_shift(low, high, shift=0):
    """The smallest shift >= shift at which the keys low to high fall in at
    most 2^BITS bins."""
    shift = max(shift, (high - low).bit_length() - BITS)
    while (high >> shift) - (low >> shift) >= 1 << BITS:
        shift += 1
    return shift


@dataclass
class Summary:
    """A column's summary: {task: (count, mean, sum of squared deviations)},
    the smallest and largest value, the histogram (its shift, its first bin,
    the counts by bin), whether the column holds integers."""
    moments: dict
    smallest: float
    largest: float
    shift: int
    first: int
    counts: np.ndarray
    integer: bool


def summary(x, integer, task, scratch):
    """The Summary of a task's values x of a column (doubles, finite),
    its temporaries computed in scratch (doubles, at least as many)."""
    mean = x.mean()
    deviations = np.subtract(x, mean, out=scratch[:len(x)])
    squares = float(np.square(deviations, out=deviations).sum())
    k = key(x, out=deviations.view(np.uint64))
    low, high = int(k.min()), int(k.max())
    shift = fitting_shift(low, high)
    first = low >> shift
    bins = np.subtract(np.right_shift(k, np.uint64(shift), out=k), np.uint64(first), out=k)
    return Summary({task: (len(x), float(mean), squares)}, float(x.min()), float(x.max()), shift, first,
                   np.bincount(bins.view(np.int64)), integer)  # the bins are below 2^BITS: as signed, the same


def reduced(columns, failed, task=0):
    """{column: Summary} of the numeric columns ({name: array}) of task
    `task` over the cases not failed (indices), where they have values (not
    NaN, not infinite)."""
    n = len(next(iter(columns.values())))
    ok = None
    if len(failed):
        ok = np.ones(n, dtype=bool)
        ok[failed] = False
    # One array for every column's temporaries: a fresh array for each
    # would come in fresh pages from the system, each page a fault.
    scratch = np.empty(n)
    out = {}
    for name, x in columns.items():
        if x.dtype.kind not in "fi":
            continue
        integer = x.dtype.kind == "i"
        x = np.ascontiguousarray(x, dtype=np.float64)
        if ok is not None:
            x = x[ok]
        if len(x) and not (np.isfinite(x.min()) and np.isfinite(x.max())):  # NaN or an infinity among them
            x = x[np.isfinite(x)]
        if len(x):
            out[name] = summary(x, integer, task, scratch)
    return out


def merged(*summaries):
    """The summaries ({column: Summary}) of several tasks as one."""
    out = {}
    for summary_ in summaries:
        for name, s in summary_.items():
            out[name] = both(out[name], s) if name in out else s
    return out


def both(a, b):
    low = min(a.first << a.shift, b.first << b.shift)
    high = max(((a.first + len(a.counts)) << a.shift) - 1, ((b.first + len(b.counts)) << b.shift) - 1)
    shift = fitting_shift(low, high, max(a.shift, b.shift))
    first = low >> shift
    counts = np.zeros((high >> shift) - first + 1, dtype=np.int64)
    for s in (a, b):
        bins = ((np.uint64(s.first) + np.arange(len(s.counts), dtype=np.uint64)) >> np.uint64(shift - s.shift)) \
            - np.uint64(first)
        counts += np.bincount(bins.astype(np.intp), weights=s.counts, minlength=len(counts)).astype(np.int64)
    return Summary({**a.moments, **b.moments}, min(a.smallest, b.smallest), max(a.largest, b.largest), shift, first,
                   counts, a.integer)  # the bincount's doubles hold the counts exactly (below 2^53)


def moments(s):
    """(count, mean, sum of squared deviations) of all the tasks, merged in
    their order."""
    tasks = sorted(s.moments)
    n, mean, squares = s.moments[tasks[0]]
    for task in tasks[1:]:
        nb, mb, sb = s.moments[task]
        total = n + nb
        delta = mb - mean
        n, mean, squares = total, mean + delta * nb / total, squares + sb + delta * delta * n * nb / total
    return n, mean, squares


def ranks(n, q):
    """The order statistics numpy's linear percentile q interpolates
    between, and its weight: (previous, next, gamma)."""
    virtual = (n - 1) * q
    previous = int(np.floor(virtual))
    if virtual >= n - 1:
        return n - 1, n - 1, virtual - previous
    return previous, previous + 1, virtual - previous


def lerp(a, b, t):
    """numpy's interpolation for percentiles, exact at both ends."""
    return b - (b - a) * (1 - t) if t >= 0.5 else a + (b - a) * t


def edges(s, b):
    """(low, high): the values bins b (an array) of a Summary can hold, their
    keys clipped to the column's smallest and largest, and to the integers
    inside for an integer column."""
    b = np.asarray(b, dtype=np.uint64) + np.uint64(s.first)
    ends = key(np.array([s.smallest, s.largest]))
    low = doubles(np.maximum(b << np.uint64(s.shift), ends[0]))
    high = doubles(np.minimum(((b + np.uint64(1)) << np.uint64(s.shift)) - np.uint64(1), ends[1]))
    if s.integer:
        return np.ceil(low), np.floor(high)
    return low, high


def order_statistic(s, cumulative, rank):
    """The value of rank `rank` (0 the smallest), placed in its bin, and
    the bin's width."""
    b = int(np.searchsorted(cumulative, rank, side="right"))
    below = int(cumulative[b - 1]) if b else 0
    low, high = (float(x[0]) for x in edges(s, [b]))
    position = (rank - below + 0.5) / s.counts[b]
    return (low + (high - low) * position if high > low else low), high - low


def statistics_of(s):
    """dict(mean, std (None for one value), p5, p50, p95, bound) of a
    Summary."""
    n, mean, squares = moments(s)
    out = dict(mean=mean, std=float(np.sqrt(squares / (n - 1))) if n > 1 else None)
    cumulative = np.cumsum(s.counts)
    bound = 0.0
    for q in QUANTILES:
        previous, following, gamma = ranks(n, q)
        (a, width_a), (b, width_b) = order_statistic(s, cumulative, previous), order_statistic(s, cumulative, following)
        out[f"p{round(100 * q)}"] = float(lerp(a, b, gamma))
        bound = max(bound, (1 - gamma) * width_a + gamma * width_b)
    out["bound"] = float(bound)
    return out


def statistics(summaries):
    """{column: statistics_of()} of the merged summaries."""
    return {name: statistics_of(s) for name, s in summaries.items()}


def histogram(s, bins):
    """(counts, low, high): a Summary's values in `bins` equal bins over
    [smallest, largest], each of its own bins counted in the one holding
    its middle (a bin's values cross an edge by at most its width)."""
    low, high = edges(s, np.flatnonzero(s.counts))
    width = (s.largest - s.smallest) / bins
    which = ((low + high) / 2 - s.smallest) / width if width > 0 else np.zeros(len(low))
    which = np.clip(which.astype(np.int64), 0, bins - 1)
    return np.bincount(which, weights=s.counts[s.counts > 0], minlength=bins).astype(np.int64), s.smallest, \
        s.largest
