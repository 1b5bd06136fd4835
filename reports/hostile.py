"""Hostile and degenerate input across the FMU's whole surface: every real
parameter and input at 0, negative, denormal, huge (1e300), NaN and +-Inf;
communication steps of 1e-15 s and 1e3 s; a step that does not start at the
last communication point; inputs changed during contact.

Every case states the verdict it must reach, and the check enforces it:

- refused when set: fmi2Error from fmi2SetReal, a log message naming the
  variable and its value, the old value kept, and the instance still usable
  (it initializes and steps with finite outputs);
- refused at initialization (rules that depend on the scene, the mass or
  the dashpot): fmi2Error from fmi2ExitInitializationMode, a message naming
  the variable and value; with the value put back the instance initializes
  and steps;
- refused by the step (a call that breaks a documented rule of fmi2DoStep):
  fmi2Error, a message naming the argument and its value, the outputs
  unchanged, and a correct step afterwards succeeds;
- runs: every output finite at every communication point, F >= 0, and the
  result agrees with something independent of the FMU: the GSL reference
  (fraccontact-solve --reference --json with the same parameters), a
  scipy solution, a closed form, or, where no reference means anything, the
  physical identities (momentum, energy not created).

Each case runs in its own process (a crash would be a finding, not fatal).
Writes the table, expected against observed verdict, to
docs/reliability_hostile.md (part of docs/reliability.md's evidence) and
exits 1 if any case fails.

Regenerate: scripts/report hostile
"""

import functools
import json
import math
import re
import subprocess
import sys

from tqdm import tqdm

from fraccontact import atomic, hertz, model, output, solver

from . import BAR

REALS = ["v", "m", "R", "E_i", "nu_i", "E_s", "nu_s", "k", "c", "dt_max", "g", "gap0"]
VALUES = {"0": 0.0, "negative": -1.0, "denormal": 5e-324, "huge": 1e300, "NaN": math.nan, "+Inf": math.inf,
          "-Inf": -math.inf}
OUTPUTS = ["F", "F_avg", "F_avg_next", "F_peak", "x", "x1", "x2", "v_striker", "E_diss", "eps", "semi_integral"]
# The library's defaults: the paper's h20 test (docs/model.md §1).
DEFAULTS = {name: model.defaults()[name] for name in REALS}
GAMMA_5_2 = 0.75 * math.sqrt(math.pi)
DEFAULT_STEPS = [["step", 1e-5]] * 200          # 2 ms: the h20 impact (1.3 ms) and some flight

REFUSED_SET = "refused when set"
REFUSED_INIT = "refused at initialization"
REFUSED_STEP = "refused by the step"
RUNS = "runs"

# The verdict for every real at each finite hostile value (NaN and +-Inf are
# refused when set, for every real): a refusal, or the check a run must pass
# ("reference": the GSL reference with the case's parameters). With why.
MATERIAL = "valid (positive, finite); no effect beside the given k (a warning names it)"
TABLE = {
    "v": {"0": ("at rest", "the striker rests on the specimen: nothing moves"),
          "negative": ("receding", "the striker moves away: free flight, no contact"),
          "denormal": ("tiny impact", "a valid speed: an impact too slow to indent measurably in 2 ms"),
          "huge": (REFUSED_SET, "the impact energy m v^2/2 = 3.7e599 J is beyond double precision, and so is "
                                "c v^2 without inertia: no run can have finite outputs, whatever m becomes")},
    "m": {"0": (REFUSED_INIT, "the drop test needs a mass (0 is the driven scene's 'no inertia')"),
          "negative": (REFUSED_SET, "a mass is >= 0"),
          "denormal": (REFUSED_SET, "1/m would overflow (docs/variables.md)"),
          "huge": ("constant rate", "valid: a striker of 1e300 kg does not slow down, a constant-rate drive")},
    "R": {"0": (REFUSED_SET, "R > 0"), "negative": (REFUSED_SET, "R > 0"),
          "denormal": ("reference", MATERIAL), "huge": ("reference", MATERIAL)},
    "E_i": {"0": (REFUSED_SET, "E > 0"), "negative": (REFUSED_SET, "E > 0"),
            "denormal": ("reference", MATERIAL), "huge": ("reference", MATERIAL)},
    "nu_i": {"0": ("reference", MATERIAL), "negative": (REFUSED_SET, "a Poisson ratio lies in (-1, 0.5]"),
             "denormal": ("reference", MATERIAL), "huge": (REFUSED_SET, "a Poisson ratio lies in (-1, 0.5]")},
    "E_s": {"0": (REFUSED_SET, "E > 0"), "negative": (REFUSED_SET, "E > 0"),
            "denormal": ("reference", MATERIAL), "huge": ("reference", MATERIAL)},
    "nu_s": {"0": ("reference", MATERIAL), "negative": (REFUSED_SET, "a Poisson ratio lies in (-1, 0.5]"),
             "denormal": ("reference", MATERIAL), "huge": (REFUSED_SET, "a Poisson ratio lies in (-1, 0.5]")},
    "k": {"0": ("reference", "valid: k derived from R, E_i, nu_i, E_s, nu_s (docs/model.md §2)"),
          "negative": (REFUSED_SET, "k >= 0"), "denormal": (REFUSED_SET, "1/k would overflow (docs/variables.md)"),
          "huge": ("rigid spring", "valid: a rigid spring, the dashpot alone stops the striker")},
    "c": {"0": (REFUSED_SET, "c > 0"), "negative": (REFUSED_SET, "c > 0"),
          "denormal": (REFUSED_SET, "1/c would overflow (docs/variables.md)"),
          "huge": ("elastic Hertz", "valid: a rigid dashpot, the elastic Hertz impact")},
    "dt_max": {"0": ("reference", "valid: the default, fixed steps of 1e-7 s"), "negative": (REFUSED_SET, "dt_max >= 0"),
               "denormal": (REFUSED_SET, "dt_max must be normal (docs/variables.md)"),
               "huge": ("reference", "valid: the internal steps are the 1e-5 s communication steps")},
    "g": {"0": ("reference", "no gravity (the default)"),
          "negative": ("reference", "valid: pulls the striker away; free flight after the rebound"),
          "denormal": ("reference", "valid: no measurable effect"),
          "huge": (REFUSED_INIT, "the weight m g = 7e299 N dissipates (m g)^2/c = 9e595 W in the dashpot: "
                                 "E_diss is beyond double precision at once (a rule on m, g, c)")},
    "gap0": {"0": ("reference", "no gap (the default)"), "negative": (REFUSED_SET, "gap0 >= 0"),
             "denormal": ("reference", "valid: contact after 8e-324 s"),
             "huge": ("never arrives", "valid: the striker does not reach the specimen")},
}


def case(expect, why, values=None, steps=None, names=None, warns=None):
    """One case as data (JSON, for the child process): what to set and do,
    the verdict and why; a refusal's (variable, value) its message must
    name; the variable a warning must name."""
    c = dict(expect=expect, why=why, values=values or {}, steps=steps or DEFAULT_STEPS)
    if names:
        c["names"] = list(names)
    if warns:
        c["warns"] = warns
    return c


def cases():
    for name in REALS:
        for label, value in VALUES.items():
            if label in ("NaN", "+Inf", "-Inf"):
                expect, why = REFUSED_SET, "not finite"
            else:
                expect, why = TABLE[name][label]
            refused = expect in (REFUSED_SET, REFUSED_INIT)
            warns = name if why == MATERIAL else None
            yield f"{name} = {label}", case(expect, why, {name: value}, names=(name, value) if refused else None,
                                            warns=warns)
    yield "communication step 1e-15 s", case("reference", "valid: ten steps of 1e-15 s, then the h20 test",
                                             steps=[["step", 1e-15]] * 10 + DEFAULT_STEPS)
    yield "communication step 1e3 s", case("one long step", "valid: the impact's internal steps, then free flight "
                                                            "in one exact step (docs/numerics.md)", steps=[["step", 1e3]])
    yield "communication step 1e3 s, dt_max 1 s", case(
        "one long step", "valid: the whole impact inside one internal step", values={"dt_max": 1.0},
        steps=[["step", 1e3]])
    yield "a step from the wrong time", case(REFUSED_STEP, "currentCommunicationPoint must be the FMU's time",
                                             steps=[["step", 1e-5], ["at", 0.5]],
                                             names=("currentCommunicationPoint", 0.5))
    yield "driven: v changed during contact", case(
        "driven reference", "valid: the master's v wins at every step (it pulls out, then pushes in again)",
        values={"scene": 2, "m": 0.0, "v": 0.5},
        steps=[["step", 1e-4], ["set", {"v": -2.0}], ["step", 1e-4], ["set", {"v": 5.0}], ["step", 1e-4]])
    yield "driven: m changed during contact", case(
        "driven reference", "valid: a proxy striker of 1 mg is thrown off by the loaded spring",
        values={"scene": 2, "m": 0.7, "v": 0.5},
        steps=[["step", 1e-4], ["set", {"m": 1e-6}], ["step", 1e-4], ["set", {"m": 0.0}], ["step", 1e-4]])
    yield "driven: v = 1e300 during contact", case(
        REFUSED_SET, "the dashpot would carry c v = 6e303 N and dissipate c v^2 = 6e603 W: beyond double "
                     "precision (a rule on c, known once running)",
        values={"scene": 2, "m": 0.0, "v": 0.5}, steps=[["step", 1e-4], ["set", {"v": 1e300}], ["step", 1e-4]],
        names=("v", 1e300))
    yield "drop test: v and m changed during contact (ignored)", case(
        "reference", "valid: the drop test takes v and m at initialization only",
        steps=[["step", 1e-4], ["set", {"v": 99.0, "m": 1e-9}]] + [["step", 1e-4]] * 19)


# --- running a case -----------------------------------------------------------

def outputs(s):
    return {n: s.get(n) for n in OUTPUTS}


def same(a, b):
    return a == b or (a != a and b != b)


def run_case_in(s, case):
    """Runs one case on s, a fresh instance not yet in initialization mode
    (tests/fmu_driver.py's Slave). Returns what was observed: the verdict reached,
    the message, the outputs after every communication step (trace), the
    warnings, and after a refusal whether the instance stayed usable."""
    from fmpy.fmi1 import FMICallException
    out = dict(observed=RUNS, message="", trace=[], usable=None, kept=None)
    phase, name, before, snapshot = "init", None, {}, None
    try:
        s.enter()
        for name, value in case["values"].items():
            before[name] = s.get(name)
            phase = "set"
            s.set(**{name: value})
            phase = "init"
        phase = "exit"
        s.fmu.exitInitializationMode()
        phase = "running"
        for kind, arg in case["steps"]:
            snapshot = outputs(s)
            if kind == "step":
                phase = "step"
                s.step(arg)
            elif kind == "at":                  # a step from the wrong time
                phase = "step"
                s.fmu.doStep(currentCommunicationPoint=arg, communicationStepSize=1e-5)
            else:
                for name, value in arg.items():
                    before[name] = s.get(name)
                    phase = "set while running"
                    s.set(**{name: value})
                phase = "running"
                continue
            values = outputs(s)
            out["trace"].append(dict(t=s.t, H=arg if kind == "step" else 1e-5, **values))
            if not all(math.isfinite(v) for v in values.values()):
                out["observed"] = "NON-FINITE OUTPUT"
                break
            if values["F"] < 0:
                out["observed"] = "TENSION"
                break
    except FMICallException:
        out["message"] = s.last_error()
        out["observed"] = {"set": REFUSED_SET, "set while running": REFUSED_SET, "exit": REFUSED_INIT,
                           "step": REFUSED_STEP}.get(phase, f"ERROR ({phase})")
        out["usable"], out["kept"] = recover(s, phase, name, before, snapshot)
    out["warnings"] = [m for status, category, m in s.log if status == 1]
    return out


def recover(s, phase, name, before, snapshot):
    """After a refusal: whether what was refused left things as they were
    (the old value, the outputs) and whether the instance then initializes
    and steps with finite outputs."""
    from fmpy.fmi1 import FMICallException
    kept = True
    try:
        if phase.startswith("set"):
            kept = same(s.get(name), before[name])
        elif phase == "exit":                  # put the values back: initialization must then succeed
            s.set(**before)
        elif phase == "step":
            kept = all(same(a, b) for a, b in zip(outputs(s).values(), snapshot.values()))
        if phase in ("set", "exit"):           # still in initialization mode
            s.fmu.exitInitializationMode()
        for _ in range(10):
            s.step(1e-5)
        return all(math.isfinite(v) for v in outputs(s).values()), kept
    except FMICallException:
        return False, kept


# One case in a child process of its own, so that a crash is a finding.
CHILD = r'''
import json, sys
from fmpy import extract, read_model_description
from fraccontact.fmu import Slave
from reports.hostile import run_case_in
md = read_model_description(sys.argv[1])
print(json.dumps(run_case_in(Slave(md, extract(sys.argv[1]), start=False), json.loads(sys.argv[2]))))
'''


def run_case(fmu, case):
    try:
        done = subprocess.run([sys.executable, "-c", CHILD, str(fmu), json.dumps(case)],
                              capture_output=True, text=True, timeout=300)
    except subprocess.TimeoutExpired:
        return dict(observed="HANG (over 300 s)", message="")
    if done.returncode != 0:
        return dict(observed=f"CRASH (exit {done.returncode})", message=" ".join(done.stderr.strip().splitlines()[-1:]))
    return json.loads(done.stdout.strip().splitlines()[-1])


# --- judging a case -----------------------------------------------------------

class Judgement:
    """The checks of one case: every failed one, and the comparison that came
    closest to its tolerance."""

    def __init__(self):
        self.failures = []
        self.worst = None   # (share of the tolerance used, text)
        self.basis = ""

    def true(self, what, condition):
        if not condition:
            self.failures.append(what)

    def close(self, what, got, want, *, rel, abs):
        """|got - want| <= max(rel |want|, abs), as pytest.approx; both
        tolerances explicit."""
        allowed = max(rel * math.fabs(want), abs)
        off = math.fabs(got - want)
        ok = off <= allowed if math.isfinite(got) else False
        share = off / allowed if allowed > 0 else (0.0 if off == 0 else math.inf)
        if not ok:
            self.failures.append(f"{what} = {got:.10g}, expected {want:.10g} (rel {rel:.2g}, abs {abs:.2g})")
        if ok and allowed > 0 and (self.worst is None or share > self.worst[0]):
            self.worst = (share, f"worst {what}: off by {off:.2g} of {allowed:.2g} allowed")


def names_value(message, name, value):
    """Whether the message says `name = value` (as printf writes it)."""
    for token in re.findall(rf"\b{re.escape(name)} = ([-+0-9.eEinfa]+)", message):
        try:
            if same(float(token.rstrip(".")), value):
                return True
        except ValueError:
            pass
    return False


def judge(name, case, r, solve):
    """The case's verdict against what was observed: a Judgement."""
    j = Judgement()
    j.true(f"verdict: expected {verdict_of(case)}, observed {r['observed']}", r["observed"] == verdict_of(case))
    if j.failures:
        return j
    if r["observed"] != RUNS:
        var, value = case["names"]
        j.true(f"the message names {var} = {value:g}", names_value(r["message"], var, value))
        j.true("the refused value or state is kept", r["kept"])
        j.true("the instance is usable afterwards (initializes, steps, finite outputs)", r["usable"])
        return j
    if "warns" in case:
        j.true(f"a warning names {case['warns']}", any(case["warns"] in w for w in r["warnings"]))
    output_identities(j, case, r)
    CHECKS[case["expect"]](j, case, r, solve)
    return j


def output_identities(j, case, r):
    """What the outputs owe each other at every communication point, in any
    run: F = Gamma(5/2) k semi_integral (docs/model.md §3: the force is the
    spring constant times the semi-integral); the dashpot carries the
    contact force, so the step's impulse F_avg H is c times x2's increase;
    in contact x = x1 + x2. Rounding only: rel 1e-12, and for the impulse
    1e-12 of c x2 (x2's increase is a difference of two rounded values)."""
    p = params(case)
    k = p["k"] if p["k"] > 0 else hertz_k(p)
    x2_0 = 0.0
    for o in r["trace"]:
        at = f" at t = {o['t']:.3g}"
        j.close("F / (Gamma(5/2) k semi_integral)" + at, o["F"], GAMMA_5_2 * k * o["semi_integral"], rel=1e-12, abs=0)
        j.close("F_avg H / c" + at, o["F_avg"] * o["H"] / p["c"], o["x2"] - x2_0, rel=1e-12, abs=1e-12 * o["x2"])
        if o["x1"] > 0:
            j.close("x - x1" + at, o["x"] - o["x1"], o["x2"], rel=1e-12, abs=1e-15 * o["x"])
        x2_0 = o["x2"]


def verdict_of(case):
    return case["expect"] if case["expect"] in (REFUSED_SET, REFUSED_INIT, REFUSED_STEP) else RUNS


def params(case):
    p = dict(DEFAULTS)
    p.update(case["values"])
    return p


def hertz_k(p):
    """k from the materials, docs/model.md §2."""
    return hertz.k_from_materials(p["R"], p["E_i"], p["nu_i"], p["E_s"], p["nu_s"])


@functools.lru_cache(maxsize=None)
def reference(solve, *args):
    """fraccontact-solve --reference --json (GSL's odeiv2 at rtol 1e-12,
    events to a few ulp): computed once per parameter set."""
    return solver.solve("--reference", *args, program=solve, timeout=300)


def scheme_tolerance(N, h, T):
    """Relative error allowed of the FMU's default scheme against an exact
    solution of the contact ODE. The G1 law's force is Hertz's times
    1 + 3/(8n) + O(n^-2) n internal steps after contact onset (docs/model.md §4).
    Results integrate it over the contact: E_diss, quadratic in the force,
    errs by 2 * 3/(8n) averaged with the weight F^2 ~ n^3 of a loading
    force (F ~ t^(3/2)), that is 1/N for N steps from onset to the force's
    peak (a drop test: about t_c/(2h)); a result linear in the force errs
    by less. SDIRK2 adds about (h/T)^2 for internal steps h on the time
    scale T. A factor 2 of margin over both.
    (The h20 defaults, N = t_c/(2h) = 6580: 3.0e-4, against errors of 2e-5
    to 6e-5; a contact of 698 steps: 2.9e-3, against 1.4e-3 in E_diss.)"""
    return 2 * (1 / N + (h / T) ** 2)


def last(r):
    return r["trace"][-1]


def internal_step(case):
    """The FMU's internal step in contact: the communication step or
    dt_max, whichever is shorter."""
    return min(model.step_limit(**params(case)), max(arg for kind, arg in case["steps"] if kind == "step"))


def drop_identities(j, case, r):
    """Momentum and energy of the drop test, at every communication point:
    m v + c x2 = m (v0 + g t) (the contact impulse is c x2; the scheme keeps
    this linear invariant to rounding: rel 1e-12 of its largest term), and
    energy not created: m v^2/2 + (spring energy 0.4 F x1) + E_diss <=
    m v0^2/2 when g = 0 (the G1 spring softens as N grows and each step
    counts J^2/(c h) <= the integral of F^2/c, so neither the law nor the
    step creates energy: rel 1e-12, rounding)."""
    p = params(case)
    m, c, v0, g = p["m"], p["c"], p["v"], p["g"]
    for o in r["trace"]:
        scale = m * math.fabs(v0) + m * math.fabs(g) * o["t"] + c * o["x2"]
        j.close(f"m v + c x2 at t = {o['t']:.3g}", m * o["v_striker"] + c * o["x2"], m * (v0 + g * o["t"]),
                rel=0, abs=1e-12 * scale)
        j.true(f"x2 >= 0, E_diss >= 0 at t = {o['t']:.3g}", o["x2"] >= 0 and o["E_diss"] >= 0)
        j.true(f"F <= F_peak at t = {o['t']:.3g}", o["F"] <= o["F_peak"])
        if g == 0:
            E = 0.5 * m * o["v_striker"] ** 2 + 0.4 * o["F"] * o["x1"] + o["E_diss"]
            j.true(f"energy {E:.10g} J not above m v0^2/2 at t = {o['t']:.3g}",
                   E <= 0.5 * m * v0 ** 2 * (1 + 1e-12))


def check_reference(j, case, r, solve):
    """The drop test against the GSL reference with the case's parameters
    (k derived from the materials in Python when k = 0): the impact's
    figures, then the free flight after separation."""
    p = params(case)
    k = p["k"] if p["k"] > 0 else hertz_k(p)
    ref = reference(solve, "--k", repr(k), "--c", repr(p["c"]), "--m", repr(p["m"]), "--v", repr(p["v"]),
                    "--g", repr(p["g"]), "--gap0", repr(p["gap0"]))
    h = internal_step(case)
    tol = scheme_tolerance(ref["t_contact"] / (2 * h), h, ref["t_contact"])
    j.basis = f"GSL reference, rel {tol:.2g}"
    o = last(r)
    t_flight = o["t"] - ref["per_impact"][0]["t_onset"] - ref["t_contact"]    # since separation
    for key, want in [("F_peak", ref["F_peak"]), ("eps", ref["eps"]), ("x2", ref["end"]["x2"]),
                      ("E_diss", ref["E_diss"]), ("v_striker", ref["end"]["v"] + p["g"] * t_flight)]:
        j.close(key, o[key], want, rel=tol, abs=0)
    # x = x2 + the flight since separation; its terms cancel, so the
    # tolerance is relative to their size.
    flight = ref["end"]["v"] * t_flight + 0.5 * p["g"] * t_flight ** 2
    j.close("x", o["x"], ref["end"]["x2"] + flight, rel=0, abs=tol * (ref["end"]["x2"] + math.fabs(flight)))
    for key in ("F", "F_avg", "x1", "semi_integral"):   # out of contact
        j.close(key, o[key], 0.0, rel=0, abs=0)
    drop_identities(j, case, r)


def check_constant_rate(j, case, r, solve):
    """m = 1e300: the force changes the striker's speed by at most
    F t / m = 8e-300 of itself, so the run is the driven scene at the
    constant rate v0, whose GSL reference it must match at 2 ms."""
    p = params(case)
    o = last(r)
    ref = reference(solve, "--scene", "driven", "--m", "0", "--v", repr(p["v"]), "--k", repr(p["k"]),
                    "--c", repr(p["c"]), "--t-end", repr(o["t"]))
    h = internal_step(case)
    tol = scheme_tolerance(o["t"] / h, h, o["t"])
    j.basis = f"GSL reference (driven at v0), rel {tol:.2g}"
    F = p["k"] * ref["end"]["x1"] ** 1.5
    for key, want in [("F_peak", ref["end"]["F_peak"]), ("F", F), ("x1", ref["end"]["x1"]), ("x2", ref["end"]["x2"]),
                      ("E_diss", ref["end"]["E_diss"]), ("semi_integral", ref["end"]["x1"] ** 1.5 / GAMMA_5_2)]:
        j.close(key, o[key], want, rel=tol, abs=0)
    # x = v0 t exactly but for the rounding of 20 000 steps' sums.
    j.close("x", o["x"], p["v"] * o["t"], rel=1e-12, abs=0)
    j.close("v_striker", o["v_striker"], p["v"], rel=1e-15, abs=0)
    j.close("eps", o["eps"], 0.0, rel=0, abs=0)        # the contact never ends
    drop_identities(j, case, r)


def check_rigid_spring(j, case, r, solve):
    """k = 1e300: the spring loads in ~1e-100 s, so the dashpot alone stops
    the striker: v = v0 exp(-c t/m), F = c v, x2 = m (v0 - v)/c,
    E_diss = m (v0^2 - v^2)/2, F_peak = c v0 (at t = 0+)."""
    p = params(case)
    m, c, v0 = p["m"], p["c"], p["v"]
    h = internal_step(case)
    j.basis = "closed form (rigid spring + dashpot)"
    for o in r["trace"][::20] + [last(r)]:
        t = o["t"]
        v = v0 * math.exp(-c * t / m)
        # The fixed step (docs/model.md §11) loads the rigid spring over its
        # first step, whose force is the spring's mean over it, so the
        # striker lags the closed form by up to a step, e^(c h/m) - 1 in v
        # (twice that allowed); after it each step decays by the trapezoidal
        # (1 - z/2)/(1 + z/2), z = c h/m, exact to z^3/12 a step.
        z, n = c * h / m, t / h
        tol = 2 * math.expm1(z) + n * z ** 3 / 12 + 1e-12
        j.close(f"v_striker at t = {t:.3g}", o["v_striker"], v, rel=tol, abs=0)
        j.close(f"F at t = {t:.3g}", o["F"], c * v, rel=tol, abs=0)
        # x2 and E_diss follow from v (m v + c x2 is kept exactly): v's
        # error carried over, absolute since v0 - v is small at first. Each
        # step counts J^2/(c h), short of the integral by the force's
        # variance over a step: (c h / m)^2 / 12 relative.
        j.close(f"x2 at t = {t:.3g}", o["x2"], m * (v0 - v) / c, rel=0, abs=m * tol * v / c)
        j.close(f"E_diss at t = {t:.3g}", o["E_diss"], 0.5 * m * (v0 ** 2 - v ** 2), rel=(c * h / m) ** 2 / 12,
                abs=m * tol * v * v)
        j.true(f"x1 below (F/k)^(2/3) * 2 at t = {t:.3g}", o["x1"] <= 2 * (c * v0 / p["k"]) ** (2 / 3))
    # The force is the spring's at the internal steps' ends. The first step
    # loads the rigid spring with the dashpot's force as its mean, so it ends
    # above it, at most at the fixed step's bound (n + 1) c v0 (docs/model.md
    # §11); none falls below c v0 less the decay of a step, c h / m.
    bound = (p.get("spring_exponent", model.defaults()["spring_exponent"]) + 1) * c * v0
    j.true(f"F_peak = {last(r)['F_peak']:.6g} within [c v0 (1 - 2 c h/m), (n + 1) c v0 = {bound:.6g}]",
           c * v0 * (1 - 2 * c * h / m) <= last(r)["F_peak"] <= bound)
    j.close("eps", last(r)["eps"], 0.0, rel=0, abs=0)        # the contact never ends
    drop_identities(j, case, r)


def check_elastic_hertz(j, case, r, solve):
    """c = 1e300: the elastic Hertz impact (docs/model.md §2):
    x_max = (5 m v0^2 / (4 k))^(2/5), F_peak = k x_max^(3/2), eps = 1,
    t_c = (4/5) B(2/5, 1/2) x_max / v0; the separation time read from the free flight
    that follows (x - x2 = v (t - t_sep))."""
    p = params(case)
    m, k, v0 = p["m"], p["k"], p["v"]
    x_max = hertz.indentation(k, m, v0)
    t_c = hertz.contact_time(k, m, v0)
    h = internal_step(case)
    tol = scheme_tolerance(t_c / (2 * h), h, t_c)
    j.basis = f"Hertz closed forms, rel {tol:.2g}"
    o = last(r)
    j.close("F_peak", o["F_peak"], k * x_max ** 1.5, rel=tol, abs=0)
    j.close("eps", o["eps"], 1.0, rel=tol, abs=0)
    j.close("v_striker", o["v_striker"], -v0, rel=tol, abs=0)
    t_sep = o["t"] - (o["x"] - o["x2"]) / o["v_striker"]
    j.close("contact time", t_sep, t_c, rel=tol + 5e-6, abs=0)   # the constant has 6 digits
    for key in ("F", "F_avg", "x1"):
        j.close(key, o[key], 0.0, rel=0, abs=0)
    # The dashpot barely moves: E_diss = int F^2/c dt <= F_peak^2 t / c.
    j.true("E_diss <= F_peak^2 t / c", o["E_diss"] <= o["F_peak"] ** 2 * o["t"] / p["c"])
    drop_identities(j, case, r)


def check_at_rest(j, case, r, solve):
    """v = 0 without gravity: the striker touches the specimen at rest and
    nothing moves: every output stays exactly 0."""
    j.basis = "closed form: all 0"
    for o in r["trace"]:
        for key in OUTPUTS:
            j.close(f"{key} at t = {o['t']:.3g}", o[key], 0.0, rel=0, abs=0)


def check_free_flight(j, case, r, solve):
    """The striker never touches (v < 0, or a gap of 1e300 m): x = -gap0 +
    v t (exact flight; rounding of up to 200 sums: rel 1e-12), v_striker = v,
    and no force, indentation or dissipation at all."""
    p = params(case)
    j.basis = "closed form: free flight"
    for o in r["trace"]:
        j.close(f"x at t = {o['t']:.3g}", o["x"], -p["gap0"] + p["v"] * o["t"], rel=1e-12, abs=0)
        j.close(f"v_striker at t = {o['t']:.3g}", o["v_striker"], p["v"], rel=0, abs=0)
        for key in ("F", "F_avg", "F_peak", "x1", "x2", "E_diss", "eps", "semi_integral"):
            j.close(f"{key} at t = {o['t']:.3g}", o[key], 0.0, rel=0, abs=0)


def check_tiny_impact(j, case, r, solve):
    """v = 5e-324: no reference resolves it, but physics bounds it: the
    striker cannot rebound, indent more than its free path v0 t (which
    rounds to 0), or push harder than the elastic Hertz peak
    k^(2/5) (5 m v0^2/4)^(3/5) (which rounds to 0); plus momentum and energy.
    One denormal ulp (5e-324) of slack for rounding."""
    p = params(case)
    m, k, v0 = p["m"], p["k"], p["v"]
    F_hertz = math.exp(0.4 * math.log(k) + 0.6 * math.log(1.25 * m) + 1.2 * math.log(v0))
    j.basis = "identities (no rebound, free-path and Hertz bounds, momentum, energy)"
    for o in r["trace"]:
        j.true(f"0 <= v_striker <= v0 at t = {o['t']:.3g}", 0 <= o["v_striker"] <= v0)
        j.close(f"F_peak at t = {o['t']:.3g}", max(o["F_peak"] - F_hertz, 0.0), 0.0, rel=0, abs=5e-324)
        j.true(f"0 <= x <= v0 t at t = {o['t']:.3g}", 0 <= o["x"] <= v0 * o["t"] + 5e-324)
        j.close(f"eps at t = {o['t']:.3g}", o["eps"], 0.0, rel=0, abs=0)   # the impact cannot end in 2 ms
    drop_identities(j, case, r)


def check_one_long_step(j, case, r, solve):
    """A 1000 s step holds the whole impact (with dt_max = 1 s inside one
    internal step, which resolves nothing, so no reference applies) and the
    flight after it; the identities apply whatever the steps: a rebound (0 < eps <= 1), v_striker = -eps v0 and
    x2 = m v0 (1 + eps)/c (momentum, to rounding), energy not created, and
    exact free flight for the rest of the 1000 s: (x - x2)/v_striker is the
    time since separation, between 1000 s - 10 ms and 1000 s."""
    p = params(case)
    m, c, v0 = p["m"], p["c"], p["v"]
    o = last(r)
    j.basis = "identities (momentum, energy, free flight)"
    j.true(f"0 < eps = {o['eps']:.6g} <= 1", 0 < o["eps"] <= 1)
    j.close("v_striker", o["v_striker"], -o["eps"] * v0, rel=1e-12, abs=0)
    j.close("x2", o["x2"], m * v0 * (1 + o["eps"]) / c, rel=1e-12, abs=0)
    flight = (o["x"] - o["x2"]) / o["v_striker"]
    j.true(f"time since separation {flight:.12g} s in [999.99, 1000]", 1000 - 1e-2 <= flight <= 1000 * (1 + 1e-12))
    j.true("F_peak > 0", o["F_peak"] > 0)
    for key in ("F", "x1", "semi_integral"):
        j.close(key, o[key], 0.0, rel=0, abs=0)
    drop_identities(j, case, r)


def driven_segments(segments, k, c):
    """The driven scene by scipy (DOP853, rtol 1e-12), independent of the C
    code: segments of (v, m, duration), v imposed at each segment's start
    (the master's v wins), then x1' = v - F/c, v' = -F/m (m > 0) or 0,
    x2' = F/c, E_diss' = F^2/c, F = k x1^(3/2) in contact; out of contact
    x1 (minus the gap) moves at v. Contact onset and separation end an
    integration and start the next. Returns the final state, F_peak, the
    events [(kind, t, v)] and x2 at the end of every segment. (Converged:
    with atol 100 times smaller the results move by 1e-11 relative, far
    inside the 3e-3 and 2e-2 the cases allow.)"""
    import numpy as np
    from scipy.integrate import solve_ivp
    y, t, F_peak, events, x2_ends = np.zeros(4), 0.0, 0.0, [], []
    for v, m, duration in segments:
        y[1] = v
        inv_m = 1.0 / m if m > 0 else 0.0
        t_end = t + duration
        while t < t_end:
            inside = y[0] > 0 or (y[0] == 0 and y[1] > 0)

            def rhs(_, y, inside=inside, inv_m=inv_m):
                F = k * max(y[0], 0.0) ** 1.5 if inside else 0.0
                return [y[1] - F / c, -F * inv_m, F / c, F * F / c]

            def crossing(_, y):
                return y[0]
            crossing.terminal, crossing.direction = True, (-1 if inside else 1)

            def turning(_, y):
                return y[1] - k * max(y[0], 0.0) ** 1.5 / c
            turning.direction = -1
            sol = solve_ivp(rhs, (t, t_end), y, method="DOP853", rtol=1e-12, atol=[1e-18, 1e-15, 1e-18, 1e-16],
                            events=[crossing, turning] if inside else [crossing])
            if inside:
                F_peak = max([F_peak, k * max(sol.y[0, -1], 0.0) ** 1.5]
                             + [k * max(ye[0], 0.0) ** 1.5 for ye in sol.y_events[1]])
            if sol.status == 1 and sol.t_events[0].size:
                t, y = sol.t_events[0][0], sol.y_events[0][0].copy()
                y[0] = 0.0
                events.append(("separation" if inside else "onset", t, y[1]))
                if not inside and not y[1] > 0:   # grazed: stays out
                    y[0] = -1e-300
            else:
                t, y = t_end, sol.y[:, -1].copy()
        x2_ends.append(y[2])
    return dict(t=t, x1=max(y[0], 0.0), x=y[0] + y[2], x2=y[2], v=y[1], E_diss=y[3], F=k * max(y[0], 0.0) ** 1.5,
                F_peak=F_peak, events=events, x2_ends=x2_ends)


def check_driven_reference(j, case, r, solve):
    """The driven scene with v or m changed between steps, against scipy
    (driven_segments). Tolerance: scheme_tolerance with N the internal
    steps of the shortest contact (G1 restarts at each onset) and T the
    shortest stretch of contact between onsets, separations and the
    master's changes of v or m (each restarts the motion)."""
    p = params(case)
    v, m, segments = p["v"], p["m"], []
    for kind, arg in case["steps"]:
        if kind == "set":
            v, m = arg.get("v", v), arg.get("m", m)
        else:
            segments.append((v, m, arg))
    ref = driven_segments(segments, p["k"], p["c"])
    h = internal_step(case)
    starts = [sum(d for _, _, d in segments[:i]) for i in range(len(segments))]
    marks = sorted([(0.0, "onset", segments[0][0])] + [(t, kind, v) for kind, t, v in ref["events"]]
                   + [(t, "input", None) for t in starts[1:]] + [(ref["t"], "end", ref["v"])])
    contacts, stretches, inside, onset = [], [], False, 0.0
    for (t0, kind0, _), (t1, kind1, _) in zip(marks, marks[1:]):
        inside = kind0 == "onset" or (inside and kind0 == "input")
        onset = t0 if kind0 == "onset" else onset
        if inside:
            stretches.append(t1 - t0)
            if kind1 in ("separation", "end"):
                contacts.append(t1 - onset)
    tol = scheme_tolerance(min(contacts) / h, h, min(stretches))
    j.basis = f"scipy (DOP853, rtol 1e-12), rel {tol:.2g}"
    o = last(r)
    for key, want in [("F", ref["F"]), ("F_peak", ref["F_peak"]), ("x1", ref["x1"]), ("x2", ref["x2"]),
                      ("x", ref["x"]), ("E_diss", ref["E_diss"]), ("v_striker", ref["v"]),
                      ("F_avg", p["c"] * (ref["x2_ends"][-1] - ref["x2_ends"][-2]) / segments[-1][2])]:
        j.close(key, o[key], want, rel=tol, abs=0)
    separations = [i for i, mark in enumerate(marks) if mark[1] == "separation"]
    if separations:     # eps = -v at separation / v at its onset
        i = separations[-1]
        onset = max(e for e in range(i) if marks[e][1] == "onset")
        j.close("eps", o["eps"], -marks[i][2] / marks[onset][2], rel=tol, abs=0)


CHECKS = {"reference": check_reference, "constant rate": check_constant_rate, "rigid spring": check_rigid_spring,
          "elastic Hertz": check_elastic_hertz, "at rest": check_at_rest, "receding": check_free_flight,
          "never arrives": check_free_flight, "tiny impact": check_tiny_impact, "one long step": check_one_long_step,
          "driven reference": check_driven_reference}


# --- the report ---------------------------------------------------------------

def main(argv=None, prog=None):
    parser = output.parser(prog, __doc__)
    output.add_fmu(parser)
    output.add_solver(parser, "fraccontact-solve, for its --reference")
    args = output.parse(parser, argv)
    all_cases = list(cases())
    rows = []
    with tqdm(all_cases, file=sys.stderr, disable=None, bar_format=BAR) as bar:
        for name, c in bar:
            bar.set_description(name)
            r = run_case(args.fmu, c)
            rows.append((name, c, r, judge(name, c, r, str(args.solver))))
    bad = [(n, c, r, j) for n, c, r, j in rows if j.failures]
    expected, observed = {}, {}
    for _, c, r, _ in rows:
        expected[verdict_of(c)] = expected.get(verdict_of(c), 0) + 1
        observed[r["observed"]] = observed.get(r["observed"], 0) + 1
    out = ["# Hostile and degenerate input", "",
           "Regenerate: `scripts/report hostile` (`reports/hostile.py`; pytest runs the same cases and "
           "checks, "
           "`tests/test_hostile.py`). Each case runs through fmpy in a process of its own, over 2 ms of the h20 "
           "drop test unless stated, and states the verdict it must reach:", "",
           "- **refused when set** / **at initialization** (rules that depend on the scene, the mass or the "
           "dashpot) / **by the step** (a documented rule of `fmi2DoStep`): `fmi2Error`, a log message naming "
           "the variable or argument and its value (quoted below), the old value or state kept, and the "
           "instance usable afterwards (it initializes and takes ten steps with finite outputs);",
           "- **runs**: every output finite at every communication point, F >= 0, and agreement with something "
           "independent of the FMU, named in the last column: the GSL reference (`fraccontact-solve --reference"
           " --json`, same parameters) or scipy, at a relative tolerance from the scheme's error, "
           "2 (1/N + (h/T)^2) (the G1 law's 3/(8n) weighed over a contact of N internal steps h up to the "
           "force's peak, SDIRK2's (h/T)^2 on the time scale T, twice over); a closed form; or, where no "
           "reference resolves the case, the identities of momentum (m v + c x2 = m v0) and energy (not "
           "created). Every run also meets F = Gamma(5/2) k semi_integral, F_avg H = c (x2's increase) and, "
           "in contact, x = x1 + x2.", "",
           f"**{len(rows) - len(bad)} of {len(rows)} cases reach their verdict.** Expected: "
           + ", ".join(f"{n} {v}" for v, n in expected.items()) + ". Observed: "
           + ", ".join(f"{n} {v}" for v, n in observed.items()) + ".", "",
           "| case | expected | why | observed | message or check |", "|---|---|---|---|---|"]
    for name, c, r, j in rows:
        if r["observed"] != RUNS:
            detail = r.get("message", "")
        else:
            detail = j.basis + (f"; {j.worst[1]}" if j.worst else "; exact")
        if j.failures:
            detail = f"**FAIL: {j.failures[0]}**" + (f" (+{len(j.failures) - 1} more)" if len(j.failures) > 1
                                                      else "") + f"; {detail}"
        expect = verdict_of(c) + (f" ({c['expect']})" if verdict_of(c) == RUNS else "")
        cells = [name, expect, c["why"], r["observed"], str(detail)]
        out.append("| " + " | ".join(s.replace("|", "/") for s in cells) + " |")
    atomic.write_text((args.out / "reliability_hostile.md"), "\n".join(out) + "\n")
    print(f"{len(rows) - len(bad)} passed, {len(bad)} failed")
    for name, c, r, j in bad:
        print(f"FAILED {name}: expected {verdict_of(c)}, observed {r['observed']}: {'; '.join(j.failures[:3])}"
              f" [{r.get('message', '')}]")
    return 1 if bad else 0

