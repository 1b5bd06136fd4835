"""The pedestrian headform on a bonnet, solved monolithically: the headform
strikes the bonnet panel through the contact element (its skin on the
panel); the panel, a lumped mass held to the body by its bending stiffness
and damping, strikes a rigid hard point beneath through a second, stiff
contact once it has travelled the clearance gap0.

    r = solve(ADULT, gap0=0.060)      # r["figures"]["HIC15"], r["panel_deflection"], ...
    clearance_for_hic(1000.0, ADULT)  # the gap0 at which HIC15 = 1000
"""

import math

import numpy as np
from scipy.optimize import brentq

from .. import crash, hertz
from .chain import GROUND, Chain, Contact, Link
from .parameters import ADULT, Bonnet, skin

HEAD, PANEL = 0, 1
SKIN, HARD = 0, 1
T_END = 0.035          # s: the head has left the panel before (solve checks it)
SAMPLE = 1e-5          # s: 100 kHz, ten times CFC 1000's sample rate floor
RTOL = 1e-10
# The hard point's contact is far shorter than the head's: no step may be
# long enough to jump over it unseen.
MAX_STEP = 1e-4
NO_HARD_POINT = math.inf


def scene(headform=ADULT, gap0=NO_HARD_POINT, bonnet=Bonnet()):
    """The Chain: head and panel, the panel's support, the skin and the hard point."""
    if not gap0 >= 0:
        raise ValueError(f"gap0 = {gap0} is invalid: a clearance >= 0 [m], or NO_HARD_POINT")
    k_skin, c_skin = skin()
    contacts = [Contact(HEAD, PANEL, k_skin, c_skin)]
    if math.isfinite(gap0):
        contacts.append(Contact(PANEL, GROUND, bonnet.k_hard, bonnet.c_hard, gap=gap0))
    return Chain([headform.m, bonnet.m_p], [headform.v, 0.0],
                 links=[Link(PANEL, GROUND, bonnet.k_p, bonnet.c_p)], contacts=contacts)


def _run(headform, gap0, bonnet, t_end):
    chain = scene(headform, gap0, bonnet)
    run = chain.solve(t_end, length=0.01, rtol=RTOL, max_step=MAX_STEP)
    return chain, run, np.arange(0.0, t_end + 0.5 * SAMPLE, SAMPLE)


def solve(headform=ADULT, gap0=NO_HARD_POINT, bonnet=Bonnet(), t_end=T_END):
    """The impact sampled every SAMPLE seconds: t, a (the head's deceleration,
    m/s^2), a_g (the same in g, unfiltered), F_skin, F_hard, u_head, u_panel; figures (crash.figures after
    CFC 1000) and figures_raw (unfiltered); panel_deflection and head_travel
    (their largest values, m); the contact events; balances (the largest
    energy and momentum residuals, relative)."""
    chain, run, t = _run(headform, gap0, bonnet, t_end)
    s = run.series(t)
    skin_left = [e for e in run.events if e[1] == SKIN and e[2] == "separation"]
    if not skin_left or run.series([t_end])["F"][SKIN, 0] > 0:
        raise RuntimeError(f"the head is still on the panel at t_end = {t_end} s: run longer")
    a = s["F"][SKIN] / headform.m
    energy, momentum = run.balances(t)
    return dict(t=t, a=a, a_g=crash.in_g(a), F_skin=s["F"][SKIN], F_hard=s["F"][HARD] if len(chain.contacts) > 1 else 0 * t,
                u_head=s["u"][HEAD], u_panel=s["u"][PANEL],
                figures=crash.figures(t, a), figures_raw=crash.figures(t, a, cfc=False),
                panel_deflection=float(s["u"][PANEL].max()), head_travel=float(s["u"][HEAD].max()),
                events=run.events, balances=(float(np.max(np.abs(energy))), float(np.max(np.abs(momentum)))))


def hic15(headform, gap0, bonnet=Bonnet()):
    """(HIC15 of the CFC 1000 filtered head acceleration, the panel's largest
    deflection [m]): the cheap path of solve."""
    _, run, t = _run(headform, gap0, bonnet, T_END)
    s = run.series(t)
    a_g = crash.in_g(crash.filtered(t, s["F"][SKIN] / headform.m))
    return crash.hic(t, a_g, crash.WINDOWS["HIC15"])[0], float(s["u"][PANEL].max())


def clearance_for_hic(target, headform=ADULT, bonnet=Bonnet(), xtol=1e-4):
    """The clearance gap0 [m] at which HIC15 reaches target, to xtol [m]:
    Brent's method between 1 mm and the panel's deflection without a hard
    point (there the hard point is only grazed). ValueError when the panel
    alone already exceeds target or 1 mm of clearance stays below it."""
    hic_free, reach = hic15(headform, NO_HARD_POINT, bonnet)
    if hic_free >= target:
        raise ValueError(f"target = {target:g}: the panel without a hard point already gives HIC15 = "
                         f"{hic_free:.4g} ({headform.name} headform), no clearance brings it lower")
    low = 1e-3
    if hic15(headform, low, bonnet)[0] <= target:
        raise ValueError(f"target = {target:g}: even gap0 = {low} m keeps HIC15 below it ({headform.name} headform)")
    return brentq(lambda gap0: hic15(headform, gap0, bonnet)[0] - target, low, reach, xtol=xtol)


def elastic_hic(m, v, k=None, sample=1e-6):
    """HIC15 of a headform of mass m [kg] striking a rigid surface at v
    [m/s] through the skin's Hertz spring k alone (no dashpot), sampled
    every sample seconds: the elastic limit in which HIC ~ m^-0.6 v^2.8.
    Unfiltered: the scaling is the mechanics'."""
    k = skin()[0] if k is None else k
    body = Chain([m], [v], contacts=[Contact(0, GROUND, k, math.inf)])
    t_end = 1.01 * hertz.contact_time(k, m, v)
    run = body.solve(t_end, length=hertz.indentation(k, m, v), rtol=1e-12)
    t = np.arange(0.0, t_end, sample)
    return crash.hic(t, crash.in_g(run.series(t)["F"][0] / m), crash.WINDOWS["HIC15"])[0]
