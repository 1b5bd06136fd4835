"""Model Exchange (docs/model_exchange.md): the contact FMU integrated by
the host's solver, fmpy's CVode, against independent references: GSL's
high-accuracy solve of the dashpot model (fraccontact-solve --reference,
rtol 1e-12) for the drop test, the driven scene and two free bodies; the
co-simulation's Radau IIA at a tolerance far below the host's for the
compressed springpot (the same kernel, another integrator); closed forms
for the derivatives. Then the refusals of the discrete-time methods, the
call sequence, the FMU state, and fmpy's validation."""

import ctypes
import json
import os
import pathlib
import subprocess

import numpy as np
import pytest
from fmpy import calloc, free, simulate_fmu
from fmpy.fmi2 import (FMU2Model, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE, fmi2CallbackFunctions,
                       fmi2CallbackLoggerTYPE)
from fmpy.logging import addLoggerProxy
from fmpy.validation import validate_fmu

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOLVE = os.environ.get("FRACCONTACT_SOLVE", str(ROOT / "build" / "fraccontact-solve"))
FMU3 = pathlib.Path(os.environ.get("FRACCONTACT_FMU3", ROOT / "build" / "fraccontact-fmi3.fmu"))

# The state vector (model/contact.h, CONTACT_ME_*): x, v, x2, E_diss, then
# CONTACT_MAX_MODES = 160 slots of the springpot's modes.
STATES, INDICATORS = 164, 2
HOST_RTOL = 1e-10  # the host's tolerance at which the figures are within 1e-6 of the references
K, C, M, V0 = 3.299e8, 6080.0, 0.7437, 0.626418  # the h20 test (docs/model.md §1)


@pytest.fixture(params=["fmi2", "fmi3"])
def either_fmu(request, fmu_path):
    """The FMI 2.0 FMU and the FMI 3.0 one: the same figures through both."""
    return fmu_path if request.param == "fmi2" else FMU3


def reference(*args):
    """fraccontact-solve --reference --json (GSL, rtol 1e-12) of law 2."""
    done = subprocess.run([SOLVE, "--reference", "--json", "--law", "hertz", *map(str, args)], capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def exchange(fmu_path, rtol, stop_time, **start):
    """An fmpy Model Exchange run with CVode, every event recorded."""
    return simulate_fmu(str(fmu_path), fmi_type="ModelExchange", solver="CVode", relative_tolerance=rtol,
                        stop_time=stop_time, start_values=dict(law=2, **start), record_events=True,
                        output=["F", "F_peak", "x", "x2", "v_striker", "E_diss", "eps", "contact"])


def impact(result):
    """The first impact's figures from a run's rows: its separation is the
    first row out of contact after one in contact (the event's own row)."""
    in_contact = np.flatnonzero(result["contact"])
    end = in_contact[0] + np.flatnonzero(~result["contact"][in_contact[0]:])[0]
    onset = result["time"][in_contact[0]]
    row = result[end]
    return dict(F_peak=row["F_peak"], eps=row["eps"], x2=row["x2"], E_diss=row["E_diss"],
                t_contact=row["time"] - onset)


def errors(found, ref):
    """Relative errors of F_peak, t_contact, x2 and E_diss, and eps's absolute one."""
    ref = dict(ref, x2=ref["x2_end"])
    out = {key: abs(found[key] / ref[key] - 1.0) for key in ("F_peak", "t_contact", "x2", "E_diss")}
    out["eps"] = abs(found["eps"] - ref["eps"])
    return out


# ------------------------------------------------------------- the figures

def test_the_h20_drop_test_matches_the_gsl_reference(either_fmu):
    """F_peak, t_contact, x2 within 1e-6 (relative) and eps within 1e-6 of
    the reference at the host's rtol 1e-10."""
    found = errors(impact(exchange(either_fmu, HOST_RTOL, 2e-3)), reference())
    assert max(found.values()) < 1e-6, found


def doc_table():
    """docs/model_exchange.md's table: {host rtol: (F_peak, t_contact, x2, eps) as written}."""
    text = (ROOT / "docs" / "model_exchange.md").read_text().split("## Accuracy against the host's tolerance")[1]
    rows = [[c.strip() for c in line.strip().strip("|").split("|")] for line in text.splitlines()
            if line.startswith("| 1e-")]
    return {float(r[0]): r[1:] for r in rows}


def test_the_error_falls_with_the_hosts_tolerance_as_the_page_says(fmu_path):
    """docs/model_exchange.md's convergence table, measured again: each
    error against the reference to the two digits written. And it falls:
    CVode's global error follows its local tolerance, so a hundredfold
    tighter rtol takes the largest error down at least tenfold."""
    ref = reference()
    table = doc_table()
    assert sorted(table) == [1e-12, 1e-10, 1e-8, 1e-6, 1e-4]
    worst = []
    for rtol, written in sorted(table.items(), reverse=True):
        found = errors(impact(exchange(fmu_path, rtol, 2e-3)), ref)
        measured = [found[key] for key in ("F_peak", "t_contact", "x2", "eps")]
        assert [f"{m:.1e}".replace("e-0", "e-") for m in measured] == written, (rtol, measured)
        worst.append(max(measured))
    for coarse, fine in zip(worst, worst[1:]):
        assert fine < coarse / 10.0, worst


def test_two_free_bodies_match_the_reference(either_fmu):
    """A striker meeting a moving second body of finite mass: the reduced
    mass at the approach speed v - v2, as the reference takes them."""
    bodies = dict(v=3.0, m=M, v2=1.0, m2=2.0)
    found = errors(impact(exchange(either_fmu, HOST_RTOL, 2e-3, **bodies)),
                   reference(*sum((["--" + k, v] for k, v in bodies.items()), [])))
    assert max(found.values()) < 1e-6, found


def test_the_driven_scene_matches_the_reference(either_fmu):
    """The indentation driven at the input rate v (no striker inertia):
    force, dent and dissipated work at t_end against the reference's."""
    t_end = 1e-3
    result = exchange(either_fmu, HOST_RTOL, t_end, scene=2, v=0.1, m=0.0)
    ref = reference("--scene", "driven", "--v", 0.1, "--m", 0, "--t-end", t_end)["end"]
    end = result[-1]
    assert end["time"] == pytest.approx(t_end, rel=0, abs=1e-15)  # fmpy ends on the stop time
    for key in ("F_peak", "x2", "E_diss"):
        assert abs(end[key] / ref[key] - 1.0) < 1e-6, key
    assert abs(end["x"] / ref["x"] - 1.0) < 1e-6


def springpot_cosimulation(fmu_path, stop_time, **start):
    """The co-simulation FMU's Radau IIA at tolerance 1e-12 (dt_max 1e-7
    and its kernel floor, the same kernel as Model Exchange's here)."""
    return simulate_fmu(str(fmu_path), stop_time=stop_time, output_interval=1e-5,
                        start_values=dict(law=2, damper=2, tolerance=1e-12, dt_max=1e-7, **start),
                        output=["F_peak", "x2", "E_diss", "eps", "contact"])


def test_the_compressed_springpot_matches_the_cosimulation(either_fmu):
    """Its kernel's modes as ODE states: F_peak and the dent x2 at 3 ms
    (recovering) within 1e-6 (relative), eps within 1e-6 of Radau IIA's.
    Both take the kernel of tolerance > 0 (floor 1e-9 s)."""
    start = dict(damper=2, tolerance=1e-12, dt_max=1e-7)
    me = exchange(either_fmu, HOST_RTOL, 3e-3, **start)[-1]
    cs = springpot_cosimulation(either_fmu, 3e-3)[-1]
    for key in ("F_peak", "x2"):
        assert abs(me[key] / cs[key] - 1.0) < 1e-6, key
    assert abs(me["eps"] - cs["eps"]) < 1e-6


# ------------------------------------------------------ the instance itself

# fmpy's logger proxy keeps the last callbacks it was given: none is freed
# before the process ends (as fraccontact.fmu's Slave keeps its own).
_CALLBACKS = []


class Instance:
    """An FMU2Model instantiated for Model Exchange and initialized with
    `values` (names set by reference), its log messages in self.log."""

    def __init__(self, model_description, unzipped, **values):
        self.vr = {v.name: v.valueReference for v in model_description.modelVariables}
        self.log = []
        callbacks = fmi2CallbackFunctions()
        callbacks.logger = fmi2CallbackLoggerTYPE(lambda env, name, status, category, message:
                                                  self.log.append(message.decode()))
        callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        addLoggerProxy(ctypes.byref(callbacks))
        _CALLBACKS.append(callbacks)
        self.fmu = FMU2Model(guid=model_description.guid, unzipDirectory=unzipped,
                             modelIdentifier=model_description.modelExchange.modelIdentifier,
                             instanceName="me")
        self.fmu.instantiate(callbacks=callbacks)
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        for name, value in values.items():
            (self.fmu.setInteger if isinstance(value, int) else self.fmu.setReal)([self.vr[name]], [value])

    def start(self):
        self.fmu.exitInitializationMode()
        self.fmu.newDiscreteStates()
        self.fmu.enterContinuousTimeMode()
        return self

    def states(self):
        x = np.zeros(STATES)
        self.fmu.getContinuousStates(x.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), STATES)
        return x

    def set_states(self, x, nx=STATES):
        self.fmu.setContinuousStates(np.ascontiguousarray(x).ctypes.data_as(ctypes.POINTER(ctypes.c_double)), nx)

    def derivatives(self):
        dx = np.zeros(STATES)
        self.fmu.getDerivatives(dx.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), STATES)
        return dx

    def get(self, name):
        return self.fmu.getReal([self.vr[name]])[0]

    def set(self, name, value):
        self.fmu.setReal([self.vr[name]], [value])

    def get_boolean(self, name):
        return self.fmu.getBoolean([self.vr[name]])[0]


class Instance3(Instance):
    """The same as an FMU3Model of the FMI 3.0 FMU (FMU3)."""

    def __init__(self, model_description, unzipped, **values):
        from fmpy.fmi3 import FMU3Model
        self.vr = {v.name: v.valueReference for v in model_description.modelVariables}
        self.log = []
        self.fmu = FMU3Model(guid=model_description.guid, unzipDirectory=unzipped,
                             modelIdentifier=model_description.modelExchange.modelIdentifier, instanceName="me3")
        self.fmu.instantiate(logMessage=lambda env, status, category, message: self.log.append(message.decode()))
        self.fmu.enterInitializationMode()
        for name, value in values.items():
            (self.fmu.setInt32 if isinstance(value, int) else self.fmu.setFloat64)([self.vr[name]], [value])

    def start(self):
        self.fmu.exitInitializationMode()
        self.fmu.updateDiscreteStates()
        self.fmu.enterContinuousTimeMode()
        return self

    def set_states(self, x, nx=STATES):
        self.fmu.setContinuousStates(np.ascontiguousarray(x).ctypes.data_as(ctypes.POINTER(ctypes.c_double)), nx)

    def get(self, name):
        return self.fmu.getFloat64([self.vr[name]])[0]

    def set(self, name, value):
        self.fmu.setFloat64([self.vr[name]], [value])


@pytest.fixture
def instance3():
    from fmpy import extract, read_model_description
    md, folder, made = read_model_description(str(FMU3)), extract(str(FMU3)), []

    def make(**values):
        made.append(Instance3(md, folder, **values))
        return made[-1]

    yield make
    for i in made:
        i.fmu.freeInstance()


@pytest.fixture
def instance(model_description, unzipped):
    made = []

    def make(**values):
        made.append(Instance(model_description, unzipped, **values))
        return made[-1]

    yield make
    for i in made:
        i.fmu.freeInstance()


def test_the_derivatives_are_the_dashpot_models(instance):
    """At a state in contact: x' = v, v' = -F/m, x2' = F/c, E_diss' = F^2/c
    with F = k x1^1.5 (the closed forms of docs/model.md §2), and the modes
    at rest."""
    i = instance(law=2).start()
    x = i.states()
    x[:4] = [2e-4, 0.3, 5e-5, 0.01]
    i.set_states(x)
    F = K * (x[0] - x[2]) ** 1.5
    dx = i.derivatives()
    # each a handful of roundings of its closed form: 1e-15 relative
    assert dx[:4] == pytest.approx([0.3, -F / M, F / C, F * F / C], rel=1e-15, abs=0)
    assert not dx[4:].any()
    assert i.get("F") == pytest.approx(F, rel=1e-15, abs=0)
    assert i.get("der(x2)") == dx[2]
    # the onset/separation indicator is the indentation x1 = x - x2, one subtraction: exact
    assert i.get("event_x1") == x[0] - x[2]


@pytest.mark.parametrize("fmi", [2, 3])
def test_the_driven_scenes_rate_follows_the_inputs_at_once(instance, instance3, fmi):
    """In the driven scene the approach speed is the input v - v2 (docs/model_exchange.md): an
    output read right after the host sets v shows it, before any state is set or derivative
    taken. One subtraction: exact."""
    i = (instance if fmi == 2 else instance3)(law=2, scene=2, v=0.5, v2=0.1).start()
    assert i.get("v_striker") == 0.5 - 0.1
    i.set("v", 0.7)
    assert i.get("v_striker") == 0.7 - 0.1
    assert i.get("der(x)") == 0.7 - 0.1
    i.set("v2", -0.2)
    assert i.get("v_striker") == 0.7 + 0.2


def test_the_springpots_modes_relax_at_their_rates(instance):
    """A mode's rate is x2' - b phi: with the modes all at the same stretch
    and the force gone, each mode's rate differs from the first's by
    (b_1 - b_i) phi, so the rates are distinct and x2' is common to all:
    the slots past the kernel's modes stay at rest."""
    i = instance(law=2, damper=2).start()
    x = i.states()
    x[4:] = 1e-6
    i.set_states(x)
    dx = i.derivatives()
    modes = np.flatnonzero(dx[4:])
    assert 20 < len(modes) < 160 and modes[-1] == len(modes) - 1  # a prefix of the slots
    assert dx[2] < 0.0  # the stretched memory pulls the dent back out of contact


@pytest.mark.parametrize("values, name, rule", [
    (dict(law=1), "law = 1", "law = 2"),
    (dict(law=3), "law = 3", "law = 2"),
    (dict(law=2, damper=2, memory=1), "memory = 1", "memory = 2"),
])
def test_the_discrete_time_methods_are_refused_and_the_instance_stays_usable(instance, values, name, rule):
    """The G1 history sums and the full G1 memory: the error names the
    variable, its value and what to take instead (co-simulation among
    it); the instance stays in initialization mode, where the variable can
    be changed and the start tried again."""
    i = instance(**values)
    with pytest.raises(Exception):
        i.fmu.exitInitializationMode()
    assert name in i.log[-1] and rule in i.log[-1] and "co-simulation" in i.log[-1], i.log
    key = "memory" if "memory" in name else "law"
    i.fmu.setInteger([i.vr[key]], [2])
    i.start()
    assert i.states()[1] == V0


def test_states_that_overflow_or_are_not_finite_are_errors(instance):
    """A non-finite state is refused naming it, the states kept; so are
    finite states whose force would overflow; extreme but finite states
    whose rates stay finite are taken."""
    i = instance(law=2).start()
    x = i.states()
    bad = x.copy()
    bad[2] = np.nan
    with pytest.raises(Exception):
        i.set_states(bad)
    assert "the state 2 is nan" in i.log[-1] and (i.states() == x).all()
    x[0] = 1e300  # a force of 1e458 N
    with pytest.raises(Exception):
        i.set_states(x)
    assert "beyond double precision" in i.log[-1] and i.states()[0] == 0.0
    x[0], x[1] = 1e-4, 1e300  # a finite state whose rate -F/m ... and x's rate v: 1e300 is finite
    i.set_states(x)
    x[3] = 1e308  # E_diss: finite; its rate F x2' finite; every derivative finite
    i.set_states(x)
    assert np.isfinite(i.derivatives()).all()
    s = instance(law=2, damper=2).start()  # a mode stretched to 1e300 m relaxes at b phi beyond doubles
    x = s.states()
    x[4] = 1e300
    s.set_states(x)
    with pytest.raises(Exception):
        s.derivatives()
    assert "the derivative of the state 4 overflows" in s.log[-1]


def test_the_call_sequence_is_enforced(instance):
    """Continuous states are set in continuous-time mode only, the count
    must be the FMU's, and co-simulation's step is not Model Exchange's."""
    i = instance(law=2)
    i.fmu.exitInitializationMode()
    x = np.zeros(STATES)
    with pytest.raises(Exception):  # event mode
        i.set_states(x)
    i.fmu.newDiscreteStates()
    i.fmu.enterContinuousTimeMode()
    with pytest.raises(Exception):
        i.set_states(x, STATES - 1)
    assert "nx = 163, but this FMU has 164" in i.log[-1]
    do_step = i.fmu.dll.fmi2DoStep
    do_step.argtypes, do_step.restype = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double, ctypes.c_int], ctypes.c_int
    assert do_step(i.fmu.component, 0.0, 1e-5, 1) == 3  # fmi2Error
    assert i.log[-1].startswith("fmi2DoStep is a function of co-simulation: this instance was made for "
                                "fmi2ModelExchange"), i.log[-1]
    i.set_states(i.states())


def test_the_fmu_state_restores_the_continuous_states(instance):
    """A state got mid-contact, the continuous states moved on, the state
    set again: the same states and derivatives, to the bit; also through
    serialization."""
    i = instance(law=2, damper=2).start()
    x = i.states()
    x[:4] = [2e-4, 0.3, 5e-5, 0.01]
    x[4:40] = 1e-6
    i.set_states(x)
    i.fmu.enterEventMode()
    i.fmu.newDiscreteStates()
    i.fmu.enterContinuousTimeMode()
    saved = i.fmu.getFMUstate()
    before, rates = i.states(), i.derivatives()
    i.set_states(np.zeros(STATES))
    i.fmu.setFMUstate(saved)
    assert (i.states() == before).all() and (i.derivatives() == rates).all()
    i.set_states(np.zeros(STATES))
    i.fmu.setFMUstate(i.fmu.deSerializeFMUstate(i.fmu.serializeFMUstate(saved)))
    assert (i.states() == before).all() and (i.derivatives() == rates).all()
    i.fmu.freeFMUstate(saved)


STATE_NAMES = ["x", "v_striker", "x2", "E_diss"] + [f"phi[{m + 1}]" for m in range(160)]
DERIVATIVES = [f"der({name})" for name in STATE_NAMES]


def jacobian_columns(i, x, knowns):
    """Per known (a state's place, or an input's name, "v" or "v2"): the
    directional derivative of all the derivatives, in the states' order,
    and the central difference of the derivatives over 1e-4 of the
    known's scale (the state's or the input's size here, at least 1e-7 m
    or 0.1 m/s)."""
    unknowns = [i.vr[n] for n in DERIVATIVES]
    columns = []
    for known in knowns:
        vr = i.vr[known] if isinstance(known, str) else i.vr[STATE_NAMES[known]]
        exact = np.array(i.fmu.getDirectionalDerivative(unknowns, [vr], [1.0]))
        value = i.get(known) if isinstance(known, str) else x[known]
        h = 1e-4 * max(abs(value), 0.1 if isinstance(known, str) else 1e-7)
        sides = []
        for sign in (1, -1):
            if isinstance(known, str):
                i.fmu.setReal([vr], [value + sign * h])
                i.set_states(x)
            else:
                y = x.copy()
                y[known] += sign * h
                i.set_states(y)
            sides.append(i.derivatives())
        if isinstance(known, str):
            i.fmu.setReal([vr], [value])
        i.set_states(x)
        columns.append((known, exact, (sides[0] - sides[1]) / (2 * h)))
    return columns


@pytest.mark.parametrize("values", [dict(law=2), dict(law=2, damper=2), dict(law=2, scene=2, v=0.1, m=0.0)],
                         ids=["dashpot", "springpot", "driven"])
def test_the_directional_derivatives_are_the_finite_differences(instance, values):
    """At a state in contact (the springpot's modes stretched), each
    column of the Jacobian the FMU gives against the central difference of
    its derivatives: they agree to the difference's error, h^2/6 times the
    third derivative of the force's x1^(3/2) at h = 1e-4 of the scale (below
    1e-9 relative) and rounding over h (1e-12), within 1e-7 of the column's
    size; the modes beyond the kernel's are 0 in both."""
    i = instance(**values).start()
    x = i.states()
    x[:4] = [2e-4, 0.3, 5e-5, 0.01]
    if values.get("damper") == 2:
        x[4:44] = np.linspace(1e-6, 2e-5, 40)
    i.set_states(x)
    knowns = [0, 1, 2, 3] + ([4, 20] if values.get("damper") == 2 else []) + (["v"] if "scene" in values else [])
    for known, exact, difference in jacobian_columns(i, x, knowns):
        scale = np.max(np.abs(exact)) + np.max(np.abs(difference))
        assert np.max(np.abs(exact - difference)) <= 1e-7 * scale, (known, exact[:6], difference[:6])


def test_directional_derivatives_name_what_they_take(instance):
    i = instance(law=2).start()
    with pytest.raises(Exception):
        i.fmu.getDirectionalDerivative([i.vr["der(x)"]], [i.vr["k"]], [1.0])
    assert "value reference 8 is not a continuous state or the input v or v2" in i.log[-1]


def declared_dependencies(model_description):
    """ModelStructure's Derivatives: {der(name): {known's name: its dependenciesKind}}."""
    return {u.variable.name: dict(zip((v.name for v in u.dependencies), u.dependenciesKind))
            for u in model_description.derivatives}


# The drop test and the driven scene, the dashpot and the springpot: the
# first springpot's kernel has all 160 modes (the tightest kernel, the
# shortest step), the second's fewer.
SCENES = [dict(law=2), dict(law=2, damper=2, memory_tolerance=1e-12, dt_max=1e-10),
          dict(law=2, scene=2, v=0.1, m=0.0), dict(law=2, damper=2, scene=2, v=0.1, m=0.0)]


def in_contact(shift):
    """States in contact, the modes stretched unevenly; shift moves them all."""
    x = np.zeros(STATES)
    x[:4] = [2e-4 + shift, 0.3 - 1e3 * shift, 5e-5 + 0.3 * shift, 0.01]
    x[4:] = np.linspace(1e-6, 2e-5, 160) * (1 + 1e4 * shift)
    return x


def test_the_declared_dependencies_are_the_jacobians_pattern(instance, model_description):
    """The Derivatives' dependencies (docs/model_exchange.md) against the
    Jacobian: over the four scenes, at two states each, every entry the
    directional derivatives give nonzero is declared, and every declared
    one is nonzero in a scene; the central differences are nonzero at the
    same entries (a rate that does not read a known does not move with it:
    exactly 0). A dependency declared fixed keeps its factor from one state
    to the other, to the bit (no rounding enters a factor that the state
    does not); each declared dependent moves in a scene. The FMI 3.0 FMU
    declares the same, by name."""
    from fmpy import read_model_description
    declared = declared_dependencies(model_description)
    assert list(declared) == DERIVATIVES
    assert declared == declared_dependencies(read_model_description(str(FMU3)))
    knowns = list(range(STATES)) + ["v", "v2"]
    names = STATE_NAMES + ["v", "v2"]
    seen, moved = set(), set()
    for values in SCENES:
        i = instance(**values).start()
        factors = []
        for shift in (0.0, 1e-5):
            x = in_contact(shift)
            i.set_states(x)
            columns = jacobian_columns(i, x, knowns)
            exact = np.array([c[1] for c in columns]).T  # row: a derivative, column: a known
            difference = np.array([c[2] for c in columns]).T
            assert ((exact != 0) == (difference != 0)).all(), values
            seen |= {(DERIVATIVES[r], names[c]) for r, c in zip(*np.nonzero(exact))}
            factors.append(exact)
        moved |= {(DERIVATIVES[r], names[c]) for r, c in zip(*np.nonzero(factors[0] != factors[1]))}
    pairs = {(d, k): kind for d, knowns_of in declared.items() for k, kind in knowns_of.items()}
    assert set(pairs) == seen
    assert {pair for pair, kind in pairs.items() if kind == "dependent"} == moved
    assert set(pairs.values()) == {"dependent", "fixed"}


def declared_output_dependencies(model_description):
    """ModelStructure's Outputs: {output's name: {known's name: its dependenciesKind}}, or None where
    the output declares no dependencies (then it depends on every known)."""
    return {u.variable.name: None if u.dependencies is None else
            dict(zip((v.name for v in u.dependencies), u.dependenciesKind or ())) for u in model_description.outputs}


def out_of_contact(shift):
    """States before contact (the gap x1 = x - x2 < 0), the modes stretched; shift moves them all."""
    x = in_contact(shift)
    x[0] = -1e-4 + shift
    return x


def output_values(i, outputs):
    return np.array([float(i.get_boolean(n)) if n == "contact" else i.get(n) for n in outputs])


def output_slopes(i, x, knowns, outputs):
    """Per known (a state's place, or an input's name, set as a host does: before the states): the
    outputs at x, their change over twice 1e-4 of the known's scale (as jacobian_columns), and that
    change over the step: the central difference."""
    at = output_values(i, outputs)
    columns, steps = [], []
    for known in knowns:
        value = i.get(known) if isinstance(known, str) else x[known]
        h = 1e-4 * max(abs(value), 0.1 if isinstance(known, str) else 1e-7)
        sides = []
        for sign in (1, -1):
            y = x.copy()
            if isinstance(known, str):
                i.set(known, value + sign * h)
            else:
                y[known] += sign * h
            i.set_states(y)
            sides.append(output_values(i, outputs))
        if isinstance(known, str):
            i.set(known, value)
        i.set_states(x)
        columns.append(sides[0] - sides[1])
        steps.append(2 * h)
    change = np.array(columns).T  # row: an output, column: a known
    return at, change, change / np.array(steps)


# The driven scene's v_striker is v - v2 in Model Exchange (the indentation's rate is the input),
# which the one ModelStructure leaves undeclared: it also makes co-simulation's promise of no direct
# feedthrough from the inputs (docs/model_exchange.md).
UNDECLARED_FEEDTHROUGH = {("v_striker", "v"), ("v_striker", "v2")}


@pytest.mark.parametrize("fmi", [2, 3])
def test_the_outputs_declared_dependencies_are_the_perturbations_pattern(instance, instance3, model_description, fmi):
    """The Outputs' dependencies (once FMI 2.0's dependencies="", co-simulation's no feedthrough, and
    FMI 3.0's none, every known) against what moving each state and the inputs v and v2 does to each
    output, in an instance of each FMU: over the four scenes, at states in contact and out of it, an
    output that moves with a known declares it, and every declared one moves in a scene (but
    UNDECLARED_FEEDTHROUGH). An output moves when its central difference exceeds 1e-10 of its value:
    the outputs that follow a known move by 2e-4 or more of their value at these steps (h = 1e-4 of
    the known, slopes of order 1 in relative terms), those that do not by a rounding of x1 + x2
    (1e-16). A dependency declared constant has the slope 1 at every state of every scene, to the
    rounding of x1 + x2 over h (1e-12); a fixed one keeps its slope from state to state within a
    scene (to that rounding; exactly in one); each declared dependent changes its slope between the
    states of a scene by more than 1e-6 of it (far above that rounding, far below the slopes'
    changes: x1's 1 to 0 out of contact, F's with x1^(1/2)). Both FMUs declare the same, by name."""
    from fmpy import read_model_description
    declared = declared_output_dependencies(model_description if fmi == 2 else read_model_description(str(FMU3)))
    outputs = list(declared)
    knowns = list(range(STATES)) + ["v", "v2"]
    names = STATE_NAMES + ["v", "v2"]
    seen, slopes = set(), []  # slopes: per scene, [output, known, state]
    for values in SCENES:
        i = (instance if fmi == 2 else instance3)(**values).start()
        found = []
        for x in (in_contact(0.0), in_contact(1e-5), out_of_contact(0.0), out_of_contact(1e-5)):
            i.set_states(x)
            at, change, slope = output_slopes(i, x, knowns, outputs)
            moves = np.abs(change) > 1e-10 * np.abs(at)[:, None]
            seen |= {(outputs[r], names[c]) for r, c in zip(*np.nonzero(moves))}
            found.append(slope)
        slopes.append(np.stack(found, axis=-1))
    every = dict.fromkeys(names, "dependent")  # what an output that declares none depends on
    pairs = {(o, k): kind for o, knowns_of in declared.items()
             for k, kind in (every if knowns_of is None else knowns_of).items()}
    assert set(pairs) | UNDECLARED_FEEDTHROUGH == seen
    assert not set(pairs) & UNDECLARED_FEEDTHROUGH
    for (output, known), kind in pairs.items():
        of = [scene[outputs.index(output), names.index(known)] for scene in slopes]  # per scene, per state
        if kind == "constant":
            assert max(np.max(np.abs(s - 1.0)) for s in of) <= 1e-12, (output, known)
        elif kind == "fixed":
            assert max(np.ptp(s) for s in of) <= 1e-12 and min(np.ptp(s) for s in of) == 0.0, (output, known)
        else:
            assert kind == "dependent" and max(np.ptp(s) - 1e-6 * np.max(np.abs(s)) for s in of) > 0, (output, known)
    assert declared_output_dependencies(read_model_description(str(FMU3))) == \
        declared_output_dependencies(model_description)


def test_a_state_the_host_set_restores_in_a_new_instance(instance):
    """Serialized mid-rise (the states set, no step completed: the force
    above the peak taken so far), it restores in an instance just made,
    to the bit, and a reset instance takes it too."""
    i = instance(law=2, damper=2).start()
    x = i.states()
    x[:4] = [2e-4, 0.3, 5e-5, 0.01]
    x[4:40] = 1e-6
    i.set_states(x)
    rates = i.derivatives()
    saved = i.fmu.serializeFMUstate(i.fmu.getFMUstate())
    for fresh in (instance(), i):
        if fresh is i:
            i.fmu.reset()
        fresh.fmu.setFMUstate(fresh.fmu.deSerializeFMUstate(saved))
        assert (fresh.states() == x).all() and (fresh.derivatives() == rates).all()


def test_fmpy_validates_the_fmu(either_fmu):
    assert validate_fmu(str(either_fmu)) == []


def test_the_fmi3_fmu_refuses_restores_and_counts_as_the_fmi2_one(model_description):
    """FMI 3.0's instance: the G1 law refused at the start naming law, the
    instance kept; then its counts, and its FMU state restoring the
    continuous states and their derivatives to the bit."""
    from fmpy import extract, read_model_description
    from fmpy.fmi3 import FMU3Model
    md = read_model_description(str(FMU3))
    folder = extract(str(FMU3))
    said = []
    fmu = FMU3Model(guid=md.guid, unzipDirectory=folder, modelIdentifier=md.modelExchange.modelIdentifier,
                    instanceName="me3")
    fmu.instantiate(logMessage=lambda env, status, category, message: said.append(message.decode()))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu.enterInitializationMode()
    with pytest.raises(Exception):
        fmu.exitInitializationMode()
    assert "law = 1" in said[-1] and "law = 2" in said[-1], said
    fmu.setInt32([vr["law"]], [2])
    fmu.setInt32([vr["damper"]], [2])
    fmu.exitInitializationMode()
    fmu.updateDiscreteStates()
    fmu.enterContinuousTimeMode()
    assert fmu.getNumberOfContinuousStates() == STATES and fmu.getNumberOfEventIndicators() == INDICATORS
    pointer = lambda a: a.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
    x = np.zeros(STATES)
    fmu.getContinuousStates(pointer(x), STATES)
    x[:4] = [2e-4, 0.3, 5e-5, 0.01]
    x[4:40] = 1e-6
    fmu.setContinuousStates(pointer(x), STATES)
    saved, rates = fmu.getFMUState(), np.zeros(STATES)
    fmu.getContinuousStateDerivatives(pointer(rates), STATES)
    fmu.setContinuousStates(pointer(np.zeros(STATES)), STATES)
    fmu.setFMUState(saved)
    after, again = np.zeros(STATES), np.zeros(STATES)
    fmu.getContinuousStates(pointer(after), STATES)
    fmu.getContinuousStateDerivatives(pointer(again), STATES)
    assert (after == x).all() and (again == rates).all()
    fmu.freeFMUState(saved)
    # the Jacobian's column of x against the central difference over 1e-4 of
    # it (as for FMI 2.0 above: agreeing within 1e-7 of the column)
    column = np.array(fmu.getDirectionalDerivative([vr["der(x)"], vr["der(v_striker)"], vr["der(x2)"]],
                                                   [vr["x"]], [1.0]))
    sides = []
    for sign in (1, -1):
        y = x.copy()
        y[0] *= 1 + sign * 1e-4
        fmu.setContinuousStates(pointer(y), STATES)
        rates = np.zeros(STATES)
        fmu.getContinuousStateDerivatives(pointer(rates), STATES)
        sides.append(rates[:3])
    difference = (sides[0] - sides[1]) / (2e-4 * x[0])
    assert np.max(np.abs(column - difference)) <= 1e-7 * np.max(np.abs(column))
    fmu.terminate()
    fmu.freeInstance()


def test_an_fmi3_model_exchange_instance_speaks_of_model_exchange(model_description):
    """The refusals of an FMI 3.0 instance for Model Exchange name the
    function that made it, its calls and its states, never co-simulation's
    own (fmi3InstantiateCoSimulation, Step Mode, communication steps); a
    co-simulation function called on it says what it is and what to call
    instead. An impact's end is logged without counting communication
    steps."""
    from fmpy import extract, read_model_description
    from fmpy.fmi3 import FMU3Model
    md = read_model_description(str(FMU3))
    folder = extract(str(FMU3))
    said = []
    log = lambda env, status, category, message: said.append(message.decode())
    for name, guid, rule in (("", md.guid, "instanceName must be a non-empty string"),
                             ("me3", "{not the token}", "instantiationToken does not match")):
        made = FMU3Model(guid=guid, unzipDirectory=folder, modelIdentifier=md.modelExchange.modelIdentifier,
                         instanceName=name)
        with pytest.raises(Exception):
            made.instantiate(logMessage=log)
        assert said[-1].startswith("fmi3InstantiateModelExchange: " + rule), said
    fmu = FMU3Model(guid=md.guid, unzipDirectory=folder, modelIdentifier=md.modelExchange.modelIdentifier,
                    instanceName="me3")
    fmu.instantiate(loggingOn=True, logMessage=log)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu.enterInitializationMode()
    fmu.setInt32([vr["law"]], [2])
    fmu.exitInitializationMode()
    pointer = lambda a: a.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
    x = np.zeros(STATES)
    with pytest.raises(Exception):
        fmu.setContinuousStates(pointer(x), STATES)
    assert said[-1] == ("fmi3SetContinuousStates: illegal call sequence: called in state Event Mode, allowed only "
                        "in Continuous-Time Mode"), said[-1]
    for call, args in (("fmi3EnterStepMode", ()), ("fmi3DoStep", (0.0, 1e-6, False, None, None, None, None))):
        with pytest.raises(Exception):
            getattr(fmu, call)(fmu.component, *args)
        assert said[-1].startswith(call + " is a function of co-simulation: this instance was made by "
                                   "fmi3InstantiateModelExchange"), said[-1]
    fmu.updateDiscreteStates()
    fmu.enterContinuousTimeMode()
    fmu.getContinuousStates(pointer(x), STATES)
    for total, velocity in ((2e-4, 0.3), (-1e-6, -0.3)):  # into contact, then out of it
        x[:2] = total, velocity
        fmu.setContinuousStates(pointer(x), STATES)
        fmu.enterEventMode()
        fmu.updateDiscreteStates()
        fmu.enterContinuousTimeMode()
    assert any(m.startswith("impact 1 ended at t = 0 s") for m in said), said
    fmu.terminate()
    fmu.freeInstance()
    for word in ("CoSimulation", "Step Mode", "communication step"):
        assert not [m for m in said if word in m and "is a function of co-simulation" not in m], word


def test_the_nominals_are_the_impacts_scales(instance):
    """The lengths' nominal is the elastic Hertz impact's largest
    indentation (5 m v0^2 / (4 k))^(2/5) (the spring's energy holding the
    striker's, docs/model_exchange.md), about a tenth of a millimetre here,
    however far the striker starts (gap0 = 1 m); the speed's is v0, the
    energy's m v0^2 / 2: each a few roundings of its closed form."""
    i = instance(law=2, gap0=1.0).start()
    nominal = np.zeros(STATES)
    i.fmu.getNominalsOfContinuousStates(nominal.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), STATES)
    length = (5 * M * V0 ** 2 / (4 * K)) ** 0.4
    expected = [length, V0, length, 0.5 * M * V0 ** 2] + [length] * 160
    assert nominal == pytest.approx(expected, rel=1e-14, abs=0)  # pow's and a few products' roundings
    assert i.states()[0] == -1.0  # the state x itself in metres
