"""The low-speed bumper impact, solved monolithically: a vehicle body
behind a bumper beam on a crash box (a spring and damper between them); the
beam's polypropylene fascia strikes a rigid barrier through the contact
element.

    r = solve()                       # 49 CFR 581's 2.5 mph
    r["F_peak"], r["crush"], r["duration"], r["restitution"]
"""

import numpy as np

from .chain import GROUND, Chain, Contact, Link
from .parameters import SPEEDS, Bumper, fascia

BODY, BEAM = 0, 1
FASCIA = 0
T_END = 0.5            # s: several contact times
SAMPLE = 1e-5          # s
RTOL = 1e-10
# The light beam's bounces on the barrier are short against the body's
# push: no step may be long enough to jump over one unseen.
MAX_STEP = 2e-4


def scene(v=SPEEDS["49 CFR 581"], bumper=Bumper()):
    """The Chain: body and beam at v, the crash box between them, the fascia on the barrier."""
    if not v > 0:
        raise ValueError(f"v = {v} is invalid: the impact speed must be > 0 [m/s]")
    k, c = fascia(bumper)
    return Chain([bumper.M, bumper.m_b], [v, v], links=[Link(BODY, BEAM, bumper.k_box, bumper.c_box)],
                 contacts=[Contact(BEAM, GROUND, k, c)])


def solve(v=SPEEDS["49 CFR 581"], bumper=Bumper(), t_end=T_END):
    """The impact: t, F (the barrier's force, N), u_body, u_beam, x2 (the
    fascia's permanent indentation) sampled every SAMPLE seconds; F_peak
    [N], crush (the body's largest travel, m), fascia_indentation (its
    largest x, m), x2_end, duration (the first contact's, s), impacts (the
    fascia's contacts), restitution (-the centre of mass's velocity at t_end
    / v, the fascia off the barrier), balances (the largest energy and
    momentum residuals, relative)."""
    chain = scene(v, bumper)
    run = chain.solve(t_end, length=0.05, rtol=RTOL, max_step=MAX_STEP)
    t = np.arange(0.0, t_end + 0.5 * SAMPLE, SAMPLE)
    s = run.series(t)
    ends = [time for time, _, kind in run.events if kind == "separation"]
    end = run.series([t_end])
    if not ends or end["F"][FASCIA, 0] > 0 or end["x1"][FASCIA, 0] >= 0:
        raise RuntimeError(f"the fascia is still on the barrier at t_end = {t_end} s: run longer")
    v_end = end["v"][:, 0]
    energy, momentum = run.balances(t)
    return dict(t=t, F=s["F"][FASCIA], u_body=s["u"][BODY], u_beam=s["u"][BEAM], x2=s["x2"][FASCIA],
                F_peak=float(s["F"][FASCIA].max()), crush=float(s["u"][BODY].max()),
                fascia_indentation=float((s["x1"][FASCIA] + s["x2"][FASCIA]).max()),
                x2_end=float(end["x2"][FASCIA, 0]), duration=ends[0],
                impacts=sum(kind == "onset" for _, _, kind in run.events) + 1,
                restitution=float(-(chain.m @ v_end) / (np.sum(chain.m) * v)),
                balances=(float(np.max(np.abs(energy))), float(np.max(np.abs(momentum)))))
