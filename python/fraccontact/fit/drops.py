"""Drop tests, F_max and eps at one or more heights, fitted at once; and,
where they cannot determine the springpot's three parameters, the family of
solutions over its order alpha."""

import dataclasses
import math

import numpy as np

from . import runs
from .least_squares import STEP, identifiability, least_squares_fit, reported
from .peak import Unreachable, fit_peak_and_restitution

K_CAP = 1e5             # k at most this many times the elastic Hertz k of the peak force: beyond it the spring is rigid
FAMILY_ALPHAS = tuple(round(0.05 * i, 2) for i in range(20, 0, -1))  # 1.00, 0.95, ..., 0.05
START_ALPHAS = (1.0, 0.8, 0.6, 0.4, 0.2)   # candidate orders a free-order fit starts from (the best of them)
CONTINUATION = 0.1      # a family member is solved from its neighbour at most 0.1 away in alpha
REPRODUCE = 1e-8        # a family member reproduces F_peak (relative) and eps (absolute) to this
ALPHA_MIN_BISECTIONS = 10   # the family's lowest order to 0.05 / 2^10 = 5e-5


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
        F, eps = runs.figures(fitted, X, drops.v)
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
    F, eps = runs.figures(fitted, [x], drops.v)
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
    base = runs.make_model(m, law, damper, alpha, k0, c0, drops.v)
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


def figure_gradients(fitted, x, v):
    """d F_peak / dx and d eps / dx at each impact velocity of v, by forward
    differences of step STEP: two arrays (len(x), len(v)), for the standard
    errors of the model's figures at the fitted values."""
    X = [x] + [x + STEP * e for e in np.eye(len(x))]
    Fs, Es = runs.figures(fitted, X, v)
    return (Fs[1:] - Fs[0]) / STEP, (Es[1:] - Es[0]) / STEP


def test_rows(fitted, drops, x, cov_x):
    """Per test: height, v, measured F_max and eps (and sigmas), the model's
    (with standard errors from cov_x)."""
    F, eps = runs.figures(fitted, [x], drops.v)
    rows = []
    sF = sE = None
    if cov_x is not None:
        GF, GE = figure_gradients(fitted, x, drops.v)
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
