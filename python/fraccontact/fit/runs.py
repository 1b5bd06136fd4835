"""The model as the fit runs it, in-process on the package's C library
(fraccontact.impact, fraccontact.impacts, fraccontact.simulate): one impact
or force curve at given k and c, and the parameters of a fit (Model) with
the one step every parameter set of that fit is run on. Every model run of
the fit goes through this module's run, force_series, figures and series."""

import dataclasses
import math

import numpy as np

from .. import hertz, model

STEPS_PER_CONTACT = 4000   # the model's internal step (dashpot): the Hertz contact time / 4000
ROWS_PER_CONTACT = 2000    # the model's force curve: a row every contact time / 2000, interpolated linearly
# The springpot's step (compressed memory): the Hertz contact time / 1000. Its figures' distance to dt -> 0
# (docs/calibration.md, "Accuracy of the members") lies far below any drop test's scatter.
SPRINGPOT_STEPS_PER_CONTACT = 1000
CONTACTS_PER_RUN = 50   # a run of the fit stops after 50 Hertz contact times; an impact still going counts eps = 0
ALPHA_LOWEST = 0.01     # the fitted order's lower bound (alpha -> 0 is a spring: nothing dissipated)
DAMPERS = {1: "dashpot", 2: "springpot"}


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
