"""The dashpot's study: a matrix of cases from the paper's h20 test, each run
with the G1 law and the Hertz law in fixed discrete-gradient steps and "adaptive" (the
Hertz law, error-controlled steps), every run checked for what holds at any
step and against the GSL reference at the scheme's own error; and the
convergence study that measures the constants those tolerances use."""

import dataclasses
import functools
import math

from fraccontact import hertz, model, solver

from .core import ENERGY, EPS, H20, RESOLVED, judge, rounding, t_end_of

# The paper's h20 test; a case changes some of these (v0 is the library's v, dt its dt_max).
BASE = dict(c=H20["c"], E_s=H20["E_s"], v0=H20["v"], m=H20["m"], dt=model.step_limit(), g1_nodes=0, gap0=0.0, g=0.0,
            impacts=1)
QUANTITIES = ("F_peak", "eps", "t_contact", "x2", "E_diss", "v")
# Reference comparison, |error| <= C2 (dt/T)^2 [+ D1 dt/T for the G1 law
# with N = steps since onset] + the reference's own error + rounding, T = t_F
# for F_peak and E_diss and t_c for the rest (see scales(), time_scale()).
# Errors: F_peak, t_contact, x2 and E_diss relative, eps absolute, v (at the end)
# over the impact speed.
# The fixed step is second order: C2 is twice the largest error / (dt/T)^2 the
# convergence study measures over every regime and every dt from T/20 to
# T/640 (docs/stability.md, "Convergence study"; the regimes' constants
# differ by orders of magnitude, so the tolerance is tight for some cases
# and loose for others, the stiff ones above all: the report lists each
# run's error over its tolerance).
C2 = dict(F_peak=0.5, eps=1.3, t_contact=2.1, x2=2.4, E_diss=4.4, v=1.3)
# The G1 law with N = n steps since onset is Hertz with the stiffness
# k (1 + 3/(8n) + O(n^-2)) (docs/model.md §4): at time t the relative error is
# 3 dt / (8 t), a first-order error in dt/T. For the elastic peak force,
# F_max ~ K^(2/5) with the error 3/(8n) at the peak, n = t_c / (2 dt), gives
# D ~ 0.4 * 0.75 = 0.30. D1 is twice the largest the convergence study
# measures, which the G1 errors approach from below as dt falls.
D1 = dict(F_peak=0.55, eps=1.2, t_contact=0.82, x2=1.9, E_diss=1.7, v=1.2)
# The reference at rtol 1e-13; its own error is bounded by its distance to
# the solve at rtol 1e-12 (the error of either scales with rtol: the distance
# is about 10 times the error of the rtol 1e-13 solve).
REF_RTOLS = (1e-13, 1e-12)
# Known findings: (case, law) -> the checks that fail there, properties of
# the time scheme reported in docs/stability.md, not allowances: a run
# listed here must still fail exactly these checks (a fix shows up as a
# failure of this script: remove the entry), and a run not listed must pass
# every check. The fixed step never creates energy (docs/model.md §11), so
# none is listed.
FORCE = "F <= c v_max"
CHECKS = ("finite", "no tension", EPS, "momentum", ENERGY, FORCE, "reference")
KNOWN = {}
# The force's bound of a fixed step: n + 1 times the model's c v_max. The
# step's mean force F exceeds c v only where x1 falls over the step, so it
# stays below the larger of c v_max and the force at the step's start, and
# the spring's force at its end is at most n + 1 times the mean where x1
# rises (docs/model.md §11): across a dashpot too stiff for the step the
# elastic indentation rings about its quasi-static value, and the force at
# the steps' ends with it, while the mean force, which moves the striker,
# stays that of the dashpot.
FIXED_FORCE = H20["spring_exponent"] + 1.0
# The adaptive variant: law 2 (Hertz) with tolerance = 1e-6 and
# the case's dt as the cap dt_max. No run of it fails a check
# (docs/stability.md, "Adaptive steps"), so KNOWN lists none: a failure
# there is new.
ADAPTIVE = "adaptive"
ADAPTIVE_TOLERANCE = 1e-6
LAWS = ("g1", "hertz", ADAPTIVE)
# Its reference tolerance is the error control's, not the fixed scheme's
# C2 (dt/T)^2: every accepted step's embedded error estimate is below
# `tolerance` relative to the elastic indentation L (the larger of x1 and
# x1 at the contact's peak force) for x1 and x2 and relative to the speed S
# (the larger of |v| and v_onset) for v (model/esdirk54.c,
# esdirk_step), and the separation is located to a tenth of the tolerance
# of the contact time. The 5th-order solution is propagated, whose local
# error is below the 4th-order estimate's, and over an impact (at most half
# a damped oscillation) the motion hardly amplifies errors, so a figure's
# error is about the sum of the local errors at most: K (accepted steps) x
# tolerance, + the reference's own error + rounding, with K the figure's
# sensitivity to a relative error in x1, x2 or v: F_peak = K x1^(3/2), 1.5;
# eps = |v_sep|/v_onset and v over the impact speed, 1; x2 over itself, 1
# (its error per step is below tol L and, through the momentum invariant
# c x2 = m dv, below tol m S/c, and x2 is at least about the smaller of
# them); E_diss = integral of F^2/c, twice F's 1.5 (it is the 5th-order
# quadrature of F^2/c over the stages, not itself estimated); t_contact, 1
# (the separation's shift by x1's error, x1 err/|v_sep| over t_c, is L/(eps
# V t_c) = 0.34/eps of it in an elastic Hertz impact: the low-eps cases run
# many capped steps, far below the bound). "steps" (the solver's JSON, the
# library's Run.steps) counts the accepted internal steps including the
# free flight (exact, no error), so the bound is loose where flight or a
# cap dt_max far below the step the tolerance allows dominate (a capped
# step errs by ~ (dt_max/h)^5 of the tolerance). Each figure's largest
# error over it: docs/stability.md, "Adaptive steps".
ADAPTIVE_K = dict(F_peak=1.5, eps=1.0, t_contact=1.0, x2=1.0, E_diss=3.0, v=1.0)
# The energy check with adaptive steps needs the error control's term too:
# the fixed scheme's dissipation per step is J^2/(c h) (J the step's
# impulse: the mean force's work at the mean dashpot rate), the adaptive E_diss the
# stages' quadrature sum b_j F_j^2 / c (Kvaerno's weights b_3, b_4 < 0),
# whose error, like every figure's, has either sign. The energy's error per
# step: m v dv + F dx1 + dE_diss <= tol (m S^2 + F_peak L + F_peak L)
# (dE_diss as the work F dx2 of x2's error), with m S^2 = 2 x the kinetic
# energy and F_peak L = K L^(5/2) = 5/2 x the elastic energy at the peak, each
# at most the energy that came in: at most 7 tol of it per step, so the
# check allows 7 (steps) x tolerance of that energy on top of rounding (the
# runs that would fail without this term are listed in docs/stability.md).
# Loose, as the figures' bound: a per-step bound summed over every step.
ADAPTIVE_ENERGY = 7.0


def hertz_k(E_s):
    return hertz.k_from_materials(H20["R"], H20["E_i"], H20["nu_i"], E_s, H20["nu_s"])


def g1_ratio(N):
    """Gamma(N + 3/2) / (Gamma(N) N^(3/2)), the G1 law's stiffness over
    Hertz's on N intervals (docs/model.md §4); >= 1 for every N."""
    return math.exp(math.lgamma(N + 1.5) - math.lgamma(N) - 1.5 * math.log(N))


def scales(case, law="hertz"):
    """The case's scales with the law's spring (k, or k Gamma(N+3/2)/
    (Gamma(N) N^(3/2)) for the G1 law with N fixed): the Hertz contact time
    t_c, the force's rise time t_F = min(t_c, t_q) where the dashpot takes
    over the loading within t_q = (c v / K)^(2/3) / v (the time to reach the
    indentation at which the spring carries the dashpot's force c v; the
    dashpot's relaxation time there is 2 t_q / 3), the velocity scale V (the
    impact speed) and the indentation x_max. At rest under gravity: the time
    gravity takes to load the spring, and the speed of that."""
    K = hertz_k(case["E_s"])
    if law == "g1" and case["g1_nodes"] > 0:
        K *= g1_ratio(case["g1_nodes"])
    v = math.sqrt(case["v0"] ** 2 + 2 * case["g"] * case["gap0"])
    if v == 0.0:
        g = max(case["g"], 1e-9)
        x = (case["m"] * g / K) ** (2 / 3)
        t_c = math.sqrt(x / g)
        return dict(K=K, t_c=t_c, t_F=t_c, V=x / t_c, x_max=x, v=0.0)
    x = hertz.indentation(K, case["m"], v)
    t_c = hertz.contact_time(K, case["m"], v)
    t_q = (case["c"] * v / K) ** (2 / 3) / v
    return dict(K=K, t_c=t_c, t_F=min(t_c, t_q), V=v, x_max=x, v=v)


def matrix():
    """(name, case) pairs: one-at-a-time sweeps from the paper's h20 test,
    the extremes' corners, and special scenes."""
    out = []
    sweeps = dict(c=[1e-2, 1.0, 1e2, 1e3, 1e5, 1e7, 1e9], E_s=[1e6, 1e7, 1e8, 7e10, 2.1e11],
                  v0=[1e-4, 1e-3, 1e-2, 0.1, 3.0, 10.0, 30.0], m=[1e-3, 1e-2, 0.1, 10.0, 100.0, 1000.0],
                  dt=[1e-9, 1e-8, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2], g1_nodes=[1, 10, 1000, 1000000])
    for key, values in sweeps.items():
        for value in values:
            out.append((f"{key} = {value:g}", dict(BASE, **{key: value})))
    for c in (1e-2, 1e9):
        for E_s in (1e6, 2.1e11):
            for v0 in (1e-4, 30.0):
                for m in (1e-3, 1000.0):
                    for dt in (1e-7, 1e-2):
                        out.append((f"corner c {c:g}, E_s {E_s:g}, v0 {v0:g}, m {m:g}, dt {dt:g}",
                                    dict(BASE, c=c, E_s=E_s, v0=v0, m=m, dt=dt)))
    out += [("zero velocity, no gravity", dict(BASE, v0=0.0)),
            ("zero velocity, gravity", dict(BASE, v0=0.0, g=9.81)),
            ("gap 1 mm", dict(BASE, gap0=1e-3)),
            ("gap 1 mm, gravity", dict(BASE, gap0=1e-3, g=9.81)),
            ("repeated impacts with gravity (5)", dict(BASE, g=9.81, impacts=5)),
            ("repeated impacts with gravity (5), dt 1e-5", dict(BASE, g=9.81, impacts=5, dt=1e-5))]
    return out


FAST = {"c = 0.01", "c = 1e+09", "E_s = 1e+06", "E_s = 2.1e+11", "v0 = 0.0001", "v0 = 30", "m = 0.001",
        "m = 1000", "dt = 1e-09", "dt = 0.01", "g1_nodes = 1e+06", "zero velocity, gravity", "gap 1 mm, gravity",
        "repeated impacts with gravity (5), dt 1e-5",
        "corner c 1e+09, E_s 2.1e+11, v0 30, m 0.001, dt 0.01", "corner c 0.01, E_s 1e+06, v0 0.0001, m 1000, dt 1e-07"}


def _key(case, law, t_end):
    return (law,) + tuple(sorted(case.items())) + (t_end,)


def run_figures(out):
    """A run (fraccontact.impact's, or the solver's JSON, named alike) as its
    figures: the FMU's outputs where it stopped (F_peak the largest, eps and
    t_contact the last impact's, E_diss in all, x, x1, x2, v, t), its counts
    and every impact."""
    return dict(out["end"], **{key: out[key] for key in ("impacts", "stopped", "steps", "k", "per_impact")})


@functools.lru_cache(maxsize=None)
def _solve(program, key, rtol):
    law, items, t_end = key[0], dict(key[1:-1]), key[-1]
    params = dict(law=law, k=0.0, E_s=items["E_s"], c=items["c"], v=items["v0"], m=items["m"], dt_max=items["dt"],
                  g1_nodes=items["g1_nodes"], gap0=items["gap0"], g=items["g"], impacts=items["impacts"], t_end=t_end)
    if law == ADAPTIVE:  # the Hertz law, error-controlled steps capped by the case's dt
        params.update(law="hertz", tolerance=ADAPTIVE_TOLERANCE)
    try:
        if not rtol:
            return run_figures(dataclasses.asdict(model.impact(**params))), ""
        options = [x for name, value in params.items() for x in ("--" + name.replace("_", "-"), value)]
        return run_figures(solver.solve(*options, "--reference", "--rtol", rtol, program=program, timeout=1800)), ""
    except (ValueError, RuntimeError) as e:  # solver.Failed is a RuntimeError
        return None, str(e)


def solve(program, case, law, t_end, rtol=None):
    """The run in-process on the library (or fraccontact-solve's reference at
    rtol), or (None, why). Runs are cached: the G1 law with N = steps and the
    Hertz law share one reference (the continuous limit), whatever the step;
    the adaptive variant (the Hertz law, error-controlled) shares it too."""
    if rtol:
        if (law == "g1" and case["g1_nodes"] == 0) or law == ADAPTIVE:
            law = "hertz"
        if law == "hertz":
            case = dict(case, g1_nodes=0)
        case = dict(case, dt=BASE["dt"])  # the reference does not step
    return _solve(str(program), _key(case, law, t_end), rtol)


def deviations(r, ref, sc):
    """The errors of r against ref: F_peak, t_contact, x2, E_diss
    relative, eps absolute, v at the end over the velocity scale; eps and t_contact
    only when both ended the same number of impacts."""
    d = {}
    if ref["F_peak"] > 0:
        d["F_peak"] = abs(r["F_peak"] / ref["F_peak"] - 1)
    if r["impacts"] == ref["impacts"] > 0:
        d["eps"] = abs(r["eps"] - ref["eps"])
        d["t_contact"] = abs(r["t_contact"] / ref["t_contact"] - 1)
    if ref["x2"] != 0:
        d["x2"] = abs(r["x2"] / ref["x2"] - 1)
    if ref["E_diss"] > 0:
        d["E_diss"] = abs(r["E_diss"] / ref["E_diss"] - 1)
    if sc["V"] > 0:
        d["v"] = abs(r["v"] - ref["v"]) / sc["V"]
    return d


def reference_of(program, case, law, t_end, sc):
    """The reference at the tighter rtol and, per quantity, a bound on its
    own error (its distance to the looser one), or (None, None, why)."""
    fine, err = solve(program, case, law, t_end, REF_RTOLS[0])
    coarse, err2 = solve(program, case, law, t_end, REF_RTOLS[1])
    if fine is None or coarse is None:
        return None, None, err or err2
    return fine, deviations(coarse, fine, sc), ""


# The time scale each figure needs resolved: the force's rise t_F for the
# peak force and for the dissipation (the integral of F^2/c: a step across
# a stiff dashpot's force rise misplaces F^2, though not the impulse), the
# contact time t_c for the rest (set by the impulse).
FAST_FIGURES = ("F_peak", "E_diss")


def time_scale(sc, q):
    return sc["t_F"] if q in FAST_FIGURES else sc["t_c"]


def resolution(case, sc, q):
    """dt / T for quantity q (T from time_scale)."""
    return case["dt"] / time_scale(sc, q)


def tolerance(case, law, q, h, steps, floor):
    """The reference tolerance of figure q: the fixed scheme's C2 h^2 [+ D1
    h for the G1 law with N = steps], h = dt/T, or the adaptive variant's
    ADAPTIVE_K (steps) x tolerance; + floor (the reference's own error) +
    rounding."""
    if law == ADAPTIVE:
        tol = ADAPTIVE_K[q] * steps * ADAPTIVE_TOLERANCE
        return tol + floor + rounding(steps)
    tol = C2[q] * h * h
    if law == "g1" and case["g1_nodes"] == 0:
        tol += D1[q] * h
    return tol + floor + rounding(steps)


def invariants(case, r, law=None):
    """The checks that hold at any step: {check: failure text or ''}, and
    the figures they measured. With law ADAPTIVE the energy check allows the
    error control's ADAPTIVE_ENERGY (steps) x tolerance of the energy too."""
    out, fig = {}, {}
    m, c, g, v0, gap0 = case["m"], case["c"], case["g"], case["v0"], case["gap0"]
    rnd = rounding(r["steps"])
    method = ADAPTIVE_ENERGY * r["steps"] * ADAPTIVE_TOLERANCE if law == ADAPTIVE else 0.0
    k = r["k"]  # the Hertz constant: the G1 laws' stiffness is never below it
    impacts = r.get("per_impact", [])
    # No tension: the force is K x1^(3/2), x1 >= 0.
    low = min([r["F_peak"], r["x1"]] + [i["F_peak"] for i in impacts])
    out["no tension"] = "" if low >= 0 else f"negative force or indentation {low:.3g}"
    # 0 <= eps <= 1: with g = 0 eps <= 1 is energy conservation (below); under
    # gravity an impact may gain gravity's work m g dx2, so only eps >= 0.
    bad = [i["eps"] for i in impacts if i["eps"] < 0 or (g == 0 and i["eps"] > 1 + rnd)]
    out[EPS] = "" if not bad else f"eps = {bad[0]:.17g}"
    # Momentum: m v + c x2 - m g t is kept exactly by the fixed step (m dv
    # = -h F = -c dx2), any Runge-Kutta method (a linear invariant) and
    # exact free flight: to rounding.
    terms = [m * v0, m * r["v"], m * g * r["t"], c * r["x2"]]
    residual = m * (v0 - r["v"]) + m * g * r["t"] - c * r["x2"]
    scale = sum(abs(t) for t in terms)
    fig["momentum"] = abs(residual) / scale if scale else abs(residual)
    out["momentum"] = "" if abs(residual) <= rnd * scale else f"momentum off by {fig['momentum']:.2e}"
    # No energy created: kinetic + elastic (at least 2/5 k x1^(5/2)) +
    # dissipated <= kinetic at start + gravity's work, to rounding only (and,
    # with adaptive steps, the error control's `method` of that energy).
    E_kin0, W_g = 0.5 * m * v0 ** 2, m * g * (r["x"] + gap0)
    E_out = 0.5 * m * r["v"] ** 2 + 0.4 * k * r["x1"] ** 2.5 + r["E_diss"]
    created, scale = E_out - (E_kin0 + W_g), E_out + E_kin0 + abs(W_g)
    fig["energy"] = created / (E_kin0 + W_g) if E_kin0 + W_g > 0 else created
    # (where, created, allowed for rounding, energy in): the run, then each finished impact
    # (1/2 m (eps v_on)^2 + E_diss,i <= 1/2 m v_on^2 + m g dx2,i).
    balances = [("run", created, rnd * scale, E_kin0 + W_g)]
    x2 = 0.0
    for n, i in enumerate(impacts, 1):
        E_on, W = 0.5 * m * i["v_onset"] ** 2, m * g * (i["x2_end"] - x2)
        E_end = 0.5 * m * (i["eps"] * i["v_onset"]) ** 2 + i["E_diss"]
        balances.append((f"impact {n}", E_end - (E_on + W), rnd * (E_end + E_on + abs(W)), E_on + W))
        x2 = i["x2_end"]
    why, beyond = [], []
    for where, gain, allowed, energy in balances:
        if not gain > allowed:
            continue
        text = f"{where}: {gain / energy:.3g} of {'the' if where == 'run' else 'its'} energy"
        if gain > allowed + method * abs(energy):
            why.append(text)
        elif method:  # beyond rounding, within the error control's bound
            beyond.append(f"{text} ({gain / (method * abs(energy)):.2g} of the bound)")
    if method:
        fig["energy_beyond_rounding"] = beyond
    out[ENERGY] = "; ".join(why)
    # F <= c v_max: the force grows only while x1' = v - F/c > 0, so it never
    # exceeds c times the largest velocity (v_onset + g t_contact in an
    # impact; v + g t_end over the run); a fixed step's, FIXED_FORCE times
    # that. fig['force'] is F_peak over c v_max, less 1.
    g_plus, factor = max(g, 0.0), 1.0 if law == ADAPTIVE else FIXED_FORCE
    bounds = [(r["F_peak"], c * (math.sqrt(v0 ** 2 + 2 * g_plus * gap0) + g_plus * r["t"]))]
    bounds += [(i["F_peak"], c * (i["v_onset"] + g_plus * i["t_contact"])) for i in impacts]
    over = max(F / b - 1 if b > 0 else (math.inf if F > 0 else 0.0) for F, b in bounds)
    fig["force"] = over
    out[FORCE] = "" if over <= factor * (1 + rnd) - 1 else f"F_peak {over:.3g} above c v_max, more than {factor:g} c v_max"
    return out, fig


def check(program, case, law, name=None):
    """Runs one case with one law; returns the figures and every check's
    outcome: row['checks'][check] is '' (pass), a failure text, or None (not
    applicable); row['failures'] lists the failures. Given the case's name,
    row['known'] lists the failures KNOWN for it and row['unexpected'] the
    other failures and the known ones that no longer fail."""
    sc = scales(case, law)
    t_end = t_end_of(case, sc["t_c"])
    row = dict(law=law, t_c=sc["t_c"], t_F=sc["t_F"], h=case["dt"] / sc["t_c"], h_F=case["dt"] / sc["t_F"],
               checks={}, failures=[])
    r, err = solve(program, case, law, t_end)
    if r is None:
        row["checks"]["finite"] = f"solver failed: {err}"
    else:
        row.update(r)
        values = [r[k] for k in ("F_peak", "eps", "t_contact", "x2", "E_diss", "v", "x", "x1")]
        row["checks"]["finite"] = "" if all(math.isfinite(v) for v in values) else "non-finite output"
    if row["checks"]["finite"]:
        row["failures"] = [f"finite: {row['checks']['finite']}"]
        return row
    inv, fig = invariants(case, r, law)
    row["checks"].update(inv)
    row.update(fig)
    # The reference, for each figure whose time scale the step resolves.
    ref, floor, err = reference_of(program, case, law, t_end, sc)
    if ref is None:
        row["checks"]["reference"] = f"reference failed: {err}"
    else:
        dev = deviations(r, ref, sc)
        row["deviation"] = max(dev.items(), key=lambda kv: kv[1], default=("", 0.0))
        compared = {}
        for q, e in dev.items():
            h = resolution(case, sc, q)
            if h <= 1.0 / RESOLVED or law == ADAPTIVE:  # the error control resolves at any cap
                compared[q] = (e, tolerance(case, law, q, h, r["steps"], floor.get(q, 0.0)))
        row["compared"] = compared
        if not compared:
            row["checks"]["reference"] = None
        else:
            worst = max(compared, key=lambda q: compared[q][0] / compared[q][1])
            row["ratio"] = (worst, compared[worst][0] / compared[worst][1])
            why = [f"{q} off by {e:.3g} > {t:.3g}" for q, (e, t) in compared.items() if e > t]
            if (r["impacts"], r["stopped"]) != (ref["impacts"], ref["stopped"]) and \
                    (case["dt"] <= sc["t_c"] / RESOLVED or law == ADAPTIVE):
                why.insert(0, f"{r['impacts']} impacts ({r['stopped']}) vs the reference's {ref['impacts']} "
                              f"({ref['stopped']})")
            row["checks"]["reference"] = "; ".join(why)
    judge(row, None if name is None else KNOWN.get((name, law), set()),
          ("known finding no longer fails", "(remove it from KNOWN)"))
    return row


# The convergence study: the constants C2 and D1 measured.

CONVERGENCE = [("elastic, c = 1e9", dict(BASE, c=1e9)),
               ("c = 1e5", dict(BASE, c=1e5)),
               ("h20, c = 6080", dict(BASE)),
               ("c = 1000", dict(BASE, c=1e3)),
               ("c = 100, no rebound", dict(BASE, c=1e2)),
               ("c = 1, stiff", dict(BASE, c=1.0)),
               ("N = 1 fixed", dict(BASE, g1_nodes=1)),
               ("gravity, 5 impacts", dict(BASE, g=9.81, impacts=5)),
               ("at rest, gravity", dict(BASE, v0=0.0, g=9.81))]
LADDER = [RESOLVED * 2 ** k for k in range(6)]  # dt = T/20 ... T/640
FAST_CONVERGENCE = {"h20, c = 6080"}


def convergence(program, name, case, law):
    """Errors against the reference on the ladder dt = T/20 ... T/640 (T
    from time_scale: t_F for F_peak and E_diss, t_c for the rest): per quantity the largest error over
    (dt/T)^2 (or over dt/T for the G1 law with N = steps), the order of the
    finest pair, and the failures: a constant above C2 (D1), an order below
    1.9 (second order; above is fine: eps converges faster in nearly
    elastic impacts), or a G1 order off 1 by more than 0.1."""
    sc = scales(case, law)
    t_end = t_end_of(case, sc["t_c"], capped=False)
    first = law == "g1" and case["g1_nodes"] == 0
    ref, floor, err = reference_of(program, case, law, t_end, sc)
    out = dict(name=name, law=law, constants={}, orders={}, failures=[])
    if ref is None:
        out["failures"].append(f"reference failed: {err}")
        return out
    for q in QUANTITIES:
        T = time_scale(sc, q)
        errors = []
        for n in LADDER:
            r, err = solve(program, dict(case, dt=T / n), law, t_end)
            if r is None:
                out["failures"].append(f"{q}, dt = T/{n}: {err}")
                break
            e = deviations(r, ref, sc).get(q)
            if e is None:
                break
            errors.append((1.0 / n, e, floor.get(q, 0.0) + rounding(r["steps"])))
        if len(errors) < len(LADDER):
            continue
        const = max(e / (h if first else h * h) for h, e, _ in errors)
        out["constants"][q] = const
        limit = (D1 if first else C2)[q]
        if const > limit:
            out["failures"].append(f"{q}: constant {const:.3g} above the {limit} the matrix uses")
        (h1, e1, f1), (h2, e2, f2) = errors[-2:]
        if e2 > 100 * f2:  # above the floor of reference error and rounding
            order = math.log2(e1 / e2)
            out["orders"][q] = order
            if (first and abs(order - 1) > 0.1) or (not first and order < 1.9):
                out["failures"].append(f"{q}: order {order:.3f}")
    return out
