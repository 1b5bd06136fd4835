"""The contact between two moving bodies (inputs v2, m2: the approach speed
v - v2 and the reduced mass m m2/(m + m2); -F on the striker, +F on the
second body) and the forces the proxy striker cannot see (inputs a, a2: the
other forces' accelerations at each step's start), in FMI 2.0 and 3.0, under
Gauss-Seidel and Jacobi masters, and in one call of the library and the
solver (its reference too); a, a2 and coupling refused there with the
reason. docs/two_bodies.md."""

import json
import math
import os
import pathlib
import shutil
import subprocess

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException

import fraccontact
from closed_forms import HERTZ_TC, SCHEME_RTOL
from doc_pages import section
from fraccontact.cosim import (M, V0, Unit, cosimulate, energy_error, monolithic, other_acceleration, spring_reference,
                               striker_values)
from test_solver import SOLVE

ROOT = pathlib.Path(__file__).resolve().parent.parent
CONTACT = pathlib.Path(os.environ.get("FRACCONTACT_FMU", ROOT / "build" / "fraccontact.fmu"))
CONTACT3 = pathlib.Path(os.environ.get("FRACCONTACT_FMU3", CONTACT.parent / "fraccontact-fmi3.fmu"))
STRIKER = pathlib.Path(os.environ.get("STRIKER_FMU", ROOT / "build" / "striker.fmu"))

# The case: 4.5 kg on 2 kg at 2 m/s (a headform on a free panel).
M1, M2, V = 4.5, 2.0, 2.0
T_END = 3e-3
# Rounding over a run: the bodies' and the proxy's motions are the same
# arithmetic in another order (a few hundred steps of 1e-16 each).
ROUNDING = 1e-12
# The momentum's change over its size: each step moves F H / m and F H / m2,
# rounded (measured below 4e-16 over 300 steps).
MOMENTUM = 1e-14


def reduced(m, m2):
    return m * m2 / (m + m2)


class Contact:
    """The contact FMU (FMI 2.0 or 3.0) through fmpy's API, by name."""

    def __init__(self, fmi, **values):
        path = str(CONTACT if fmi == 2 else CONTACT3)
        md = read_model_description(path)
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.folder = extract(path)
        if fmi == 2:
            from fmpy.fmi2 import FMU2Slave
            self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=self.folder,
                                 modelIdentifier=md.coSimulation.modelIdentifier, instanceName="contact")
            self.fmu.instantiate()
            self.fmu.setupExperiment(startTime=0.0)
            self.fmu.enterInitializationMode()
            self._set_real, self._get_real, self._set_int = self.fmu.setReal, self.fmu.getReal, self.fmu.setInteger
        else:
            from fmpy.fmi3 import FMU3Slave
            self.fmu = FMU3Slave(guid=md.guid, unzipDirectory=self.folder,
                                 modelIdentifier=md.coSimulation.modelIdentifier, instanceName="contact")
            self.fmu.instantiate()
            self.fmu.enterInitializationMode(startTime=0.0)
            self._set_real, self._get_real, self._set_int = (self.fmu.setFloat64, self.fmu.getFloat64,
                                                             self.fmu.setInt32)
        self.set(**values)
        self.fmu.exitInitializationMode()

    def set(self, **values):
        for name, value in values.items():
            (self._set_int if isinstance(value, int) else self._set_real)([self.vr[name]], [value])

    def get(self, name):
        return self._get_real([self.vr[name]])[0]

    def step(self, t, H):
        self.fmu.doStep(t, H)

    def free(self):
        self.fmu.terminate()
        self.fmu.freeInstance()
        shutil.rmtree(self.folder, ignore_errors=True)


def two_bodies(fmi, coupling, H, m=M1, v=V, m2=M2, v2=0.0, g1=0.0, g2=0.0, feed=False):
    """Two rigid bodies on one axis, integrated by this master exactly (each
    under its constant acceleration g1, g2 and the contact force held over
    the step: -F on the striker, +F on the second), the contact FMU between
    them; coupling 1 feeds F_avg after the contact's step (Gauss-Seidel), 2
    F_avg_next before it (Jacobi). feed: g1, g2 given to the contact as its
    inputs a, a2. Returns the contact's F_peak and eps, the restitution of
    the approach speed, and the momentum's change less the impulse of g1, g2
    over its size."""
    c = Contact(fmi, law=2, scene=2, coupling=coupling, v=v, m=m, v2=v2, m2=m2)
    x1 = x2 = 0.0
    v1, w = v, v2
    steps = round(T_END / H)
    for n in range(steps):
        c.set(v=v1, v2=w, **(dict(a=g1, a2=g2) if feed else {}))
        if coupling == 2:
            F = c.get("F_avg_next")
            c.step(n * H, H)
        else:
            c.step(n * H, H)
            F = c.get("F_avg")
        a1, a2 = g1 - F / m, g2 + F / m2
        x1, v1 = x1 + v1 * H + 0.5 * a1 * H * H, v1 + a1 * H
        x2, w = x2 + w * H + 0.5 * a2 * H * H, w + a2 * H
    F_peak, eps = c.get("F_peak"), c.get("eps")
    c.free()
    momentum = m * v1 + m2 * w - (m * v + m2 * v2) - (m * g1 + m2 * g2) * steps * H
    return dict(F_peak=F_peak, eps_contact=eps, eps=-(v1 - w) / (v - v2),
                momentum_error=momentum / (abs(m * v) + abs(m2 * v2)))


@pytest.fixture(scope="module")
def single_body():
    """The reference: the contact FMU's own drop test of the reduced mass at the approach speed."""
    return monolithic(CONTACT, m=reduced(M1, M2), v=V)


# ------------------------------------------------------- two free bodies

@pytest.mark.parametrize("fmi", [2, 3])
@pytest.mark.parametrize("coupling", [1, 2], ids=["gauss-seidel", "jacobi"])
@pytest.mark.parametrize("H", [1e-5, 1e-4])
def test_two_free_bodies_are_the_reduced_mass_impact(single_body, fmi, coupling, H):
    """The proxy moves the relative motion with the reduced mass: the same
    model and internal steps as the single body's drop test, so F_peak and
    eps to rounding (measured: F_peak bit for bit, eps 1e-14), and the
    momentum the two bodies exchange is conserved to rounding."""
    r = two_bodies(fmi, coupling, H)
    assert r["F_peak"] == pytest.approx(single_body["F_peak"], rel=ROUNDING, abs=0)
    assert r["eps_contact"] == pytest.approx(single_body["eps"], rel=ROUNDING, abs=0)
    assert r["eps"] == pytest.approx(single_body["eps"], rel=ROUNDING, abs=0)
    assert r["momentum_error"] == pytest.approx(0, rel=0, abs=MOMENTUM)


@pytest.mark.parametrize("coupling", [1, 2], ids=["gauss-seidel", "jacobi"])
def test_a_second_body_moving_towards_the_striker_through_striker_fmus(single_body, coupling):
    """The same through the striker FMU (two instances, cosim.py's master),
    the second body coming the other way: only the approach speed counts."""
    force = "mass-aware" if coupling == 1 else "predictive"
    order = "gauss-seidel" if coupling == 1 else "jacobi"
    r = cosimulate(CONTACT, STRIKER, 1e-5, force, order, m=M1, v=1.5, m2=M2, v2=-0.5)
    assert r["F_peak"] == pytest.approx(single_body["F_peak"], rel=ROUNDING, abs=0)
    assert r["eps"] == pytest.approx(single_body["eps"], rel=ROUNDING, abs=0)
    assert r["momentum_error"] == pytest.approx(0, rel=0, abs=MOMENTUM)
    assert r["energy_error"] <= 0  # the scheme's own dissipation, no energy created


@pytest.mark.parametrize("coupling", [1, 2], ids=["gauss-seidel", "jacobi"])
def test_a_common_acceleration_fed_as_a_and_a2_leaves_the_impact_alone(single_body, coupling):
    """Both bodies under the same acceleration (falling together): fed as a
    and a2 the proxy feels a - a2 = 0, and the impact is the free one to
    rounding; the momentum changes by the acceleration's impulse alone."""
    r = two_bodies(2, coupling, 1e-5, g1=9.81, g2=9.81, feed=True)
    assert r["F_peak"] == pytest.approx(single_body["F_peak"], rel=ROUNDING, abs=0)
    assert r["eps"] == pytest.approx(single_body["eps"], rel=ROUNDING, abs=0)
    assert r["momentum_error"] == pytest.approx(0, rel=0, abs=MOMENTUM)


def test_the_drop_test_reads_v2_and_m2_at_initialization(slave, single_body):
    """scene = 1: the FMU's own striker is the relative motion of the two
    bodies from the start (the same model as the single body's, the reduced
    mass rounded another way)."""
    s = slave(law=2, m=M1, v=2.5, m2=M2, v2=0.5)
    for _ in range(300):
        s.step(1e-5)
    assert s.get("F_peak") == pytest.approx(single_body["F_peak"], rel=ROUNDING, abs=0)
    assert s.get("eps") == pytest.approx(single_body["eps"], rel=ROUNDING, abs=0)


def test_a_in_the_drop_test_is_named_in_a_warning(slave):
    s = slave(a=1.0)
    assert any("a = 1" in message and "no effect in the drop test" in message for _, _, message in s.log)


# ------------------------------------------- the forces the proxy cannot see

K_S = 1e5  # the striker FMU's spring, N/m (docs/cosimulation.md's case)
COUPLINGS = [("mass-aware", "gauss-seidel"), ("predictive", "jacobi")]


@pytest.fixture(scope="module")
def spring():
    return spring_reference(K_S)


def errors(r, ref):
    """F_peak's relative error and eps's (the contact's own, at the separation) against scipy's."""
    return abs(r["F_peak"] / ref["F_peak"] - 1), abs(r["eps_contact"] - ref["eps"])


@pytest.mark.parametrize("coupling", COUPLINGS, ids=["gauss-seidel", "jacobi"])
def test_a_constant_force_fed_as_a_is_g(coupling):
    """Gravity in the striker FMU, fed to the contact as a (not as its g):
    the proxy moves as the striker does, and the co-simulation is the one
    with the contact's g to rounding. Neither creates energy beyond the
    model's own (the monolithic drop test's balance): the striker taking
    F_avg held over each step ends the contact higher than the proxy did,
    and the account takes that potential energy back after the contact
    (docs/model.md §17), so v_end moves off the drop test's by the
    correction (measured 7.8e-7 relative under Gauss-Seidel at this H,
    where 5.0e-7 E0 was created before)."""
    ref = monolithic(CONTACT, g=9.81)
    fed = cosimulate(CONTACT, STRIKER, 1e-4, *coupling, g=9.81, feed_a=True)
    known = cosimulate(CONTACT, STRIKER, 1e-4, *coupling, g=9.81, g_contact=9.81)
    assert fed["F_peak"] == pytest.approx(known["F_peak"], rel=ROUNDING, abs=0)
    assert fed["v_end"] == pytest.approx(known["v_end"], rel=ROUNDING, abs=0)
    assert fed["energy_error"] <= ref["energy_error"] + ROUNDING
    # rel 1e-5: the correction's measured 7.8e-7 with room; F_peak is before the correction acts
    assert fed["v_end"] == pytest.approx(ref["v_end"], rel=1e-5, abs=0)
    assert fed["F_peak"] == pytest.approx(ref["F_peak"], rel=ROUNDING, abs=0)


@pytest.mark.parametrize("coupling", COUPLINGS, ids=["gauss-seidel", "jacobi"])
def test_a_spring_fed_as_a_is_second_order(spring, coupling):
    """The spring k_s on the striker, which no contact parameter describes:
    its acceleration fed as a at each step's start cuts the coupling's error
    from first order in H to second (measured at 1e-5 s: F_peak 2.6e-4 ->
    6.4e-7 Gauss-Seidel, 2.1e-6 Jacobi; eps 2.2e-4 -> 1.1e-6 and 2.9e-6;
    orders 1.9 to 2.9 over 1e-6 to 1e-4 s)."""
    blind, fed = {}, {}
    for H in (1e-6, 1e-5, 1e-4):
        blind[H] = errors(cosimulate(CONTACT, STRIKER, H, *coupling, k_s=K_S), spring)
        fed[H] = errors(cosimulate(CONTACT, STRIKER, H, *coupling, k_s=K_S, feed_a=True), spring)
    for i in range(2):
        assert fed[1e-5][i] <= blind[1e-5][i] / 10  # at least tenfold (measured a hundredfold)
    # second order: a decade of H, two of the error (1.8, below the measured 1.9 to 2.4, allows the
    # scheme's error at 1e-6 s, where F_peak's is 2e-8 against the FMU's own floor of about 1e-9)
    assert math.log10(fed[1e-4][0] / fed[1e-5][0]) >= 1.8
    assert math.log10(fed[1e-5][0] / fed[1e-6][0]) >= 1.8
    assert math.log10(fed[1e-4][1] / fed[1e-5][1]) >= 1.8  # eps at 1e-6 s is at the floor (7e-9)
    # and first order without: a decade of H, one of the error (measured 0.97 to 1.0)
    assert 0.9 <= math.log10(blind[1e-5][0] / blind[1e-6][0]) <= 1.1


STEPS = (1e-6, 1e-5, 1e-4, 2e-4, 5e-4, 1e-3)  # the report's range, 1 us to 1 ms
T_REPAID = 6e-3  # three steps of 1 ms after the separation; the spring brings the striker back after 10 ms


@pytest.mark.parametrize("H", STEPS)
@pytest.mark.parametrize("coupling", COUPLINGS, ids=["gauss-seidel", "jacobi"])
def test_a_spring_fed_as_a_creates_no_energy(coupling, H):
    """The coupling's energy account (docs/model.md §17) corrects the force
    the bodies take so that the energy it creates stays at or below 0: the
    striker's kinetic and spring energy plus the contact's E_diss end below
    the start (main created (k_s / m) (H^2 / 4) E_diss, +2.2e-6 E0 at
    1e-5 s). Measured -1.4e-8 E0 at 1 us to -1.1e-1 at 1 ms; a Jacobi
    master at 1 ms created +0.41 E0 before the account counted the proxy's
    own work at the contact's end and could pull the separated bodies.
    ROUNDING: the energies' rounding over a run, far below the FMU's own
    dissipation (about -1e-9 E0 at these H), so only a coupling that
    creates energy fails."""
    r = cosimulate(CONTACT, STRIKER, H, *coupling, k_s=K_S, feed_a=True)
    assert r["energy_error"] <= ROUNDING


@pytest.mark.parametrize("H", STEPS)
@pytest.mark.parametrize("coupling", COUPLINGS, ids=["gauss-seidel", "jacobi"])
def test_a_spring_the_contact_does_not_see_creates_no_energy(coupling, H):
    """Blind (a not fed), the account still sees the bodies' velocities at
    both ends of each step, and the energy the unseen spring makes the
    coupling create (first order in H on main: +7.8e-4 E0 at 1e-5 s) is
    taken back (measured -9.9e-9 to -9.8e-3 E0). Under Jacobi at 1 ms the
    force of each step is fixed a step before the inputs that end the step
    before it: what the unseen spring did in the impact's last step is
    taken back from the separated bodies over the following steps (+8.3e-2
    E0 at 3 ms, +2.3e-2 at 4, +3.3e-3 at 5, -3.5e-3 at 6), so the runs go on
    to T_REPAID."""
    r = cosimulate(CONTACT, STRIKER, H, *coupling, k_s=K_S, t_end=T_REPAID)
    assert r["energy_error"] <= ROUNDING


@pytest.mark.parametrize("coupling", COUPLINGS, ids=["gauss-seidel", "jacobi"])
def test_the_energy_correction_keeps_the_spring_case_within_its_second_order_error(spring, coupling):
    """The correction takes energy from the bodies only where the coupling
    would create it, by a force change of the size of that energy over the
    step's displacement: second order in H, so F_peak and eps stay within
    the fed coupling's second-order error at 1e-5 s (measured: F_peak
    6.4e-7 Gauss-Seidel, 2.1e-6 Jacobi; eps 1.1e-6 and 2.9e-6), far below
    the blind coupling's 2.6e-4 and 2.2e-4."""
    r = cosimulate(CONTACT, STRIKER, 1e-5, *coupling, k_s=K_S, feed_a=True)
    # rel 5e-6: the larger measured F_peak error (2.1e-6) and room for the FMU's own 1e-9; 50 times below blind
    assert r["F_peak"] == pytest.approx(spring["F_peak"], rel=5e-6, abs=0)
    # abs 6e-6: the larger measured eps error (2.9e-6) twice over; 35 times below blind
    assert r["eps_contact"] == pytest.approx(spring["eps"], rel=0, abs=6e-6)


def early_return_run(order, H, gap0, t_end):
    """The k_s case through the FMI 3.0 contact with early return allowed,
    a fed each step: the striker FMU takes each part up to an onset or a
    separation as a step. Returns the energy error and the early returns."""
    from fmpy.fmi3 import FMU3Slave
    md = read_model_description(str(CONTACT3))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    contact = FMU3Slave(guid=md.guid, unzipDirectory=extract(str(CONTACT3)),
                        modelIdentifier=md.coSimulation.modelIdentifier, instanceName="contact")
    contact.instantiate(earlyReturnAllowed=True)
    contact.enterInitializationMode(startTime=0.0)
    contact.setInt32([vr["scene"], vr["law"], vr["coupling"]], [2, 2, 2 if order == "jacobi" else 1])
    contact.setFloat64([vr["gap0"], vr["m"], vr["v"]], [gap0, M, V0])
    contact.exitInitializationMode()
    striker = Unit(STRIKER, "striker", striker_values(k_s=K_S))
    force = vr["F_avg_next" if order == "jacobi" else "F_avg"]
    t, early = 0.0, 0
    for n in range(round(t_end / H)):
        end = (n + 1) * H
        while t < end:
            announced = contact.getFloat64([force])[0]
            x, v = striker.get("x", "v")
            contact.setFloat64([vr["v"], vr["a"]], [v, other_acceleration(x, 0.0, K_S)])
            _, _, returned, last = contact.doStep(t, end - t)
            early += returned
            striker.set(F=announced if order == "jacobi" else contact.getFloat64([force])[0])
            striker.do_step(t, last - t)
            t = last
        t = end
    E_diss = contact.getFloat64([vr["E_diss"]])[0]
    contact.terminate()
    contact.freeInstance()
    x, v = striker.get("x", "v")
    striker.free()
    return energy_error(v, E_diss, x, k_s=K_S), early


@pytest.mark.parametrize("order", ["gauss-seidel", "jacobi"])
def test_an_early_returns_part_of_a_step_is_a_step_of_the_account(order):
    """FMI 3.0 with early return: the master takes the part of a step up to
    the contact's onset or separation as a step of its own, and so does
    the energy account. Left out of it, those parts let a Gauss-Seidel
    master at H = 1 ms create +2.4e-3 E0 (measured now -3.0e-2 E0, Jacobi
    -5.8e-2). ROUNDING as above."""
    energy, early = early_return_run(order, 1e-3, 1e-4, 4e-3)
    assert early == 2  # the onset and the separation
    assert energy <= ROUNDING


@pytest.mark.parametrize("H", (1e-6, 1e-5))
@pytest.mark.parametrize("coupling", COUPLINGS, ids=["gauss-seidel", "jacobi"])
def test_the_energy_correction_takes_back_no_more_than_the_coupling_creates(coupling, H):
    """What the fed coupling would create without the correction has a
    closed form, C = (k_s / m) (H^2 / 4) E_diss / E0 (the proxy holding a
    over the step, and the master holding the force on a striker the spring
    slows; it matched the uncorrected runs within 3 % up to 2e-5 s). An
    account that knows the bodies' displacement to the order of those terms
    (Hermite's quadrature of the velocities with the fed a at both ends)
    overshoots by less than C: the energy ends between -C and 0 (measured
    -0.53 C to -0.67 C). With the trapezoid's displacement instead, the
    account misses the held force's share and the correction takes back
    more than twice what was created (-1.06 C to -1.19 C)."""
    r = cosimulate(CONTACT, STRIKER, H, *coupling, k_s=K_S, feed_a=True)
    created = K_S / M * H ** 2 / 4 * r["E_diss"] / (0.5 * M * V0 ** 2)
    assert -created <= r["energy_error"] <= ROUNDING


# ------------------------------------------------------------- bad input

@pytest.mark.parametrize("name, value, shown", [
    ("m2", -1.0, "-1"), ("m2", math.nan, "nan"), ("m2", math.inf, "inf"), ("m2", 1e-310, "1e-310"),
    ("v2", math.nan, "nan"), ("v2", -math.inf, "-inf"), ("a", math.nan, "nan"), ("a2", math.inf, "inf"),
    ("a", 1e300, "1e+300"),   # the power it drives into the dashpot overflows
])
def test_bad_second_body_inputs_are_refused_and_the_instance_stays_usable(slave, name, value, shown):
    s = slave(scene=2, law=2, m=1.0, m2=2.0, v=1.0)
    before = s.get(name)
    with pytest.raises(FMICallException):
        s.set(**{name: value})
    message = s.last_error()
    assert message.startswith(f"{name} = {shown} is invalid: "), message
    assert s.get(name) == before
    s.step(1e-4)
    assert s.get("F") > 0


def test_a_relative_motion_beyond_double_is_named_as_such(slave):
    """Each body's own motion passes the striker's rules, their relative
    motion does not (the reduced mass's kinetic energy overflows): the
    message names the approach speed and the reduced mass, not v and m."""
    s = slave(scene=2, law=2, m=1.0, m2=1.0, v=1.5e154)
    with pytest.raises(FMICallException):
        s.set(v2=-1.5e154)
    assert ("the relative motion of the two bodies (v - v2 = 3e+154 m/s, reduced mass m m2/(m + m2) = 0.5 kg) "
            "breaks the striker's rule: v = 3e+154 is invalid: the striker's kinetic energy") in s.last_error()
    assert s.get("v2") == 0.0
    s.set(v2=-1.0)  # the instance stays usable
    assert s.get("v2") == -1.0


def test_an_approach_speed_beyond_double_is_refused(slave):
    s = slave(scene=2, law=2, damper=2, m=0.0, v=1e308)  # the springpot: no dashpot power c v^2 to overflow
    with pytest.raises(FMICallException):
        s.set(v2=-1e308)
    assert "v2 = -1e+308 is invalid: the approach speed v - v2 must be finite" in s.last_error()
    assert s.get("v2") == 0.0


# ------------------------------------------------ two bodies in one call of the library and the solver

K, MR = 3.299e8, M1 * M2 / (M1 + M2)


def test_the_two_body_impact_is_one_call_and_the_elastic_closed_form():
    """4.5 kg at 3 m/s on a 2 kg body at 1 m/s, no damping to speak of
    (c = 1e300): Hertz's closed form (docs/model.md §2) at the approach speed
    2 m/s with the reduced mass 18/13 kg. Tolerances: the scheme's
    (closed_forms.SCHEME_RTOL, 3x what it measures; here F_peak 1.0e-9,
    t_contact 3.2e-9, eps 1.6e-11)."""
    r = fraccontact.impact(law="hertz", c=1e300, v=3.0, m=M1, v2=1.0, m2=M2)
    u = 3.0 - 1.0
    x_max = (5 * MR * u * u / (4 * K)) ** 0.4
    assert r.F_peak == pytest.approx(K * x_max ** 1.5, rel=SCHEME_RTOL["F_peak"], abs=0)
    assert r.t_contact == pytest.approx(HERTZ_TC * x_max / u, rel=SCHEME_RTOL["t_contact"], abs=0)
    assert r.eps == pytest.approx(1.0, rel=SCHEME_RTOL["eps"], abs=0)
    assert r.v_onset == u


def test_the_solvers_reference_takes_the_two_bodies_too():
    """--reference (GSL at --rtol 1e-12) with --v2 and --m2: the same closed
    form, within 1e-10 (100x the reference's tolerance; it measures 1e-14)."""
    done = subprocess.run([SOLVE, "--reference", "--law", "hertz", "--c", "1e300", "--v", "3", "--m", str(M1),
                           "--v2", "1", "--m2", str(M2), "--json"], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    r = json.loads(done.stdout)
    x_max = (5 * MR * 2.0 ** 2 / (4 * K)) ** 0.4
    assert r["F_peak"] == pytest.approx(K * x_max ** 1.5, rel=1e-10, abs=0)
    assert r["t_contact"] == pytest.approx(HERTZ_TC * x_max / 2.0, rel=1e-10, abs=0)
    assert r["end"]["v"] == pytest.approx(-2.0, rel=1e-10, abs=0)  # the approach speed, reversed


def test_the_two_body_impact_is_the_two_free_bodies_co_simulation():
    """Against the two bodies each integrated by the master and exchanging
    -F and +F (two_bodies() above): their F_peak, and eps from the
    bodies' own final velocities, to the rounding of the same internal
    steps taken in another order (ROUNDING there, 1e-12)."""
    r = fraccontact.impact(law="hertz", v=V, m=M1, v2=0.0, m2=M2)
    bodies = two_bodies(2, 1, 1e-5)
    assert r.F_peak == pytest.approx(bodies["F_peak"], rel=1e-12, abs=0)
    assert r.eps == pytest.approx(bodies["eps"], rel=1e-12, abs=0)


def test_the_second_bodys_values_are_refused_by_name():
    for params, says in ((dict(m2=-1.0), "m2 = -1 is invalid: the second body's mass"),
                         (dict(v2=math.inf), "v2 = inf is invalid: the second body's velocity must be finite"),
                         (dict(v=1.5e154, m=1.0, v2=-1.5e154, m2=1.0), "the relative motion of the two bodies")):
        with pytest.raises(ValueError, match="^" + says.replace("(", r"\(")):
            fraccontact.impact(**params)
        option = "--" + next(iter(params))
        done = subprocess.run([SOLVE, *(str(x) for k, v in params.items() for x in (f"--{k}", v))], capture_output=True, text=True,
                              timeout=60)
        assert done.returncode == 2 and says in done.stderr and done.stdout == "", (option, done.stderr)


@pytest.mark.parametrize("name", ["a", "a2", "coupling"])
def test_the_co_simulation_inputs_are_refused_with_the_reason(name):
    """The FMU's variables that are no parameter of a run: TypeError saying
    why, as docs/python.md states."""
    with pytest.raises(TypeError, match=f"^{name}: no parameter of a run; .*a library run has no master"):
        fraccontact.impact(**{name: 1})
    prose = " ".join(section("In Python: the `fraccontact` package").split())
    assert "The FMU's inputs `a`, `a2` and `coupling` are no parameters of a run" in prose
