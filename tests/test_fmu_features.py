"""FMU features checked through the FMU against what is known independently
of the C code: gravity and the initial gap against free
fall, the driven scene's proxy striker under gravity, the extrapolated G1
law (law 3) at odd N, the force peak located inside a coarse step, the
`contact` flag's transitions, and k derived from the materials.

The references: closed forms (docs/model.md §2, §4; free fall), GSL's
high-accuracy solve of the same ODE (`fraccontact-solve --reference`) and
scipy (fraccontact/scipy_contact.py). Every approximate comparison states its
absolute tolerance (usually 0) and where its relative one comes from."""

import json
import math
import os
import pathlib
import re
import subprocess

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from fraccontact.scipy_contact import solve_drop

from closed_forms import EPS, GAMMA_5_2, HERTZ_TC, SCHEME_RTOL, extrapolated_ratio, hertz_k
from fmu_driver import C, K, M, V0

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOLVE = os.environ.get("FRACCONTACT_SOLVE", str(ROOT / "build" / "fraccontact-solve"))

# x1 = v t summed over <= 400 internal steps: <= n ulp (measured 1.5e-14),
# 1.5 times that and a few ulp in F = K x1^1.5 (measured 2.2e-14).
DRIVEN_RTOL = 1e-13
# %.6g in the log: half a unit in the 6th significant digit, <= 5e-6 relative.
LOGGED_RTOL = 5e-6


def reference(*options):
    """GSL's solve of the drop test (closed-form Hertz, so that the G1 error
    does not enter) as the solver's JSON."""
    done = subprocess.run([SOLVE, "--law", "hertz", "--reference", "--json", *map(str, options)],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def onsets_logged(s):
    """The (t_a, t_b, v) of every "contact began in (t_a, t_b] s at v m/s"."""
    found = []
    for _, category, message in s.log:
        m = re.fullmatch(r"contact began in \((\S+), (\S+)\] s at (\S+) m/s", message)
        if m and category == "logEvents":
            found.append(tuple(float(x) for x in m.groups()))
    return found


def first_flip(s, happened, leave_at="hi"):
    """Bisects the length tau of one communication step from the slave's
    present state for where happened() turns true (it must stay true for
    longer steps): returns the times (t_lo, t_hi) at the ends of the two
    steps around the flip, adjacent doubles, and leaves the slave at the end
    of the step to t_hi (or t_lo). The step's internal grid changes with tau,
    and with it the FMU's event time by the scheme's error: the flip is
    where the step ends just before or just after the event it finds."""
    state, t0 = s.fmu.getFMUstate(), s.t

    def run(tau):
        s.fmu.setFMUstate(state)
        s.t = t0
        if tau > 0.0:
            s.step(tau)
        return happened()

    lo, hi = 0.0, 1e-6
    while not run(hi):
        lo, hi = hi, 2 * hi
    while lo < 0.5 * (lo + hi) < hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if run(mid) else (mid, hi)
    assert run(hi) if leave_at == "hi" else not run(lo)
    s.fmu.freeFMUstate(state)
    return t0 + lo, t0 + hi


# --- gravity and the initial gap: free fall, exact in the FMU ---------------

def free_fall_onset(v0, g, gap0):
    """When and how fast the striker, starting at the gap gap0 with v0 under
    g, meets the specimen: v0 t + g t^2/2 = gap0. The root written without
    cancellation, t = 2 gap0 / (v0 + sqrt(v0^2 + 2 g gap0)), is also the
    g = 0 case, gap0 / v0. The conditioning of v0^2 + 2 g gap0 (large when
    g < 0 nearly stops the striker) is returned with them."""
    D = v0 * v0 + 2 * g * gap0
    v_on = math.sqrt(D)
    condition = max((v0 * v0 + 2 * abs(g) * gap0) / D, (abs(v0) + abs(g) * 2 * gap0 / (v0 + v_on)) / v_on)
    return 2 * gap0 / (v0 + v_on), v_on, condition


FALLS = [(V0, 9.81, 1e-3), (V0, 0.0, 1e-3), (V0, -9.81, 1e-3), (0.0, 9.81, 2e-3), (0.3, -9.81, 4e-3)]


@pytest.mark.parametrize("v0, g, gap0", FALLS)
def test_contact_begins_when_free_fall_closes_the_gap(slave, v0, g, gap0):
    """The onset time and speed against the closed form, to rounding. The
    closed form and the FMU's root each cost a few roundings, amplified by
    the conditioning when g < 0 nearly stops the striker (14.6 at v0 = 0.3,
    g = -9.81, gap0 = 4 mm); the bisection's bracket is 1 ulp wide: 4 ulp
    times that (measured: 2 ulp at most for the time, 3 for the speed)."""
    t_on, v_on, condition = free_fall_onset(v0, g, gap0)
    s = slave(law=2, v=v0, g=g, gap0=gap0)
    t_lo, t_hi = first_flip(s, lambda: s.get("contact") or s.get("F_peak") > 0.0, leave_at="lo")
    assert t_hi == pytest.approx(t_on, rel=4 * EPS * condition, abs=0)
    assert t_hi - t_lo <= 2 * math.ulp(t_on)
    # Just before: out of contact, at the surface to rounding (x can end a
    # rounding error inside, 1.1e-19 m at gap0 = 4 mm: the next step begins
    # contact at once), at the speed of free fall (v0 + g t exactly: the
    # flight is a parabola).
    assert not s.get("contact") and s.get("F") == 0.0
    assert abs(s.get("x")) <= 4 * EPS * gap0 and s.get("x1") <= 4 * EPS * gap0
    assert s.get("v_striker") == pytest.approx(v_on, rel=4 * EPS * condition, abs=0)


@pytest.mark.parametrize("v0, g, gap0", FALLS)
def test_onset_is_logged_and_contact_flips_in_its_step(slave, v0, g, gap0):
    """Under logEvents the FMU names the communication step in which contact
    began and the speed then; `contact` flips at that step's end."""
    t_on, v_on, _ = free_fall_onset(v0, g, gap0)
    H = 1e-4
    s = slave(law=2, v=v0, g=g, gap0=gap0)
    s.fmu.setDebugLogging(True, ["logEvents"])
    while not s.get("contact"):
        assert s.get("x") < 0.0 and s.get("F_peak") == 0.0
        s.step(H)
    assert s.t - H < t_on <= s.t
    [(t_a, t_b, v)] = onsets_logged(s)
    # the times as printed with %.9g: 5e-9 relative
    assert t_a == pytest.approx(s.t - H, rel=5e-9, abs=0) and t_b == pytest.approx(s.t, rel=5e-9, abs=0)
    assert v == pytest.approx(v_on, rel=LOGGED_RTOL, abs=0)


def test_a_flight_that_turns_back_never_touches(slave):
    """g < 0 with v0^2 < 2 |g| gap0: the striker turns in the gap. x follows
    the parabola exactly: to n ulp of its largest term over n steps of one
    exact piece each, 1e-14 of it at n = 20 (measured 2.9e-16 for x, 1.7e-16
    for v_striker); and contact never begins."""
    v0, g, gap0, H = 0.3, -9.81, 5e-3, 7e-3
    s = slave(law=2, v=v0, g=g, gap0=gap0)
    for n in range(1, 21):
        s.step(H)
        t = n * H
        scale = max(gap0, v0 * t, 0.5 * abs(g) * t * t)
        assert s.get("x") == pytest.approx(-gap0 + v0 * t + 0.5 * g * t * t, rel=0, abs=1e-14 * scale)
        assert s.get("v_striker") == pytest.approx(v0 + g * t, rel=0, abs=1e-14 * (v0 + abs(g) * t))
        assert not s.get("contact") and s.get("F_peak") == 0.0 and s.get("eps") == 0.0


# --- the drop test and the driven scene's proxy striker under gravity -------

GAP, GRAVITY = 2e-3, 9.81


@pytest.fixture(scope="module")
def gravity_reference():
    """GSL's solve of the drop test with g and a gap, three impacts."""
    return reference("--g", GRAVITY, "--gap0", GAP, "--v", repr(V0), "--impacts", 3)["per_impact"]


def first_impact(s):
    return dict(F_peak=s.get("F_peak"), eps=s.get("eps"), x2=s.get("x2"), E_diss=s.get("E_diss"))


@pytest.mark.parametrize("H", [1e-5, 1e-4])
def test_drop_test_under_gravity_matches_the_reference(slave, gravity_reference, H):
    """The FMU's own striker falls 2 mm under g before it lands: the first
    impact against GSL's, to the scheme's error (measured F_peak 9.1e-10,
    eps 3.4e-9, x2 1.3e-9, E_diss 7.7e-9, as without gravity); the logged
    onset brackets the reference's, with its speed to the printed digits."""
    s = slave(law=2, v=V0, g=GRAVITY, gap0=GAP)
    s.fmu.setDebugLogging(True, ["logEvents"])
    while s.get("eps") == 0.0:
        s.step(H)
    ref = gravity_reference[0]
    got = first_impact(s)
    for key in got:
        assert got[key] == pytest.approx(ref[key if key != "x2" else "x2_end"], rel=SCHEME_RTOL[key], abs=0), key
    [(t_a, t_b, v)] = onsets_logged(s)
    assert t_a < ref["t_onset"] <= t_b and v == pytest.approx(ref["v_onset"], rel=LOGGED_RTOL, abs=0)


@pytest.mark.parametrize("H", [1e-5, 1e-4])
def test_proxy_striker_falls_under_gravity_too(slave, gravity_reference, H):
    """Driven with m > 0 and g: the master owns the striker, m dv/dt = m g -
    F_avg, and steps the contact first. The proxy striker inside a step
    falls under g as the master's does, so the master reproduces the
    reference drop test to the scheme's error at any communication step. A
    proxy without gravity would lag the master's striker by g H^2/2 a step:
    F_peak off by 8e-5 at H = 1e-5 and 8e-4 at 1e-4 (measured), 3e4 and 3e5
    times the tolerance; its logged onset speed would lack the last step's
    g H (off by 1e-4 and 2.5e-4, 20 and 50 times the printed digits)."""
    s = slave(scene=2, m=M, law=2, v=V0, g=GRAVITY, gap0=GAP)
    s.fmu.setDebugLogging(True, ["logEvents"])
    v = V0
    while s.get("eps") == 0.0:
        s.set(v=v)
        s.step(H)
        v += (GRAVITY - s.get("F_avg") / M) * H
    ref = gravity_reference[0]
    got = first_impact(s)
    for key in got:
        assert got[key] == pytest.approx(ref[key if key != "x2" else "x2_end"], rel=SCHEME_RTOL[key], abs=0), key
    [(t_a, t_b, v_logged)] = onsets_logged(s)
    assert t_a < ref["t_onset"] <= t_b
    assert v_logged == pytest.approx(ref["v_onset"], rel=LOGGED_RTOL, abs=0)
    # and it is the FMU's own drop test under the same g: the master's v
    # differs from the proxy's end velocity by rounding (measured 1.7e-14
    # relative at most): 1e-13
    drop = slave(law=2, v=V0, g=GRAVITY, gap0=GAP)
    while drop.t < s.t - 0.5 * H:
        drop.step(H)
    for key, value in first_impact(drop).items():
        assert got[key] == pytest.approx(value, rel=1e-13, abs=0), key


# --- the contact flag -------------------------------------------------------

def test_contact_flag_follows_onsets_and_separations(slave, gravity_reference):
    """Under gravity the striker lands, rebounds and lands again. `contact`
    is false before the gap closes, true during each contact, false after
    separation, at every communication point (those within 1 ns of an event
    are skipped: the FMU's event times differ from the reference's by its
    scheme error, 3e-12 s at the first separation, 3e-10 s at the second
    landing, after 78 ms of flight)."""
    t_on1, _, _ = free_fall_onset(V0, GRAVITY, GAP)
    ref = gravity_reference
    intervals = [(t_on1, ref[0]["t_onset"] + ref[0]["t_contact"]),
                 (ref[1]["t_onset"], ref[1]["t_onset"] + ref[1]["t_contact"])]
    events = [t for interval in intervals for t in interval]
    s = slave(law=2, v=V0, g=GRAVITY, gap0=GAP)
    H, flags, checked = 1e-5, [False], 0
    while s.t < intervals[1][1] + 1e-3:
        s.step(H)
        contact = s.get("contact")
        if contact != flags[-1]:
            flags.append(contact)
        if min(abs(s.t - t) for t in events) > 1e-9:
            assert contact == any(a <= s.t < b for a, b in intervals), s.t
            assert (s.get("F") > 0.0) == contact and (s.get("x1") > 0.0) == contact, s.t
            checked += 1
    assert flags == [False, True, False, True, False] and checked > 8000


def test_contact_flag_flips_at_the_event_times(slave, gravity_reference):
    """The flips located to an ulp by bisecting the communication step. The
    first separation against the reference's (GSL) t_onset + t_contact, to
    the scheme's error in t_contact (measured 3.0e-12 s, 2.3e-9 of it); the
    second landing against the exact free flight from the FMU's own
    separation, which leaves the surface at x2 with v_sep and returns to it
    after -2 v_sep / g (rounding: measured 1 ulp, held to 8), and against
    the reference, off
    by the flight's 2 dv/g, the scheme's error in eps (measured 2.7e-10 s,
    3.4e-9 of the 78 ms flight)."""
    ref = gravity_reference
    s = slave(law=2, v=V0, g=GRAVITY, gap0=GAP)
    while not s.get("contact"):
        s.step(1e-5)
    t_sep = first_flip(s, lambda: not s.get("contact"))[1]
    assert t_sep == pytest.approx(ref[0]["t_onset"] + ref[0]["t_contact"], rel=0,
                                  abs=SCHEME_RTOL["t_contact"] * ref[0]["t_contact"])
    # just separated: x1 = 0, out of contact, leaving at v_sep, in flight
    # since the separation the FMU found inside the step for less than
    # 1e-17 s (measured 1.8e-18 s), a tenth of the landing's tolerance below
    v_sep = s.get("v_striker")
    assert not s.get("contact") and s.get("x1") == 0.0 and v_sep < 0.0
    assert 0.0 <= s.get("x2") - s.get("x") <= -v_sep * 1e-17
    x2 = s.get("x2")
    t_land = first_flip(s, lambda: s.get("contact") or s.get("x2") != x2)[1]
    flight = -2 * v_sep / GRAVITY
    assert t_land - t_sep == pytest.approx(flight, rel=8 * EPS, abs=0)
    assert t_land == pytest.approx(ref[1]["t_onset"], rel=0,
                                   abs=SCHEME_RTOL["t_contact"] * ref[0]["t_contact"]
                                   + SCHEME_RTOL["eps"] * flight)


# --- law 3: G1 with Richardson extrapolation --------------------------------

NODES = [1, 2, 3, 7, 15, 333, 1000, 1001]


@pytest.mark.parametrize("N", NODES)
def test_extrapolated_g1_law_at_fixed_nodes(slave, N):
    """Driven at a constant rate through a rigid dashpot: x1 = v t, so the
    force is k x1^(3/2) times the extrapolated ratio, odd N included."""
    v, H = 0.5, 1e-6
    s = slave(scene=2, m=0.0, v=v, c=1e20, law=3, g1_nodes=N, dt_max=1e-7)
    ratio = extrapolated_ratio(N)
    for n in range(1, 11):
        s.step(H)
        x1 = v * n * H
        assert s.get("F") == pytest.approx(K * x1 ** 1.5 * ratio, rel=DRIVEN_RTOL, abs=0), n
        assert s.get("semi_integral") == pytest.approx(x1 ** 1.5 / GAMMA_5_2 * ratio, rel=DRIVEN_RTOL, abs=0)
    if N >= 7:
        # Second order, independently of the formula above: with r(N) = 1 +
        # a1/N + a2/N^2 + a3/N^3, a2 = -21/384, a3 = 9/1024 (the series of
        # Gamma(N + 3/2)/Gamma(N)), the extrapolated ratio is 1 - a2/(N M)
        # - a3 (N + M)/(N M)^2 + O(N^-4): the leading term to within twice
        # the next one (1.5e-3 of it at N = 333, 0.034 at N = 15).
        M_ = N // 2
        leading, next_term = 21 / (384 * N * M_), 9 / 1024 * (N + M_) / (N * M_) ** 2
        assert s.get("F") / (K * x1 ** 1.5) - 1 == pytest.approx(leading, rel=2 * next_term / leading, abs=0)


def test_extrapolated_g1_law_counts_steps_since_onset(slave):
    """g1_nodes = 0: N = internal steps since onset, 3 per communication step
    of 3e-7 s at dt_max = 1e-7, so N = 3, 6, 9, ... half of them odd."""
    v, H = 0.5, 3e-7
    s = slave(scene=2, m=0.0, v=v, c=1e20, law=3, g1_nodes=0, dt_max=1e-7)
    for n in range(1, 41):
        s.step(H)
        x1 = v * n * H
        assert s.get("F") == pytest.approx(K * x1 ** 1.5 * extrapolated_ratio(3 * n), rel=DRIVEN_RTOL, abs=0), n


def test_extrapolated_g1_law_drop_test_matches_its_reference(slave):
    """With N fixed (odd) the law is Hertz with k times the extrapolated
    ratio: scipy's solve of that ODE, to the scheme's error."""
    N = 7
    s = slave(law=3, g1_nodes=N, v=V0)
    ref = solve_drop(K * extrapolated_ratio(N), C, M, V0)
    while s.get("eps") == 0.0:
        s.step(1e-5)
    for key in ("F_peak", "eps", "x2", "E_diss"):
        assert s.get(key) == pytest.approx(ref[key], rel=SCHEME_RTOL[key], abs=0), key


# --- the force peak inside a coarse step ------------------------------------

def hertz_peak():
    """The h20 impact with law 2 by scipy: the peak force and its time
    (where x1' = v - F/c = 0)."""
    def rhs(t, y):
        F = K * max(y[0], 0.0) ** 1.5
        return [y[1] - F / C, -F / M]

    def turn(t, y):
        return y[1] - K * max(y[0], 0.0) ** 1.5 / C
    turn.direction, turn.terminal = -1, True
    T0 = 1e-12
    sol = solve_ivp(rhs, (T0, 2e-3), [V0 * T0, V0], method="DOP853", rtol=1e-13, atol=[1e-19, 1e-15],
                    events=turn)
    return K * sol.y_events[0][0][0] ** 1.5, sol.t_events[0][0]


def test_force_peak_inside_a_step_converges_at_second_order(slave):
    """Steps of 1e-5 to 1.25e-6 s (one internal step per communication
    step), chosen so that the peak falls in the middle of a step, the worst
    place for the step ends. There the largest step-end force misses the
    peak by |F''| (dt/2)^2 / 2, F''/F = -1.5 F/(m x1) at the turn (x1' = 0,
    x1'' = -F/m): 1.22e6 dt^2 relative. The located peak errs by the
    scheme's C dt^2 alone, C = 3.76e5 to 3.79e5 s^-2 measured over this
    range with the fixed step (docs/model.md §11; order 1.98 to 2.00): held to
    4.9e5 dt^2 (1.3 times the largest) and an order of 2 +- 0.1."""
    F_ref, t_peak = hertz_peak()
    # Two DOP853 solves at rtol 1e-13: against a 25-digit Taylor-series solve
    # (mpmath's odefun) their peaks err up to 5e-14, alike with each
    # right-hand side's rounding moved by an ulp (another machine's SIMD
    # paths or libm); 1e-12 leaves a factor 20, 1e5 below the errors measured here.
    assert F_ref == pytest.approx(solve_drop(K, C, M, V0)["F_peak"], rel=1e-12, abs=0)
    x1_peak = (F_ref / K) ** (2 / 3)
    sampling = 0.1875 * F_ref / (M * x1_peak)
    errors, steps = [], []
    for n in (57, 114, 228, 456):
        dt = t_peak / (n + 0.5)
        s = slave(law=2, v=V0, dt_max=dt)
        samples = []
        while s.get("eps") == 0.0:
            s.step(dt)
            samples.append(s.get("F"))
        located, sampled = s.get("F_peak") / F_ref - 1, max(samples) / F_ref - 1
        assert abs(located) <= 4.9e5 * dt ** 2, (dt, located)
        # the premise: the step ends straddle the peak, where they miss it by
        # the closed form's amount, to O(dt) (F''' over half a step, and the
        # scheme's error): measured 1.2 % at the coarsest step, 0.15 % at the
        # finest
        assert sampled - located == pytest.approx(-sampling * dt ** 2, rel=0.03, abs=0), dt
        errors.append(located)
        steps.append(dt)
    orders = np.log(np.array(errors[:-1]) / np.array(errors[1:])) / np.log(np.array(steps[:-1]) / np.array(steps[1:]))
    assert np.all(np.abs(orders - 2) < 0.1), (errors, orders)


# --- the materials behind k = 0 ---------------------------------------------

DEFAULT_MATERIALS = dict(R=6.35e-3, E_i=210e9, nu_i=0.3, E_s=2.64e9, nu_s=0.4)
OTHER_MATERIALS = dict(R=5e-3, E_i=70e9, nu_i=0.33, E_s=1.2e9, nu_s=0.42)


@pytest.mark.parametrize("changed", list(OTHER_MATERIALS) + ["all"])
def test_k_zero_uses_every_material_parameter(slave, changed):
    """One material away from its default at a time (each changes k by
    2.8e-4, nu_i's share, or more: 1e9 times the tolerance), and all at
    once: F = k x1^(3/2) with k from docs/model.md §2, to the rounding of
    x1 = v t (DRIVEN_RTOL). No warning: k = 0 uses them."""
    materials = dict(DEFAULT_MATERIALS)
    materials.update(OTHER_MATERIALS if changed == "all" else {changed: OTHER_MATERIALS[changed]})
    k = hertz_k(**materials)
    assert abs(k / hertz_k(**DEFAULT_MATERIALS) - 1) > 2e-4
    v, H = 0.5, 1e-6
    s = slave(scene=2, m=0.0, v=v, c=1e20, law=2, k=0.0, dt_max=1e-7, **materials)
    for n in range(1, 11):
        s.step(H)
        assert s.get("F") == pytest.approx(k * (v * n * H) ** 1.5, rel=DRIVEN_RTOL, abs=0), n
    assert not [entry for entry in s.log if entry[0] != 0]


def test_k_from_materials_gives_the_hertz_impact(slave):
    """The elastic limit (docs/model.md §2) with k derived from other materials,
    another mass and speed: x_max = (5 m v0^2/(4k))^(2/5), F_max = k x_max^1.5,
    t_c = (4/5) B(2/5, 1/2) x_max / v0, eps = 1. At c = 1e15 the dashpot's
    share (~1/c: 2e-6 of F_peak at c = 1e9, too much) is ~1e-12, below the
    scheme's error at dt_max = 1e-7, measured here F_peak -9.3e-10, t_c
    2.9e-9, 1 - eps -1.5e-11: held to 3e-9, 7e-9 and 5e-11."""
    m, v0, H = 0.5, 1.2, 1e-6
    k = hertz_k(**OTHER_MATERIALS)
    s = slave(law=2, c=1e15, k=0.0, m=m, v=v0, **OTHER_MATERIALS)
    x_max = (5 * m * v0 ** 2 / (4 * k)) ** 0.4
    x1_max = 0.0
    while s.get("eps") == 0.0:
        s.step(H)
        x1_max = max(x1_max, s.get("x1"))
    # with g = 0 the free flight after separation dates it: x - x2 = v (t - t_sep)
    t_contact = s.t - (s.get("x") - s.get("x2")) / s.get("v_striker")
    assert s.get("F_peak") == pytest.approx(k * x_max ** 1.5, rel=SCHEME_RTOL["F_peak"], abs=0)
    assert t_contact == pytest.approx(HERTZ_TC * x_max / v0, rel=SCHEME_RTOL["t_contact"], abs=0)
    assert s.get("eps") == pytest.approx(1.0, rel=0, abs=5e-11)
    # x1 sampled every H: at most x''(H/2)^2/2 below x_max, x'' = k x_max^1.5/m
    # (7.8e-7 of x_max; measured 1.2e-7), and the scheme's 3e-9
    sampling = k * math.sqrt(x_max) / m * (H / 2) ** 2 / 2
    assert x1_max == pytest.approx(x_max, rel=sampling + 3e-9, abs=0)
    assert x1_max <= x_max * (1 + 3e-9)
