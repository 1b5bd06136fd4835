"""Crash figures of an acceleration record, computed by the crashmetrics
package (PyPI): the SAE J211 CFC 1000 filter first, then HIC15 and HIC36
with the window where they occur, the 3 ms clip and the peak, in g.

Time in s, acceleration in m/s^2 along one axis; g is crashmetrics' standard
gravity (9.80665 m/s^2). J211 filters each axis, then takes the resultant: for
one axis the resultant is the filtered signal's magnitude, so the sign of the
record does not matter and the filter's small undershoot after a steep edge
counts as acceleration too.

    from fraccontact import crash
    f = crash.figures(t, a)      # f["HIC15"], f["HIC15_window"], f["peak_g"], f["clip3ms_g"], ...
"""

import math

import numpy as np
from crashmetrics.acceleration import clip_3ms
from crashmetrics.pedestrian import calculate_hic
from crashmetrics.signals import STANDARD_GRAVITY, cfc_filter

CFC = 1000.0          # the channel class J211 and the pedestrian protocols prescribe for head acceleration
WINDOWS = {"HIC15": 0.015, "HIC36": 0.036}
# Uniform sampling, as J211's recursive filter assumes: steps within this
# fraction of their mean.
UNIFORM = 1e-6
# The finest grid HIC's windows are searched on [s]: 100 kHz, ten times the
# 10 kHz (ten times F_H) J211 asks of a CFC 1000 channel. crashmetrics'
# search grows as the samples times the window's samples: a finer record,
# once filtered, is interpolated onto this grid, so that its cost is bounded
# (tests/test_crash_metrics.py measures what the grid changes).
HIC_STEP = 1e-5


def record(t, a):
    """t and a as float arrays, checked: one-dimensional, the same length (at
    least 3), finite, t strictly increasing. ValueError names what is wrong."""
    t, a = np.asarray(t, dtype=float), np.asarray(a, dtype=float)
    if t.ndim != 1 or a.ndim != 1 or len(t) != len(a) or len(t) < 3:
        raise ValueError(f"t and a must be one-dimensional of one length >= 3: shapes {t.shape} and {a.shape}")
    for name, x in (("t", t), ("a", a)):
        if not np.all(np.isfinite(x)):
            raise ValueError(f"{name}[{int(np.argmin(np.isfinite(x)))}] is not finite: every sample must be")
    steps = np.diff(t)
    if not np.all(steps > 0):
        i = int(np.argmin(steps > 0))
        raise ValueError(f"t[{i + 1}] = {t[i + 1]:g} s is not after t[{i}] = {t[i]:g} s: t must increase")
    return t, a


def filtered(t, a):
    """a through the J211 CFC 1000 filter (crashmetrics.signals.cfc_filter).
    t must be uniform and sampled above 10 kHz."""
    t, a = record(t, a)
    step = (t[-1] - t[0]) / (len(t) - 1)
    if np.max(np.abs(np.diff(t) - step)) > UNIFORM * step:
        raise ValueError("t is not uniform: the CFC filter needs samples at a constant step (resample first)")
    if 1.0 / step < 10.0 * CFC:
        raise ValueError(f"the sample rate {1.0 / step:g} Hz is too low for CFC {CFC:g}: it must be >= {10 * CFC:g} Hz")
    return cfc_filter(t, a, CFC)


def in_g(a):
    """|a| [m/s^2] in g."""
    return np.abs(np.asarray(a, dtype=float)) / STANDARD_GRAVITY


def hic(t, a_g, window):
    """(HIC, t1, t2): the largest (t2 - t1) (mean of a_g over [t1, t2])^2.5
    over windows no longer than window [s], a_g in g, zero outside the
    record (crashmetrics.pedestrian.calculate_hic on the record, which
    searches every sample as a window end)."""
    t, a_g = record(t, a_g)
    if not (math.isfinite(window) and window > 0):
        raise ValueError(f"window = {window} is invalid: it must be a positive duration [s]")
    if np.any(a_g < 0):
        raise ValueError(f"a_g has negative samples (the least {a_g.min():g}): HIC takes a magnitude")
    if t[-1] - t[0] < window:
        # Zero after the record: a step down just after its end, then zero up
        # to a full window, so that crashmetrics searches the whole window.
        t = np.append(t, [t[-1] + 1e-9 * window, t[0] + window])
        a_g = np.append(a_g, [0.0, 0.0])
    r = calculate_hic(t, a_g, window_ms=1e3 * window)
    return r.value, r.start_time, r.end_time


def on_hic_grid(t, a_g):
    """(t, a_g) on a uniform grid of steps no shorter than HIC_STEP from
    t[0] to t[-1] (a_g linearly interpolated), or as they are where the
    record is sampled no finer."""
    steps = int(math.ceil((t[-1] - t[0]) / HIC_STEP))
    if len(t) <= steps + 1:
        return t, a_g
    grid = np.linspace(t[0], t[-1], steps + 1)
    return grid, np.interp(grid, t, a_g)


def figures(t, a, cfc=True):
    """The crash figures of one axis's acceleration a [m/s^2] sampled at t
    [s]: HIC15, HIC36 and their windows (t1, t2), searched on_hic_grid; the
    peak in g and its time, the 3 ms clip in g (cumulative: the level
    exceeded for 3 ms in all), on every sample.
    cfc: through the CFC 1000 filter first (J211), as the protocols require."""
    t, a = record(t, a)
    a_g = in_g(filtered(t, a) if cfc else a)
    out = {}
    for name, window in WINDOWS.items():
        value, t1, t2 = hic(*on_hic_grid(t, a_g), window)
        out[name], out[name + "_window"] = value, (t1, t2)
    i = int(np.argmax(a_g))
    out["peak_g"], out["t_peak"] = float(a_g[i]), float(t[i])
    out["clip3ms_g"] = clip_3ms(t, a_g, duration_ms=3.0) if t[-1] - t[0] >= 3e-3 else float("nan")
    return out


def stopping_distance(HIC, v, window=WINDOWS["HIC15"]):
    """The stopping distance [m] of a constant deceleration (a square pulse)
    from v [m/s] whose HIC over window [s] is HIC: the square pulse of
    level a [g] and length T = v/(a g) has HIC = min(T, window) a^2.5, so
    a = (HIC g / v)^(2/3) while T <= window, else a = (HIC/window)^(2/5); and
    d = v^2 / (2 a g)."""
    if not (HIC > 0 and v > 0 and window > 0):
        raise ValueError(f"HIC = {HIC}, v = {v}, window = {window}: all must be > 0")
    a = (HIC * STANDARD_GRAVITY / v) ** (2.0 / 3.0)
    if v / (a * STANDARD_GRAVITY) > window:
        a = (HIC / window) ** 0.4
    return v * v / (2.0 * a * STANDARD_GRAVITY)


def least_stopping_distance(HIC, v, window=WINDOWS["HIC15"]):
    """The shortest distance [m] in which any pulse whose HIC over window is
    HIC stops from v [m/s]: three quarters of the square pulse's. HIC over
    [0, t] caps the speed lost by t at (HIC t^1.5)^0.4 g, and the pulse
    a = 0.6 HIC^0.4 t^-0.4 [g] loses exactly that at every t, with HIC no
    more than HIC over any other window (t^0.6 is subadditive): it stops
    after the square pulse's T = (v/g)^(5/3) HIC^(-2/3), having travelled
    3/8 v T against the square pulse's v T/2. ValueError when T > window
    (the bound then needs the windows that do not start at 0)."""
    duration = (v / STANDARD_GRAVITY) ** (5.0 / 3.0) * HIC ** (-2.0 / 3.0) if HIC > 0 and v > 0 else -1.0
    if not 0 < duration <= window:
        raise ValueError(f"HIC = {HIC}, v = {v}: the pulse would last {duration:g} s, beyond window = {window} s "
                         "(or HIC, v are not > 0)")
    return 0.375 * v * duration
