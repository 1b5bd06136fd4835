"""Statistics of a Monte Carlo campaign, computed on the workers over its
Parquet partitions, over the impacts that succeeded and where the figure
exists (an impact that did not end by t_end has no eps):

- the mean and the sample standard deviation, merged from each partition's
  count, mean and sum of squared deviations (Chan, Golub and LeVeque's
  pairwise update), which each task computes from its own results;
- the 5, 50 and 95 % percentiles exact, as numpy's linear interpolation
  gives them over all the values: the order statistics they need are found
  by passes over the partitions, each counting the values in 2^BITS bins of
  the range still open, with each bin's smallest and largest (the bins
  taken on the doubles' order-preserving 64-bit keys, so that a pass
  narrows any range, however many decades it spans, by 2^BITS at least),
  until the bin holding the rank holds one value, or at most GATHER, which
  are then gathered and the rank selected among them;
- the histograms of the plotted results, on the first of those passes.

The client holds only the counts of the bins and the values selected."""

import numpy as np
import pyarrow.parquet as pq

QUANTILES = (0.05, 0.5, 0.95)
BITS = 12
GATHER = 1 << 16
SIGN = np.uint64(1 << 63)
NO_KEY = np.uint64((1 << 64) - 1)
# A pass narrows a range of 2^64 keys by 2^BITS: 6 passes reach one key.
PASSES = -(-64 // BITS) + 1


def numeric(table):
    """The numeric columns of a partition (not the words, not error)."""
    return [f.name for f in table.schema if f.type in ("double", "int64")]


def values(table, name, ok):
    """A column's finite values of the impacts that succeeded (ok: None
    for all), as doubles; copied only where some are left out."""
    x = table.column(name).to_numpy()
    if ok is not None:
        x = x[ok]
    x = x.astype(np.float64, copy=False)
    if len(x) and not (np.isfinite(x.min()) and np.isfinite(x.max())):  # NaN or an infinity among them
        x = x[np.isfinite(x)]
    return x


def succeeded(table):
    """Which impacts succeeded, or None for all."""
    error = table.column("error")
    return None if error.null_count == len(error) else error.is_null().to_numpy(zero_copy_only=False)


def moments(columns, failed):
    """{column: (count, mean, sum of squared deviations, min, max)} of the
    numeric columns ({name: array}) over the cases not failed (indices),
    where they have values."""
    ok = np.ones(len(next(iter(columns.values()))), dtype=bool)
    ok[failed] = False
    out = {}
    for name, x in columns.items():
        if x.dtype.kind not in "fi":
            continue
        x = x.astype(np.float64, copy=False)
        if len(failed):
            x = x[ok]
        if len(x) and not (np.isfinite(x.min()) and np.isfinite(x.max())):  # NaN or an infinity among them
            x = x[np.isfinite(x)]
        if len(x):
            mean = x.mean()
            deviations = x - mean
            out[name] = (len(x), mean, float(np.square(deviations, out=deviations).sum()), float(x.min()),
                         float(x.max()))
    return out


def merged_moments(a, b):
    """The moments of two sets of values from theirs (Chan et al.)."""
    out = dict(a)
    for name, (nb, mb, sb, lob, hib) in b.items():
        if name not in out:
            out[name] = (nb, mb, sb, lob, hib)
            continue
        na, ma, sa, loa, hia = out[name]
        n = na + nb
        delta = mb - ma
        out[name] = (n, ma + delta * nb / n, sa + sb + delta * delta * na * nb / n, min(loa, lob), max(hia, hib))
    return out


def key(x):
    """Each double's key: unsigned integers in the doubles' order (the
    sign bit set for the positive, every bit flipped for the negative)."""
    bits = np.ascontiguousarray(x, dtype=np.float64).view(np.uint64)
    if len(bits) and not np.signbit(x).any():
        return bits | SIGN
    return np.where(bits >> np.uint64(63) == 1, ~bits, bits | SIGN)


def double(k):
    """The double of a key."""
    k = np.uint64(k)
    return float(np.array(k & ~SIGN if k >> np.uint64(63) == 1 else ~k, dtype=np.uint64).view(np.float64))


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


def shift(low, high):
    """The bin of key k in [low, high] is (k - low) >> shift: at most 2^BITS bins."""
    return max(0, (high - low).bit_length() - BITS)


def partition_pass(path, requests):
    """One partition's part of a pass: for each request ("bins", column,
    low, high) the count, the smallest and the largest of its keys in [low,
    high] by bin, ("gather", column, low, high, picks) those keys, ("hist",
    column, low, high, bins) numpy's histogram of its values."""
    table = pq.read_table(path, columns=sorted({r[1] for r in requests}) + ["error"])
    ok = succeeded(table)
    columns = {}
    out = []
    for kind, name, low, high, *rest in requests:
        if name not in columns:
            x = values(table, name, ok)
            columns[name] = (x, key(x))
        x, k = columns[name]
        if kind == "hist":
            out.append(np.histogram(x, bins=rest[0], range=(low, high))[0])
            continue
        inside = k[(k >= np.uint64(low)) & (k <= np.uint64(high))]
        if kind == "gather":
            out.append(inside)
        else:
            out.append(binned(inside, low, high))
    return out


def binned(k, low, high):
    """(count, smallest, largest) of the keys k by bin of [low, high]; an
    empty bin's smallest is the largest key and its largest 0."""
    bins = ((k - np.uint64(low)) >> np.uint64(shift(low, high))).astype(np.int64)
    size = ((high - low) >> shift(low, high)) + 1
    smallest, largest = np.full(size, NO_KEY, dtype=np.uint64), np.zeros(size, dtype=np.uint64)
    np.minimum.at(smallest, bins, k)
    np.maximum.at(largest, bins, k)
    return np.bincount(bins, minlength=size), smallest, largest


def combined(*parts):
    """Passes over several partitions as one: counts added, keys joined,
    the smallest and largest of each bin kept."""
    return [joined(xs) for xs in zip(*parts)]


def joined(xs):
    if isinstance(xs[0], tuple):
        counts, smallest, largest = zip(*xs)
        return np.sum(counts, axis=0), np.minimum.reduce(smallest), np.maximum.reduce(largest)
    return np.concatenate(xs) if xs[0].dtype == np.uint64 else np.sum(xs, axis=0)


def finished(result, requests):
    """A pass's result as the client needs it: the counts, and for a
    gather the keys of the ranks it picks (selected here, on a worker)."""
    return [np.partition(x, r[4])[list(r[4])] if r[0] == "gather" else x for x, r in zip(result, requests)]


def summaries(moments, run_pass, histograms=()):
    """{column: dict(mean, std, p5, p50, p95)} (std None for one value) from
    the merged moments, and {column: (counts, low, high)} of the
    histograms asked for ((column, bins), ...); run_pass(requests) returns
    finished() of a pass over all partitions."""
    # Each wanted order statistic: its open key range [low, high], the values below it, and the values inside.
    wanted = {}
    for name, (n, *_, low, high) in moments.items():
        for q in QUANTILES:
            for rank in ranks(n, q)[:2]:
                wanted[(name, rank)] = [int(key(np.array([low]))[0]), int(key(np.array([high]))[0]), 0, n]
    found = {}
    extra = [("hist", name, moments[name][3], moments[name][4], bins) for name, bins in histograms if name in moments]
    plotted = {}
    for _ in range(PASSES + 1):  # each pass narrows a range by 2^BITS: the last leaves one key
        for target, (low, high, below, count) in wanted.items():
            if low == high:
                found.setdefault(target, double(low))
        open_ = {t: s for t, s in wanted.items() if t not in found}
        if not open_ and not extra:
            break
        requests, picks = request_pass(open_)
        results = run_pass(requests + extra)
        for r, counts in zip(extra, results[len(requests):]):
            plotted[r[1]] = (counts, r[2], r[3])
        extra = []
        settle(wanted, found, requests, picks, results)
    return {name: statistics_of(name, moments[name], found) for name in moments}, plotted


def request_pass(open_):
    """The requests of the next pass: a gather where few values remain in
    the range, else its bins; picks maps each target to its request and,
    for a gather, its position in the pick list."""
    requests, index, picks = [], {}, {}
    for target, (low, high, below, count) in open_.items():
        kind = "gather" if count <= GATHER else "bins"
        where = (kind, target[0], low, high)
        if where not in index:
            index[where] = len(requests)
            requests.append([kind, target[0], low, high, []])
        r = requests[index[where]]
        if kind == "gather":
            picks[target] = (index[where], len(r[4]))
            r[4].append(target[1] - below)
        else:
            picks[target] = (index[where], None)
    return [tuple(r[:4]) if r[0] == "bins" else (r[0], r[1], r[2], r[3], tuple(r[4])) for r in requests], picks


def settle(wanted, found, requests, picks, results):
    """Each target after a pass: its value where gathered, else its range
    narrowed to the keys in the bin holding its rank (one key: found)."""
    for target, (i, pick) in picks.items():
        if requests[i][0] == "gather":
            found[target] = double(results[i][pick])
            continue
        counts, smallest, largest = results[i]
        below = wanted[target][2]
        cumulative = np.cumsum(counts)
        b = int(np.searchsorted(cumulative, target[1] - below, side="right"))
        wanted[target] = [int(smallest[b]), int(largest[b]), below + (int(cumulative[b - 1]) if b else 0),
                          int(counts[b])]


def statistics_of(name, m, found):
    n, mean, squares, _, _ = m
    out = dict(mean=float(mean), std=float(np.sqrt(squares / (n - 1))) if n > 1 else None)
    for q in QUANTILES:
        previous, following, gamma = ranks(n, q)
        out[f"p{round(100 * q)}"] = lerp(found[(name, previous)], found[(name, following)], gamma)
    return out
