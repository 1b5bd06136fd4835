"""Force curves, one or more, fitted at once: k, the damper and each
curve's contact onset t0 by least squares on the whole curve, each curve
weighed by its own noise."""

import dataclasses
import math

import numpy as np

from .. import hertz
from . import runs
from .drops import K_CAP, Drops, dashpot_start, figure_gradients, start_point
from .least_squares import identifiability, least_squares_fit, reported
from .peak import Unreachable

WHITENESS_SIGMAS = 3    # lag-1 autocorrelation of white residuals is about N(0, 1/n)


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
            cache[key] = [runs.series(fitted, x[:p], c.v, tc / runs.ROWS_PER_CONTACT) for c, tc in zip(curves, t_c)]
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
        tm, Fm = runs.series(fitted, x, c.v, tc / runs.ROWS_PER_CONTACT)
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
    base = runs.make_model(m, law, damper, alpha, k0, c0, drops.v)
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
    F, eps = runs.figures(base, [result.x[:p]], drops.v)
    GF, GE = figure_gradients(base, result.x[:p], drops.v)
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
