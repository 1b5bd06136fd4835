"""The least squares of every fit: scipy's least_squares with a
forward-difference Jacobian, whether that Jacobian can determine the
parameters, and the fitted values with their standard errors."""

import math

import numpy as np
from scipy.optimize import least_squares

# Finite-difference step of the Jacobian in ln k, ln c, alpha and t0 / t_c, each an O(1) quantity: where a
# forward difference's truncation error (about the step) meets the figures' own roughness over the step.
STEP = 1e-5
# Singular values of the Jacobian (columns: ln k, ln c, alpha, t0 / t_c) below 1e-3 of the largest are not
# told from zero: the forward differences carry relative errors of about STEP, and the data set is then as
# good as rank-deficient (a parameter's standard error 1000 times the best one's).
RANK_TOLERANCE = 1e-3
POOR = 0.5              # a relative standard error above 50 % (alpha: above 0.5) is called poorly determined


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
