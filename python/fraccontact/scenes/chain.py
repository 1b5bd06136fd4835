"""Rigid bodies on one axis, joined by linear spring-dampers and by contacts
with the contact element's law, solved as one ODE by scipy's solve_ivp with
an event at every contact's onset and separation: the monolithic reference
of the scenes.

The contact law is docs/model.md §2 for two moving bodies: body i strikes body j
(or the fixed ground) once the gap between them has closed; the indentation
x = u_i - u_j - gap splits into the spring's x1 and the dashpot's x2,

    F = k x1^n (x1 > 0, else 0),    c x2' = F,    x = x1 + x2,

F pushes i back and j on. Contact ends when F returns to zero (x1 back to 0
while unloading); x2 stays (the permanent dent) and contact begins again
where x meets it. c = inf is the elastic spring alone.

Positions u count along the impact from where each body starts; the ODE also
carries the energy the dampers and dashpots have dissipated and the impulse
the ground has given, so that each run's energy and momentum balances can be
checked (Solution.balances).
"""

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from .. import hertz

GROUND = -1
MAX_EVENTS = 1000


@dataclass(frozen=True)
class Link:
    """A linear spring k [N/m] and damper c [N s/m] in parallel between
    body i and body j (GROUND: the fixed world), unstretched at the start."""
    i: int
    j: int
    k: float
    c: float


@dataclass(frozen=True)
class Contact:
    """The contact element between body i (striking) and body j (GROUND: a
    rigid fixed surface): k [N/m^n], c [N s/m] (inf: no dashpot), n, and
    the gap [m] between them at the start."""
    i: int
    j: int
    k: float
    c: float
    n: float = 1.5
    gap: float = 0.0


def contact_force(contact, x1):
    """k x1^n where x1 > 0, else 0 (x1 may be an array)."""
    return contact.k * np.maximum(x1, 0.0) ** contact.n


class Chain:
    """Bodies of masses m [kg] starting at velocities v0 [m/s], joined by
    links and contacts."""

    def __init__(self, m, v0, links=(), contacts=()):
        self.m, self.v0 = np.asarray(m, dtype=float), np.asarray(v0, dtype=float)
        self.links, self.contacts = tuple(links), tuple(contacts)
        nb = len(self.m)
        if self.v0.shape != (nb,) or not np.all(self.m > 0):
            raise ValueError(f"m = {m} and v0 = {v0}: one velocity per body, every mass > 0")
        for part in self.links + self.contacts:
            if not (0 <= part.i < nb and (part.j == GROUND or 0 <= part.j < nb) and part.i != part.j):
                raise ValueError(f"{part} joins bodies that do not exist: bodies are 0..{nb - 1} and GROUND")
        for c in self.contacts:
            if not (c.k > 0 and c.c > 0 and c.n >= 1 and c.gap >= 0):
                raise ValueError(f"{c}: k and c must be > 0, n >= 1 and gap >= 0")
        nc = len(self.contacts)
        # State: u, v (per body), x2 (per contact), energy dissipated in the
        # links, energy dissipated in each contact's dashpot, the ground's impulse.
        self.U, self.V = slice(0, nb), slice(nb, 2 * nb)
        self.X2 = slice(2 * nb, 2 * nb + nc)
        self.E_LINKS = 2 * nb + nc
        self.E_CONTACTS = slice(2 * nb + nc + 1, 2 * nb + 2 * nc + 1)
        self.IMPULSE = 2 * nb + 2 * nc + 1
        self.size = self.IMPULSE + 1

    def relative(self, y, part):
        """(u_i - u_j, v_i - v_j) of a link or contact."""
        u, v = y[self.U], y[self.V]
        if part.j == GROUND:
            return u[part.i], v[part.i]
        return u[part.i] - u[part.j], v[part.i] - v[part.j]

    def x1(self, y, index):
        contact = self.contacts[index]
        return self.relative(y, contact)[0] - contact.gap - y[self.X2][index]

    def rhs(self, t, y):
        dy = np.zeros(self.size)
        force = np.zeros(len(self.m))
        pairs = []
        for link in self.links:
            du, dv = self.relative(y, link)
            pairs.append((link, link.k * du + link.c * dv))
            dy[self.E_LINKS] += link.c * dv * dv
        for index, contact in enumerate(self.contacts):
            F = contact_force(contact, self.x1(y, index))
            pairs.append((contact, F))
            if math.isfinite(contact.c):
                dy[self.X2][index] = F / contact.c
                dy[self.E_CONTACTS][index] = F * F / contact.c
        for part, F in pairs:
            force[part.i] -= F
            if part.j == GROUND:
                dy[self.IMPULSE] -= F
            else:
                force[part.j] += F
        dy[self.U] = y[self.V]
        dy[self.V] = force / self.m
        return dy

    def initial(self):
        y = np.zeros(self.size)
        y[self.V] = self.v0
        return y

    def touching(self, y):
        """Per contact: in contact (x1 > 0, or x1 = 0 and closing)."""
        return [self.x1(y, i) > 0 or (self.x1(y, i) == 0 and self.relative(y, c)[1] > 0)
                for i, c in enumerate(self.contacts)]

    def solve(self, t_end, length, rtol=1e-11, max_step=np.inf, method="DOP853"):
        """Integrate from 0 to t_end [s]; length [m] is the scale of the
        motions (atol of the positions = rtol * length). Returns a Solution."""
        y, t = self.initial(), 0.0
        scale = np.zeros(self.size)
        v_scale = max(np.max(np.abs(self.v0)), 1e-300)
        energy = max(0.5 * np.sum(self.m * self.v0 ** 2), 1e-300)
        scale[self.U], scale[self.V], scale[self.X2] = length, v_scale, length
        scale[self.E_LINKS], scale[self.E_CONTACTS] = energy, energy
        scale[self.IMPULSE] = np.sum(self.m) * v_scale
        touching = self.touching(y)
        segments, events = [], []
        while t < t_end:
            sol = solve_ivp(self.rhs, (t, t_end), y, method=method, rtol=rtol, atol=rtol * scale,
                            max_step=max_step, dense_output=True, events=self._events(touching))
            if sol.status < 0:
                raise RuntimeError(f"solve_ivp failed at t = {sol.t[-1]:.6g} s: {sol.message}")
            segments.append(sol.sol)
            if sol.status == 0:
                break
            index = next(i for i, times in enumerate(sol.t_events) if len(times))
            t, y = float(sol.t_events[index][0]), sol.y_events[index][0].copy()
            touching[index] = not touching[index]
            events.append((t, index, "onset" if touching[index] else "separation"))
            if len(events) > MAX_EVENTS:
                raise RuntimeError(f"more than {MAX_EVENTS} contact events before t = {t:.6g} s: chattering contact")
        return Solution(self, segments, events, t_end)

    def _events(self, touching):
        """One terminal event per contact: x1 falling through 0 while in
        contact, rising through 0 while apart."""
        def event(index, direction):
            def crossing(t, y):
                return self.x1(y, index)
            crossing.terminal, crossing.direction = True, direction
            return crossing
        return [event(i, -1.0 if inside else 1.0) for i, inside in enumerate(touching)]


class Solution:
    """A Chain's run: the state at any time, the contact events as
    (t, contact index, "onset" | "separation")."""

    def __init__(self, chain, segments, events, t_end):
        self.chain, self.segments, self.events, self.t_end = chain, segments, events, t_end

    def y(self, t):
        """The state on the times t (an array within [0, t_end]): shape (size, len(t))."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        starts = np.array([s.t_min for s in self.segments])
        which = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(self.segments) - 1)
        out = np.empty((self.chain.size, len(t)))
        for k in np.unique(which):
            out[:, which == k] = self.segments[k](t[which == k])
        return out

    def series(self, t):
        """{u, v: (bodies, len(t)), x2, x1, F: (contacts, len(t))} on the times t."""
        c, y = self.chain, self.y(t)
        x1 = np.array([c.x1(y, i) for i in range(len(c.contacts))])
        F = np.array([contact_force(contact, x1[i]) for i, contact in enumerate(c.contacts)])
        return dict(u=y[c.U], v=y[c.V], x2=y[c.X2], x1=x1, F=F)

    def balances(self, t):
        """The energy and momentum balances at the times t, each relative to
        its initial value (zero in exact arithmetic): (kinetic + stored +
        dissipated - initial) / initial energy and (momentum - initial -
        the ground's impulse) / initial momentum."""
        c, y = self.chain, self.y(t)
        v = y[c.V]
        energy = 0.5 * np.sum(c.m[:, None] * v ** 2, axis=0) + y[c.E_LINKS] + np.sum(y[c.E_CONTACTS], axis=0)
        for link in c.links:
            energy = energy + 0.5 * link.k * c.relative(y, link)[0] ** 2
        for i, contact in enumerate(c.contacts):
            energy = energy + contact.k * np.maximum(c.x1(y, i), 0.0) ** (contact.n + 1) / (contact.n + 1)
        e0 = 0.5 * np.sum(c.m * c.v0 ** 2)
        p0 = np.sum(c.m * c.v0)
        momentum = np.sum(c.m[:, None] * v, axis=0) - y[c.IMPULSE]
        return (energy - e0) / e0, (momentum - p0) / (abs(p0) if p0 else 1.0)


def restitution(k, c, m, v):
    """-v_end/v of a body of mass m [kg] striking the rigid ground at v [m/s]
    through the contact (k, c) with Hertz's n = 3/2; 0 if it has not left
    after 50 elastic contact times."""
    elastic = hertz.contact_time(k, m, v)
    body = Chain([m], [v], contacts=[Contact(0, GROUND, k, c)])
    run = body.solve(50.0 * elastic, length=v * elastic, rtol=1e-10)
    ends = [t for t, _, kind in run.events if kind == "separation"]
    return -float(run.y(ends[0])[body.V][0, 0]) / v if ends else 0.0


def dashpot_for_restitution(eps, k, m, v):
    """The dashpot c [N s/m] with which a body of mass m striking the rigid
    ground at v through the Hertz spring k leaves at eps v (Brent's method on
    log c; restitution rises with c from 0 to 1)."""
    if not 0 < eps < 1:
        raise ValueError(f"eps = {eps} is invalid: a restitution with a dashpot lies in (0, 1)")
    scale = m / hertz.contact_time(k, m, v)      # the dashpot whose force at v matches the impact's mean force
    low, high = math.log(0.1 * scale), math.log(1e6 * scale)
    return math.exp(brentq(lambda log_c: restitution(k, math.exp(log_c), m, v) - eps, low, high, xtol=1e-12))
