"""Fractional damping: the springpot F = c_alpha D^alpha x2
against the dashpot on the paper's drop test. Force curves and hysteresis
loops for alpha from 0.1 to 1; restitution and peak force against drop height
(5 to 100 mm); the dent's recovery after separation and the second contact
under gravity; cost per internal step and FMU state size of both memories;
the compressed memory's error against its number of modes. Everything is
measured by this run, in-process on the C library and through the FMU.
Writes docs/fractional_damping.md and docs/fractional_damping_*.png.

Regenerate: scripts/report fractional_damping   (about 40 s of CPU)
"""

import json
import math
import os
import time

import numpy as np

import matplotlib.ticker

from fraccontact import atomic, model, output, solver
from fraccontact.fmu import Slave, unpacked

plt = output.pyplot()

H20 = model.defaults()
M, V0, C = H20["m"], H20["v"], H20["c"]
ALPHAS = (0.1, 0.25, 0.5, 0.75, 0.9, 1.0)            # the force curves
RULE_ALPHAS = (0.1, 0.25, 0.5, 0.75, 0.9)            # the height sweep, c_alpha by the frequency rule
MATCH_ALPHAS = (0.5, 0.75, 0.9)                      # the height sweep, c_alpha matched to the dashpot's eps
RECOVERY_ALPHAS = (0.25, 0.5, 0.75)
HEIGHTS = np.round(np.arange(5, 101, 5) * 1e-3, 6)   # the paper's campaign [m]
TOLERANCES = [10.0 ** -e for e in range(2, 13)]
KERNEL_ALPHAS = (0.25, 0.5, 0.75)
SPAN = 1e3                                           # the compressed kernel's span (CONTACT_MEMORY_SPAN) [s]
PUBLISHED = {1e-6: (32, 37, 48, 59), 1e-9: (45, 53, 69, 85), 1e-12: (58, 68, 90, 111)}  # docs/model.md §6
PUBLISHED_RATIOS = (1e-3, 1e-4, 1e-6, 1e-8)
COST_STEPS = (1e3, 3e3, 1e4, 3e4, 1e5)               # internal steps of one impact, for the cost per step
LADDER = (8e-7, 4e-7, 2e-7, 1e-7)                    # dt_max of the memory-1 reference (N <= 14 000)
COMPRESSED_LADDER = tuple(8e-7 / 2 ** i for i in range(10))  # the compressed memory alone: to 1.6e-9 s
ORDER_FLOOR = 1.2e-8                                 # below it the compressed memory's error nears its reference's
STIFF = 100.0                                        # c and c_alpha times this: the lightly damped limit


# ------------------------------------------------------------ pure helpers

def c_alpha_rule(alpha, omega, c=C):
    """The springpot as damping as the dashpot c at the frequency omega: its
    dynamic stiffness c_alpha omega^alpha equals c omega."""
    return c * omega ** (1.0 - alpha)


def _power_difference(u0, u1, p):
    """u0^p - u1^p for u0 >= u1 >= 0, without cancellation when u0 ~ u1."""
    u0, u1 = np.broadcast_arrays(np.asarray(u0, float), np.asarray(u1, float))
    out = np.power(u0, p)
    pos = u1 > 0
    base = np.where(pos, u1, 1.0)
    out = np.where(pos, np.power(base, p) * np.expm1(p * np.log1p((u0 - u1) / base)), out)
    return out


def riemann_liouville(ts, F, alpha, at):
    """The Riemann-Liouville integral of order alpha of the piecewise-linear
    interpolant of the samples (ts, F) (0 outside them) at the times `at`,
    each >= ts[-1]: 1/Gamma(alpha) int (t - s)^(alpha-1) F(s) ds, exact for
    the interpolant (product integration)."""
    ts, F = np.asarray(ts, float), np.asarray(F, float)
    at = np.atleast_1d(np.asarray(at, float))
    if np.any(at < ts[-1]):
        raise ValueError("riemann_liouville: every time must be at or after the last sample")
    s0, s1 = ts[:-1], ts[1:]
    h = s1 - s0
    keep = h > 0
    s0, s1, h, F0, F1 = s0[keep], s1[keep], h[keep], F[:-1][keep], F[1:][keep]
    slope = (F1 - F0) / h
    out = np.empty(len(at))
    for i, t in enumerate(at):
        u0, u1 = t - s0, t - s1
        P0 = _power_difference(u0, u1, alpha) / alpha               # int u^(alpha-1) du over [u1, u0]
        P1 = _power_difference(u0, u1, alpha + 1.0) / (alpha + 1.0)  # int u^alpha du
        # F(s) = F0 + slope (s - s0) = F0 + slope (u0 - u)
        out[i] = np.sum(F0 * P0 + slope * (u0 * P0 - P1)) / math.gamma(alpha)
    return out


def exact_kernel(tau, alpha):
    """The springpot's kernel tau^(-alpha)/Gamma(1 - alpha) (docs/model.md §6)."""
    return np.power(tau, -alpha) / math.gamma(1.0 - alpha)


def kernel_error(a, b, alpha, lo, hi, per_decade=400):
    """The largest relative error of sum_i a_i exp(-b_i tau) against the exact
    kernel over tau in [lo, hi], on a logarithmic grid."""
    tau = np.logspace(math.log10(lo), math.log10(hi), int(per_decade * math.log10(hi / lo)) + 1)
    approx = np.exp(-np.outer(tau, b)) @ a
    return float(np.max(np.abs(approx / exact_kernel(tau, alpha) - 1.0)))


def energy_balance(r):
    """E_diss against the striker's lost kinetic energy, relative (g = 0)."""
    return r.E_diss / (0.5 * M * r.v_onset ** 2 * (1 - r.eps ** 2)) - 1


def log_slope(x, y):
    """The least-squares slope of ln y against ln x."""
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


def rel(a, b):
    return abs(a / b - 1.0)


def cpu_with_children():
    """CPU seconds of this process and its finished children (the bench)."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


def cpu_seconds(fn):
    t0 = time.process_time()
    value = fn()
    return time.process_time() - t0, value


# ------------------------------------------------------------ measurements

def frequency():
    """omega = pi / t_contact of the dashpot's h20 impact."""
    return math.pi / model.impact().t_contact


def curves(omega):
    """Section 1: the h20 impact for every alpha (c_alpha by the frequency
    rule) and the dashpot; the time series and the figures."""
    out = {}
    for alpha in ALPHAS:
        s = model.simulate(output_interval=2e-6, damper=2, damper_order=alpha, c_alpha=c_alpha_rule(alpha, omega))
        out[alpha] = s
    out["dashpot"] = model.simulate(output_interval=2e-6)
    return out


def alpha_one_against_dashpot():
    """The springpot at alpha = 1 (c_1 = c) against the dashpot, every internal step."""
    sp = model.simulate(output_interval=0, damper=2, damper_order=1.0, c_alpha=C)
    da = model.simulate(output_interval=0)
    n = min(len(sp["t"]), len(da["t"]))
    dF = float(np.max(np.abs(sp["F"][:n] - da["F"][:n])) / da["run"].F_peak)
    return dict(rows=(len(sp["t"]), len(da["t"])), dF=dF, F_peak=rel(sp["run"].F_peak, da["run"].F_peak),
                eps=rel(sp["run"].eps, da["run"].eps))


def matched_c_alpha(alphas, target):
    """c_alpha per alpha giving the dashpot's eps at h20: bisection in log c_alpha
    (eps rises with c_alpha), all alphas in one batch per iteration."""
    alphas = np.asarray(alphas, float)
    lo, hi = np.full(len(alphas), 1e2), np.full(len(alphas), 1e10)
    for _ in range(60):
        mid = np.sqrt(lo * hi)
        e = model.impacts(height=0.020, damper=2, damper_order=alphas, c_alpha=mid)["eps"]
        lo, hi = np.where(e < target, mid, lo), np.where(e < target, hi, mid)
    return np.sqrt(lo * hi)


def height_row(name, alpha, c_alpha, r):
    eps, F = r["eps"], r["F_peak"]
    i20 = int(np.flatnonzero(np.isclose(HEIGHTS, 0.020))[0])
    return dict(name=name, alpha=alpha, c_alpha=c_alpha, eps=eps, F_peak=F, eps5=eps[0], eps20=eps[i20],
                eps100=eps[-1], spread=eps[0] - eps[-1], loss_ratio=(1 - eps[-1]) / (1 - eps[0]),
                loss_slope=log_slope(HEIGHTS, 1 - eps), F_slope=log_slope(HEIGHTS, F),
                light=(2.0 - alpha) / 10.0)


def heights(omega):
    """Section 2: eps and F_peak over the campaign's heights."""
    dash = model.impacts(height=HEIGHTS)
    target = float(dash["eps"][np.isclose(HEIGHTS, 0.020)][0])
    rows = {"dashpot": height_row("dashpot", 1.0, C, dash)}
    rule = {}
    for alpha in RULE_ALPHAS:
        ca = c_alpha_rule(alpha, omega)
        rule[alpha] = height_row(f"springpot {alpha:g}, rule", alpha, ca,
                                 model.impacts(height=HEIGHTS, damper=2, damper_order=alpha, c_alpha=ca))
    matched = {}
    for alpha, ca in zip(MATCH_ALPHAS, matched_c_alpha(MATCH_ALPHAS, target)):
        matched[alpha] = height_row(f"springpot {alpha:g}, matched", alpha, float(ca),
                                    model.impacts(height=HEIGHTS, damper=2, damper_order=alpha, c_alpha=ca))
    stiff = {"dashpot": height_row(f"dashpot, c x {STIFF:g}", 1.0, C * STIFF,
                                   model.impacts(height=HEIGHTS, c=C * STIFF))}
    for alpha in (0.1, 0.5):
        ca = c_alpha_rule(alpha, omega) * STIFF
        stiff[alpha] = height_row(f"springpot {alpha:g}, rule x {STIFF:g}", alpha, ca,
                                  model.impacts(height=HEIGHTS, damper=2, damper_order=alpha, c_alpha=ca))
    # How far eps can fall at all: c_alpha -> 0 (or a rigid spring) leaves the
    # springpot alone, a linear element whose eps depends on alpha only.
    floor = {a: model.impacts(height=np.array([0.005, 0.020, 0.100]), damper=2, damper_order=a, k=1e13,
                              c_alpha=1e5)["eps"] for a in (0.1, 0.25, 0.5)}
    # A linear spring (n = 1): the whole model is linear, eps cannot depend on the height.
    linear = {name: model.impacts(height=np.array([0.005, 0.100]), spring_exponent=1.0, k=3e6, **kw)["eps"]
              for name, kw in (("dashpot", {}), ("springpot 0.5", dict(damper=2, c_alpha=c_alpha_rule(0.5, omega))))}
    return dict(target=target, dashpot=rows["dashpot"], rule=rule, matched=matched, stiff=stiff, floor=floor,
                linear=linear)


def log_times(t_sep, t_end, per_decade=40):
    return t_sep + np.logspace(math.log10(1e-5), math.log10(t_end - t_sep), int(per_decade * math.log10(
        (t_end - t_sep) / 1e-5)) + 1)


def recovery(omega):
    """Section 3: x2(t) after the h20 impact (no gravity) to 1000 s against
    x2 = I^alpha F / c_alpha of the run's own force and its power-law tail."""
    out = {}
    for alpha in RECOVERY_ALPHAS:
        ca = c_alpha_rule(alpha, omega)
        params = dict(damper=2, damper_order=alpha, c_alpha=ca)
        contact = model.simulate(output_interval=0, impacts=1, **params)  # every internal step of the contact
        run = contact["run"]
        t_sep = run.t_onset + run.t_contact
        inside = contact["t"] <= t_sep
        ts, F = contact["t"][inside], contact["F"][inside]
        impulse = float(np.sum(0.5 * (F[1:] + F[:-1]) * np.diff(ts)))
        t, x2 = [], []
        for t_end in (1e-2, 1.0, 1e2, 1e3):
            s = model.simulate(output_interval=t_end / 1000, t_end=t_end, impacts=2, **params)
            keep = s["t"] > (t_end / 100 if t_end > 1e-2 else t_sep + 1e-5)
            t.append(s["t"][keep])
            x2.append(s["x2"][keep])
        t, x2 = np.concatenate(t), np.concatenate(x2)
        order = np.argsort(t)
        t, x2 = t[order], x2[order]
        predicted = riemann_liouville(ts, F, alpha, t) / ca
        tail = impulse / (ca * math.gamma(alpha)) * t ** (alpha - 1.0)
        late = (t >= 1.0) & (t <= 100.0)
        far = t >= 10 * run.t_contact
        out[alpha] = dict(c_alpha=ca, t=t, x2=x2, predicted=predicted, tail=tail, t_sep=t_sep,
                          x2_sep=run.x2_end, impulse=impulse, impulse_striker=M * run.v_onset * (1 + run.eps),
                          slope=log_slope(t[late], x2[late]), slope_predicted=log_slope(t[late], predicted[late]),
                          error=float(np.max(np.abs(x2[far] / predicted[far] - 1))),
                          error_1s=float(np.interp(1.0, t, x2 / predicted - 1)),
                          x2_1s=float(np.interp(1.0, t, x2)), t_contact=run.t_contact)
    return out


def recovery_sensitivity():
    """x2 at 100 s against I^alpha F / c_alpha of each run's own force, for
    the default springpot at other memory tolerances and steps: what sets the
    recovery's error."""
    rows = []
    for tol, dt in ((1e-6, 1e-7), (1e-12, 1e-7), (1e-4, 1e-7), (1e-6, 1e-6), (1e-6, 1e-8)):
        params = dict(damper=2, memory_tolerance=tol, dt_max=dt)
        contact = model.simulate(output_interval=0, impacts=1, **params)
        run = contact["run"]
        inside = contact["t"] <= run.t_onset + run.t_contact
        s = model.simulate(output_interval=100.0, t_end=100.0, impacts=2, **params)
        predicted = riemann_liouville(contact["t"][inside], contact["F"][inside], 0.5, [100.0])[0] / H20["c_alpha"]
        rows.append(dict(tol=tol, dt=dt, error=s["x2"][-1] / predicted - 1, contact_steps=run.steps,
                         recovery_steps=s["run"].steps - run.steps))
    return rows


def onset_figures(s):
    """The second impact of a run with impacts = 2: the dent and the striker where it begins."""
    first, second = s["run"].per_impact[:2]
    t = second.t_onset
    return dict(x2_sep=first.x2_end, t_sep=first.t_onset + first.t_contact, t_onset=t, v_onset=second.v_onset,
                x_onset=float(np.interp(t, s["t"], s["x"])), x2_onset=float(np.interp(t, s["t"], s["x2"])),
                F_peak=second.F_peak, eps=second.eps, x2_end=second.x2_end, eps1=first.eps, F_peak1=first.F_peak,
                steps=s["run"].steps)


def second_contact():
    """Section 3b: a second contact under gravity, the springpot (defaults:
    alpha 0.5, c_alpha 3e5) with both memories, and the dashpot."""
    out = {}
    first = model.simulate(output_interval=0, impacts=1, damper=2, g=9.81)  # the weight is part of F
    inside = first["t"] <= first["run"].t_onset + first["run"].t_contact
    ts, F = first["t"][inside], first["F"][inside]
    s = model.simulate(output_interval=1e-5, damper=2, g=9.81, impacts=2)
    out["springpot"] = onset_figures(s)
    out["springpot"]["predicted"] = float(riemann_liouville(ts, F, 0.5, [out["springpot"]["t_onset"]])[0]
                                          / H20["c_alpha"])
    out["series"] = s
    for memory in (2, 1):
        seconds, s = cpu_seconds(lambda: model.simulate(output_interval=1e-4, damper=2, memory=memory, dt_max=5e-6,
                                                       g=9.81, impacts=2))
        out[f"memory {memory}"] = onset_figures(s)
        out[f"memory {memory}"]["cpu"] = seconds
    d = model.simulate(output_interval=1e-5, g=9.81, impacts=2)
    out["dashpot"] = onset_figures(d)
    out["dashpot_series"] = d
    return out


def steps_per_second(runs, **params):
    """CPU per internal step of `runs` identical runs in one fraccontact.impacts
    call (best of three)."""
    best = math.inf
    for _ in range(3 if runs > 1 or params.get("memory") != 1 else 1):
        batch = dict(params)
        batch["m"] = np.full(runs, M)
        seconds, r = cpu_seconds(lambda: model.impacts(**batch))
        best = min(best, seconds / float(np.sum(r["steps"])))
    return best, int(r["steps"][0])


def cost():
    """Section 4a: ns per internal step, dashpot / compressed / full history,
    against the steps N of one impact (dt_max = t_contact / N)."""
    t_c = model.impact(damper=2).t_contact
    rows = []
    for n in COST_STEPS:
        dt = t_c / n
        row = dict(N=n, dt=dt)
        for name, params, budget in (("dashpot", {}, 2e6), ("compressed", dict(damper=2), 1e6),
                                     ("full", dict(damper=2, memory=1), 1.5e8 / n)):
            runs = max(1, int(budget / n))
            row[name], row[name + "_steps"] = steps_per_second(runs, dt_max=dt, **params)
        rows.append(row)
    return rows


def bench():
    """fraccontact-bench springpot's JSON, or None while the program lacks it."""
    try:
        return solver.run_json(solver.bench_path(), "springpot", "1e5", timeout=600)
    except (solver.Failed, OSError, ValueError, json.JSONDecodeError):
        return None


def fmu_state_size(md, folder, H, **values):
    """The serialized FMU state's bytes after one communication step H."""
    s = Slave(md, folder, **values)
    try:
        s.step(H)
        state = s.fmu.getFMUstate()
        size = len(s.fmu.serializeFMUstate(state))
        s.fmu.freeFMUstate(state)
        return size
    finally:
        s.free()


def state_sizes(fmu):
    """Section 4b: the FMU state's size, each memory against the dashpot.
    The contact starts at t = 0 (gap0 = 0) and steps at dt_max, so a
    communication step H in contact is H / dt_max internal steps."""
    md, folder = unpacked(str(fmu))
    rows = []
    for label, params, dt, H in [
            ("dashpot", {}, 1e-7, 1e-3),
            ("compressed", dict(damper=2), 1e-7, 1e-3),
            ("compressed", dict(damper=2), 1e-10, 1e-6),
            ("compressed", dict(damper=2), 1e-10, 1e-3),
            ("full history", dict(damper=2, memory=1), 1e-7, 1e-4),
            ("full history", dict(damper=2, memory=1), 1e-7, 1e-3),
            ("full history", dict(damper=2, memory=1), 1e-7, 3e-3)]:
        seconds, size = cpu_seconds(lambda: fmu_state_size(md, folder, H, dt_max=dt, **params))
        modes = len(model.memory_kernel(damper=2, dt_max=dt)[0]) if params.get("damper") == 2 else 0
        rows.append(dict(label=label, dt=dt, steps=round(H / dt), size=size, cpu=seconds,
                         modes=modes if params.get("memory", 2) == 2 else 0))
    # The library counts the same steps: check the largest.
    steps_1e7 = model.impact(damper=2, dt_max=1e-10, t_end=1e-3, impacts=5).steps
    refusal = Slave(md, folder, damper=2, memory=1)
    try:
        refusal.step(0.2)
        refused = "(accepted)"
    except Exception:  # fmpy raises on the error status; the message is in the log
        refused = refusal.last_error()
    finally:
        refusal.fmu.freeInstance()
    return dict(rows=rows, steps_1e7=steps_1e7, refused=refused)


def kernels():
    """Section 5a: M and the kernel's own error against the tolerance."""
    rows = []
    for alpha in KERNEL_ALPHAS:
        for tol in TOLERANCES:
            a, b, eta = model.memory_kernel(damper_order=alpha, memory_tolerance=tol)
            rows.append(dict(alpha=alpha, tol=tol, M=len(a), eta=eta,
                             error=kernel_error(a, b, alpha, model.step_limit(), SPAN)))
    broken = []
    for tol in TOLERANCES[:4]:
        bad = [a for a in np.arange(0.002, 0.2, 0.002)
               if not all(np.all(np.isfinite(x)) for x in model.memory_kernel(damper_order=a, memory_tolerance=tol))]
        if bad:
            try:
                model.impact(damper=2, damper_order=bad[0], memory_tolerance=tol)
                failure = "runs"
            except (RuntimeError, ValueError) as err:
                failure = str(err)
            broken.append(dict(tol=tol, lo=bad[0], hi=bad[-1], count=len(bad), failure=failure))
    published = []
    for tol, counts in PUBLISHED.items():
        for ratio, count in zip(PUBLISHED_RATIOS, counts):
            dt = ratio * SPAN
            a, b, eta = model.memory_kernel(damper_order=0.5, memory_tolerance=tol, dt_max=dt)
            published.append(dict(tol=tol, ratio=ratio, published=count, M=len(a),
                                  error=kernel_error(a, b, 0.5, dt, SPAN)))
    return dict(rows=rows, published=published, broken=broken)


def memory_agreement():
    """Section 5b: F_peak and eps of the compressed memory at each tolerance
    against the full history (memory 1) and against the compressed memory at
    the finest tolerance, all at the default dt_max."""
    out = {}
    for alpha in KERNEL_ALPHAS:
        params = dict(damper=2, damper_order=alpha)
        ref = model.impact(memory=1, **params)
        r = model.impacts(memory_tolerance=np.array(TOLERANCES), **params)
        finest = r["F_peak"][-1], r["eps"][-1]
        out[alpha] = dict(
            full=(ref.F_peak, ref.eps),
            F_vs_full=np.abs(r["F_peak"] / ref.F_peak - 1), eps_vs_full=np.abs(r["eps"] / ref.eps - 1),
            F_vs_finest=np.abs(r["F_peak"] / finest[0] - 1), eps_vs_finest=np.abs(r["eps"] / finest[1] - 1))
    return out


def ladder():
    """Section 5c: both memories over dt_max. The default spring (law 1, the
    G1 law) for the accuracy criterion; the closed-form Hertz spring (law 2)
    and tolerance 1e-12 to see each memory's own time-stepping error, against
    the compressed memory at its finest step (1.6e-9 s, ~900 000 steps)."""
    default = {dt: dict(full=model.impact(damper=2, memory=1, dt_max=dt),
                        comp=model.impact(damper=2, memory=2, dt_max=dt)) for dt in LADDER}
    own = {}
    for alpha in KERNEL_ALPHAS:
        params = dict(damper=2, damper_order=alpha, law=2)
        comp = {dt: model.impact(memory=2, memory_tolerance=1e-12, dt_max=dt, **params) for dt in COMPRESSED_LADDER}
        full = {dt: model.impact(memory=1, dt_max=dt, **params) for dt in LADDER}
        ref = comp[COMPRESSED_LADDER[-1]]
        dts = [dt for dt in COMPRESSED_LADDER if dt >= ORDER_FLOOR]
        steps = [abs(comp[a].F_peak - comp[b].F_peak) for a, b in zip(dts, dts[1:])]
        own[alpha] = dict(ref=ref, orders=order(steps, dts[:-1]),
                          comp={dt: (rel(r.F_peak, ref.F_peak), rel(r.eps, ref.eps))
                                for dt, r in comp.items() if dt != COMPRESSED_LADDER[-1]},
                          full={dt: (rel(r.F_peak, ref.F_peak), rel(r.eps, ref.eps)) for dt, r in full.items()},
                          diff={dt: (rel(comp[dt].F_peak, full[dt].F_peak), rel(comp[dt].eps, full[dt].eps))
                                for dt in LADDER})
    return dict(default=default, own=own)


# ------------------------------------------------------------ figures

def label_of(alpha):
    return "dashpot" if alpha == "dashpot" else f"alpha = {alpha:g}"


def plot_curves(path, series, omega):
    fig, (ax_t, ax_x) = plt.subplots(1, 2, figsize=(12, 4.4))
    colors = plt.cm.viridis(np.linspace(0, 0.9, len(ALPHAS)))
    for color, alpha in zip(colors, ALPHAS):
        s = series[alpha]
        ax_t.plot(s["t"] * 1e3, s["F"], color=color, label=label_of(alpha))
        ax_x.plot(s["x"] * 1e6, s["F"], color=color, label=label_of(alpha))
    d = series["dashpot"]
    ax_t.plot(d["t"] * 1e3, d["F"], "k:", lw=2, label="dashpot (c = 6080 N s/m)")
    ax_x.plot(d["x"] * 1e6, d["F"], "k:", lw=2, label="dashpot")
    ax_t.set(xlabel="time [ms]", ylabel="contact force F [N]", title="Force against time")
    ax_x.set(xlabel="total indentation x [um]", ylabel="contact force F [N]",
             title="Force against indentation (loop area = E_diss)")
    for ax in (ax_t, ax_x):
        ax.grid(alpha=0.3)
    ax_t.legend(fontsize=8)
    fig.suptitle(f"h20 drop test with a springpot, c_alpha = c omega^(1-alpha), c = {C:g} N s/m, "
                 f"omega = {omega:.0f} rad/s")
    output.save(fig, path)


def plot_heights(path, h):
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.4))
    mm = HEIGHTS * 1e3
    d = h["dashpot"]
    for ax, group, title in ((axes[0], h["rule"], "eps, c_alpha = c omega^(1-alpha)"),
                             (axes[1], h["matched"], "eps, c_alpha matched to the dashpot's eps at 20 mm")):
        colors = plt.cm.viridis(np.linspace(0, 0.9, len(group)))
        for color, (alpha, row) in zip(colors, group.items()):
            ax.plot(mm, row["eps"], marker=".", color=color, label=f"springpot alpha = {alpha:g}")
        ax.plot(mm, d["eps"], "k.-", label="dashpot")
        ax.set(xlabel="drop height [mm]", ylabel="restitution coefficient eps", title=title)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    ax = axes[2]
    colors = plt.cm.viridis(np.linspace(0, 0.9, len(h["matched"])))
    for color, (alpha, row) in zip(colors, h["matched"].items()):
        ax.plot(mm, row["F_peak"], marker=".", color=color, label=f"springpot alpha = {alpha:g} (matched)")
    ax.plot(mm, d["F_peak"], "k.-", label="dashpot")
    ax.set(xlabel="drop height [mm]", ylabel="peak force F_peak [N]", title="Peak force (matched c_alpha)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.suptitle(f"Drop heights 5 to 100 mm (m = {M:g} kg, k = {H20['k']:.4g} N/m^1.5, n = 1.5)")
    output.save(fig, path)


def plot_recovery(path, rec, sc):
    fig, (ax_r, ax_e, ax_s) = plt.subplots(1, 3, figsize=(16, 4.6))
    colors = plt.cm.viridis(np.linspace(0, 0.8, len(rec)))
    for color, (alpha, r) in zip(colors, rec.items()):
        dt = r["t"] - r["t_sep"]
        ax_r.loglog(r["t"], r["x2"] * 1e6, color=color, lw=2, label=f"alpha = {alpha:g}: the model")
        ax_r.loglog(r["t"], r["predicted"] * 1e6, "k:", lw=1)
        ax_r.loglog(r["t"], r["tail"] * 1e6, "--", color=color, lw=1)
        ax_e.semilogx(dt, r["x2"] / r["predicted"] - 1, color=color, label=f"alpha = {alpha:g}")
    ax_r.loglog([], [], "k:", label="I^alpha F / c_alpha of the run's own F")
    ax_r.loglog([], [], "k--", lw=1, label="impulse t^(alpha-1) / (c_alpha Gamma(alpha))")
    ax_r.set(xlabel="time since the impact began [s]", ylabel="dent x2 [um]",
             title="Recovery of the dent after separation (g = 0)")
    ax_e.set(xlabel="time since separation [s]", ylabel="x2 / (I^alpha F / c_alpha) - 1",
             title="The model's x2 against the exact convolution")
    ax_e.set_ylim(-1.5e-3, 1.5e-3)
    for ax in (ax_r, ax_e):
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    s, d = sc["series"], sc["dashpot_series"]
    t2 = sc["springpot"]["t_onset"]
    window = (s["t"] > t2 - 2e-3) & (s["t"] < t2 + 1.6e-3)
    ax_s.plot((s["t"][window] - t2) * 1e3, s["x"][window] * 1e6, color="C0", label="striker x (springpot 0.5)")
    ax_s.plot((s["t"][window] - t2) * 1e3, s["x2"][window] * 1e6, color="C0", ls="--", label="dent x2 (springpot)")
    td = sc["dashpot"]["t_onset"]
    window = (d["t"] > td - 2e-3) & (d["t"] < td + 1.6e-3)
    ax_s.plot((d["t"][window] - td) * 1e3, d["x"][window] * 1e6, color="C3", label="striker x (dashpot)")
    ax_s.plot((d["t"][window] - td) * 1e3, d["x2"][window] * 1e6, color="C3", ls="--", label="dent x2 (dashpot)")
    ax_s.axvline(0, color="gray", lw=0.8)
    ax_s.set(xlabel="time from the second onset [ms]", ylabel="[um]", ylim=(-400, 300),
             title="Second contact under gravity: it begins where x = x2")
    ax_s.grid(alpha=0.3)
    ax_s.legend(fontsize=8)
    output.save(fig, path)


def plot_cost(path, rows, sizes, bench_json):
    fig, (ax_c, ax_s) = plt.subplots(1, 2, figsize=(12, 4.4))
    N = [r["N"] for r in rows]
    for key, label in (("dashpot", "dashpot"), ("compressed", "springpot, compressed (memory 2)"),
                       ("full", "springpot, full G1 history (memory 1)")):
        ax_c.loglog(N, [r[key] * 1e9 for r in rows], marker="o", label=label)
    if bench_json is not None:
        ladder = bench_json["ladder"]
        for i, key in ((1, "compressed"), (2, "full")):
            ax_c.loglog([r["N"] for r in ladder], [r[key]["ns_per_step"] for r in ladder], ls="", marker="D",
                        mfc="none", color=f"C{i}", label=f"{key}, fraccontact-bench springpot")
        ax_c.loglog([1.4e4], [bench_json["h20"]["dashpot"]["ns_per_step"]], ls="", marker="D", mfc="none", color="C0",
                    label="dashpot, fraccontact-bench (h20)")
    ax_c.set(xlabel="internal steps of the impact N", ylabel="CPU per internal step [ns]",
             title="Cost per step (filled: fraccontact.impacts batches)")
    steps = [r["steps"] for r in sizes]
    for label, dt, marker, color in (("dashpot", 1e-7, "s", "C0"), ("compressed", 1e-7, "D", "C1"),
                                     ("compressed", 1e-10, "o", "C1"), ("full history", 1e-7, "^", "C2")):
        pts = [(r["steps"], r["size"]) for r in sizes if r["label"] == label and r["dt"] == dt]
        ax_s.loglog(*zip(*pts), marker=marker, color=color, ls="-" if len(pts) > 1 else "",
                    label=f"{label}, dt_max {e(dt, 0)} s")
    ax_s.axhline(4096, color="gray", ls=":", label="4 KiB")
    ax_s.set(xlabel="internal steps taken", ylabel="serialized FMU state [bytes]",
             title="FMU state size (fmi2SerializeFMUstate)", xlim=(min(steps) / 3, max(steps) * 3))
    for ax in (ax_c, ax_s):
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    output.save(fig, path)


def plot_memory(path, k, agree, lad):
    fig, (ax_m, ax_a, ax_l) = plt.subplots(1, 3, figsize=(16, 4.6))
    for i, alpha in enumerate(KERNEL_ALPHAS):
        rows = [r for r in k["rows"] if r["alpha"] == alpha]
        ax_m.loglog([r["M"] for r in rows], [r["error"] for r in rows], marker="o", color=f"C{i}",
                    label=f"alpha = {alpha:g}")
    ax_m.set(xlabel="modes M", ylabel="max relative error over [dt_max, 1000 s]",
             title="The compressed kernel (tolerance 1e-2 ... 1e-12)")
    for i, alpha in enumerate(KERNEL_ALPHAS):
        a = agree[alpha]
        ax_a.loglog(TOLERANCES[:-1], a["F_vs_finest"][:-1], marker="o", color=f"C{i}",
                    label=f"vs tolerance 1e-12, alpha {alpha:g}")
        ax_a.loglog(TOLERANCES, a["F_vs_full"], ls="--", marker="x", color=f"C{i}",
                    label=f"vs memory 1, alpha {alpha:g}")
    ax_a.set(xlabel="memory_tolerance", ylabel="relative difference in F_peak",
             title="Compressed memory's F_peak (dt_max = 1e-7 s)")
    ax_a.invert_xaxis()
    colors = {alpha: f"C{i}" for i, alpha in enumerate(KERNEL_ALPHAS)}
    for alpha, o in lad["own"].items():
        dts = [dt for dt in sorted(o["comp"], reverse=True) if dt >= ORDER_FLOOR]
        ax_l.loglog(dts, [o["comp"][dt][0] for dt in dts], marker="s", ms=4, color=colors[alpha],
                    label=f"memory 2's own error, alpha {alpha:g}")
        ax_l.loglog(LADDER, [o["full"][dt][0] for dt in LADDER], marker="^", ls="--", color=colors[alpha],
                    label=f"memory 1's own error, alpha {alpha:g}")
    d = lad["default"]
    ax_l.loglog(LADDER, [rel(d[dt]["comp"].F_peak, d[dt]["full"].F_peak) for dt in LADDER], marker="o", color="k",
                label="|memory 2 - memory 1|, defaults (law 1)")
    ax_l.loglog(LADDER, [0.3 * 1e-8 * (dt / 1e-7) ** 2 for dt in LADDER], color="gray", ls=":", label="slope 2")
    ax_l.set(xlabel="dt_max [s]", ylabel="relative error / difference in F_peak",
             title="Own errors over the step (law 2, tol 1e-12)")
    ax_l.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    for ax in (ax_m, ax_a, ax_l):
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7, loc="upper left" if ax is ax_l else "best")
    output.save(fig, path)


# ------------------------------------------------------------ the report

def e(x, digits=2):
    """x in compact scientific notation (1.2e-06 -> 1.2e-6)."""
    if x == 0:
        return "0"
    text = f"{x:.{digits}e}"
    mant, exp = text.split("e")
    return f"{mant}e{int(exp)}"


def order(errors, steps):
    """Observed orders between consecutive (step, error) pairs."""
    return [math.log(errors[i] / errors[i + 1]) / math.log(steps[i] / steps[i + 1]) for i in range(len(errors) - 1)]


def section_curves(series, omega, one):
    lines = ["## 1. Force curves and hysteresis loops", "",
             f"The h20 drop (m = {M:g} kg, v0 = {V0:.4g} m/s, k = {H20['k']:.4g} N/m^1.5, n = 1.5, dt_max = "
             f"{model.step_limit():g} s, compressed memory). To make the orders comparable each springpot is given "
             "c_alpha = c omega^(1-alpha): its dynamic stiffness c_alpha omega^alpha equals the dashpot's c omega at "
             f"the impact's frequency omega = pi / t_contact = {omega:.0f} rad/s (the dashpot's t_contact), "
             f"c = {C:g} N s/m. The loss angle is alpha pi / 2 at every frequency, so at equal stiffness a lower alpha "
             "dissipates less: eps rises from the dashpot's towards 1 as alpha falls to 0, the limit of a linear "
             "spring.", "", "![force curves](fractional_damping_curves.png)", "",
             "| damper | alpha | c_alpha [N s^alpha/m] | F_peak [N] | eps | t_contact [ms] | x2 at separation [um] | "
             "E_diss [mJ] | E_diss / (1/2 m v0^2 (1 - eps^2)) - 1 |", "|---|---|---|---|---|---|---|---|---|"]
    for key in ALPHAS + ("dashpot",):
        r = series[key]["run"]
        alpha = 1.0 if key == "dashpot" else key
        ca = C if key == "dashpot" else c_alpha_rule(alpha, omega)
        name = "dashpot" if key == "dashpot" else "springpot"
        lines.append(f"| {name} | {alpha:g} | {ca:.4g} | {r.F_peak:.1f} | {r.eps:.4f} | {r.t_contact * 1e3:.4f} | "
                     f"{r.x2_end * 1e6:.2f} | {r.E_diss * 1e3:.3f} | "
                     f"{e(energy_balance(r))} |")
    hertz = [energy_balance(model.impact(law=2, **kw)) for kw in ({}, dict(damper=2))]
    lines += ["", "E_diss, the work on the damper (the integral of F dx2), is the loop's area and should equal the "
              "striker's lost kinetic energy at separation, where the spring holds no energy (x1 = 0). It does to "
              "about 1e-4 only: the default G1 spring (law 1) is k x1^n Gamma(N+n)/(Gamma(N) N^n) with N the steps "
              "since onset (docs/model.md §4), a stiffness that changes during the contact, so the spring is not exactly "
              "conservative. With the closed-form Hertz spring (law 2) the balance holds to "
              f"{e(abs(hertz[0]), 1)} (dashpot) and {e(abs(hertz[1]), 1)} (springpot 0.5). The springpot at alpha = 1 "
              f"(c_1 = c) against the dashpot, every internal step ({one['rows'][0]} and {one['rows'][1]} rows): "
              + ("identical, bit for bit (the target is 1e-9 relative)."
                 if one["dF"] == one["F_peak"] == one["eps"] == 0 else
                 f"the largest force difference is {e(one['dF'])} of F_peak, F_peak differs by {e(one['F_peak'])}, "
                 f"eps by {e(one['eps'])} (relative; the target is 1e-9)."), ""]
    return lines


def section_heights(h):
    d = h["dashpot"]
    lines = ["## 2. Restitution and peak force against drop height", "",
             "The paper's campaign, 5 to 100 mm in 5 mm steps (v0 = sqrt(2 g h)), one `fraccontact.impacts` batch per "
             "curve. Two families of springpots: c_alpha by the frequency rule of section 1 (each is then less "
             "damping than the dashpot), and c_alpha matched so that eps at 20 mm equals the dashpot's "
             f"({h['target']:.4f}), which compares the height dependence at equal damping. alpha <= 0.25 cannot be "
             "matched: as c_alpha falls to 0 the springpot alone remains, a linear element whose eps depends on "
             "alpha only (measured with a rigid spring, k = 1e13: "
             + ", ".join(f"alpha {a:g}: eps {v[1]:.4f}" for a, v in h["floor"].items())
             + f"), above {h['target']:.4f} for alpha <= 0.25.", "",
             "![heights](fractional_damping_heights.png)", "",
             "| damper | c_alpha [N s^alpha/m] | eps, 5 mm | eps, 20 mm | eps, 100 mm | eps(5) - eps(100) | "
             "(1 - eps) at 100 / at 5 mm | d ln(1 - eps) / d ln h | (2 - alpha)/10 | F_peak 5 / 100 mm [N] | "
             "d ln F_peak / d ln h |", "|---|---|---|---|---|---|---|---|---|---|---|"]

    def row(r, name):
        return (f"| {name} | {r['c_alpha']:.4g} | {r['eps5']:.4f} | {r['eps20']:.4f} | {r['eps100']:.4f} | "
                f"{r['spread']:.4f} | {r['loss_ratio']:.3f} | {r['loss_slope']:.3f} | {r['light']:.2f} | "
                f"{r['F_peak'][0]:.0f} / {r['F_peak'][-1]:.0f} | {r['F_slope']:.3f} |")
    lines.append(row(d, "dashpot"))
    for alpha, r in h["matched"].items():
        lines.append(row(r, f"springpot {alpha:g}, matched"))
    for alpha, r in h["rule"].items():
        lines.append(row(r, f"springpot {alpha:g}, frequency rule"))
    for alpha, r in h["stiff"].items():
        lines.append(row(r, r["name"]))
    m = h["matched"]
    best = min(m.values(), key=lambda r: r["spread"])
    worst = max(m.values(), key=lambda r: r["spread"])
    lin = h["linear"]
    lines += ["", "**Result.** The springpot's eps does *not* depend far less on the drop height than the dashpot's in "
              f"this model. At equal eps at 20 mm, eps falls from 5 to 100 mm by {d['spread']:.4f} for the dashpot "
              f"and by {best['spread']:.4f} to {worst['spread']:.4f} for the springpots (alpha "
              + ", ".join(f"{a:g}: {r['spread']:.4f}" for a, r in m.items())
              + f"): {100 * (1 - best['spread'] / d['spread']):.0f} % less at best (alpha = {best['alpha']:g}), more "
              "for alpha >= 0.75. The frequency-rule springpots, which dissipate less, vary less in eps "
              "but as much or more in their loss 1 - eps (the log-slope column).", "",
              "Why: the restitution of this series model depends on the ratio of the spring's stiffness to the "
              "damper's. The Hertz spring stiffens with the impact, k x1^(1/2) ~ v0^(2/5) (x ~ v0^(4/5)), while the "
              "contact shortens, omega ~ v0^(1/5). A dashpot's dynamic stiffness c omega grows as v0^(1/5), a "
              "springpot's c_alpha omega^alpha only as v0^(alpha/5): the ratio, and with it the loss, changes "
              "*faster* with height for a springpot, as h^((2 - alpha)/10) in the lightly damped limit against "
              f"h^(1/10) for the dashpot: with c and c_alpha {STIFF:g} times stiffer (the last rows) the fitted "
              "log-slopes of 1 - eps are " + ", ".join(f"{r['loss_slope']:.3f} ({r['name']}, limit {r['light']:.2f})"
                                                         for r in h["stiff"].values()) + ". The "
              "frequency-independent loss angle makes eps independent of the height only when nothing else sets a "
              "scale: with a linear spring (n = 1, k = 3e6 N/m) the whole model is linear and eps is the same at "
              f"5 and 100 mm for both dampers (dashpot {lin['dashpot'][0]:.6f} / {lin['dashpot'][1]:.6f}, springpot "
              f"0.5 {lin['springpot 0.5'][0]:.6f} / {lin['springpot 0.5'][1]:.6f}); so is the springpot alone "
              f"(rigid spring, alpha 0.5: {h['floor'][0.5][0]:.5f} at 5 mm, {h['floor'][0.5][2]:.5f} at 100 mm). "
              "The published observation concerns viscoelastic (complex-modulus) Hertz contact, where the "
              "springpot sits inside the Hertz stiffness, not in series with it.", "",
              "Peak force grows as h^0.6 for an elastic Hertz impact (F ~ v0^(6/5)); every damper here stays close "
              "to that (last column), the softer matched springpots at low alpha a little below.", ""]
    return lines


def section_recovery(rec, sens, sc):
    lines = ["## 3. Recovery of the dent", "",
             "After separation F = 0, so D^alpha x2 = 0 from then on and the dent recovers. Since x2(0) = 0, "
             "F = c_alpha D^alpha x2 inverts to x2 = I^alpha F / c_alpha exactly (Riemann-Liouville integral of "
             "order alpha): the recovery is fixed by the force history of the contact. The dotted line is that "
             "integral computed here from the run's own F (every internal step of the contact, product integration "
             "of its piecewise-linear interpolant); long after the contact it tends to the power law "
             "x2 = impulse t^(alpha-1) / (c_alpha Gamma(alpha)) (dashed). h20 impact, g = 0, c_alpha by the "
             "frequency rule, compressed memory, run to 1000 s (the span of its kernel).", "",
             "![recovery](fractional_damping_recovery.png)", "",
             "| alpha | c_alpha | x2 at separation [um] | x2 at 1 s [um] | fitted exponent, 1-100 s | alpha - 1 | "
             "exponent of I^alpha F | impulse int F dt [N s] | m v0 (1 + eps) [N s] | "
             "x2 / (I^alpha F / c_alpha) - 1 at 1 s | largest, 10 t_contact ... 1000 s |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for alpha, r in rec.items():
        lines.append(f"| {alpha:g} | {r['c_alpha']:.4g} | {r['x2_sep'] * 1e6:.2f} | {r['x2_1s'] * 1e6:.4f} | "
                     f"{r['slope']:.4f} | {alpha - 1:.2f} | {r['slope_predicted']:.4f} | {r['impulse']:.5f} | "
                     f"{r['impulse_striker']:.5f} | {e(r['error_1s'])} | {e(r['error'])} |")
    worst = max(r["error"] for r in rec.values())
    lines += ["", "The measured exponents match alpha - 1 to the fourth decimal (the finite contact shifts the "
              "exponent of the exact integral itself by about (1 - alpha) t_c / (2 t), below 1e-3 from 1 s on). "
              f"The model follows the exact convolution of its own force to {e(worst, 1)} relative from ten contact "
              "times to 1000 s, while the dent falls by "
              + ", ".join(f"{math.log10(r['x2_sep'] / r['x2'][-1]):.1f}" for r in rec.values())
              + " decades (alpha " + ", ".join(f"{a:g}" for a in rec) + "). Right after separation x2 is not yet "
              "on the power law (the contact's length still matters); by 1 s it is.", "",
              "What sets that error: the recovery's own time steps. Out of contact a recovering springpot steps at "
              "a fraction f = 64 dt_max / t_contact (at most 1/16) of the time since separation (RECOVERY_STEPS in "
              "model/control.c), so that the recovery's O(f^2) error falls with dt_max like the contact's; x2 at 100 s "
              "against the exact convolution of each run's own force (alpha 0.5, c_alpha 3e5):", "", "| memory_tolerance | dt_max [s] | contact steps | recovery steps to 100 s | "
              "x2 / (I^alpha F / c_alpha) - 1 at 100 s |", "|---|---|---|---|---|"]
    for r in sens:
        lines.append(f"| {e(r['tol'], 0)} | {e(r['dt'], 0)} | {r['contact_steps']} | {r['recovery_steps']} | "
                     f"{e(r['error'])} |")
    by_dt = {r["dt"]: abs(r["error"]) for r in sens if r["tol"] == 1e-6}
    by_tol = {r["tol"]: abs(r["error"]) for r in sens if r["dt"] == 1e-7}
    lines += ["", "At dt_max = 1e-7 s the error is " + ", ".join(f"{e(v)} (tolerance {e(t, 0)})"
                                                            for t, v in sorted(by_tol.items(), reverse=True))
              + "; with dt_max it goes " + ", ".join(f"{e(v)} ({e(d, 0)} s)" for d, v in sorted(by_dt.items(), reverse=True))
              + f": an observed order of {math.log10(by_dt[1e-6] / by_dt[1e-7]):.2f} from 1e-6 to 1e-7 s and "
              f"{math.log10(by_dt[1e-7] / by_dt[1e-8]):.2f} from 1e-7 to 1e-8 s (the reference, the convolution of "
              "the run's own force sampled at its steps, has errors of its own near the finest step).", ""]
    s, d = sc["springpot"], sc["dashpot"]
    m1, m2 = sc["memory 1"], sc["memory 2"]
    lines += ["### The second contact under gravity", "",
              "g = 9.81 m/s^2, two impacts: the striker flies up and falls back. A dashpot's dent stays, so the "
              "second contact begins at the first one's x2; a springpot's dent has recovered, and the second "
              "contact begins where the striker meets the recovered surface, x = x2 (x1 = 0).", "",
              "| run | x2 at 1st separation [um] | 2nd onset t [ms] | x2 at 2nd onset [um] | "
              "striker x at 2nd onset [um] | I^alpha F / c_alpha at 2nd onset [um] | v at 2nd onset [m/s] | "
              "2nd F_peak [N] | 2nd eps | x2 after 2nd [um] |", "|---|---|---|---|---|---|---|---|---|---|"]

    def row(name, r, pred=""):
        return (f"| {name} | {r['x2_sep'] * 1e6:.3f} | {r['t_onset'] * 1e3:.4f} | {r['x2_onset'] * 1e6:.4f} | "
                f"{r['x_onset'] * 1e6:.4f} | {pred} | {r['v_onset']:.5f} | {r['F_peak']:.2f} | {r['eps']:.5f} | "
                f"{r['x2_end'] * 1e6:.3f} |")
    lines += [row("springpot 0.5, c_alpha 3e5, dt_max 1e-7 (memory 2)", s, f"{s['predicted'] * 1e6:.4f}"),
              row("the same, dt_max 5e-6, memory 2", m2), row("the same, dt_max 5e-6, memory 1", m1),
              row("dashpot, c = 6080", d), ""]
    lines += [f"Between the impacts the springpot's dent recovered from {s['x2_sep'] * 1e6:.1f} um to "
              f"{s['x2_onset'] * 1e6:.2f} um ({100 * (1 - s['x2_onset'] / s['x2_sep']):.1f} %), and the second "
              "contact starts there: the onset is located where x1 = x - x2 reaches 0, and x - x2 = "
              f"{e(abs(s['x_onset'] - s['x2_onset']))} m in the row written at the onset. The dent predicted from the "
              "first contact's force alone, I^alpha F / c_alpha at the second onset (F of the run with gravity: "
              f"the weight adds about 1 % to the contact's impulse), is {s['predicted'] * 1e6:.4f} um, "
              f"{e(rel(s['x2_onset'], s['predicted']))} from the model's (the recovery error above). The full G1 "
              "history (memory 1, uniform steps of dt_max through the whole flight: "
              f"{m1['steps']} steps, {m1['cpu']:.2f} s of CPU against {m2['steps']} steps and {m2['cpu'] * 1e3:.1f} ms "
              "for memory 2) agrees with the compressed memory at the same dt_max to "
              f"{e(rel(m1['x2_onset'], m2['x2_onset']))} in the dent at the onset and "
              f"{e(rel(m1['F_peak'], m2['F_peak']))} in the second F_peak (memory 1 locates the onset on its grid; "
              "dt_max = 5e-6 s gives a coarse contact of ~280 steps, hence the difference to the 1e-7 s row). "
              "The dashpot's x2 does not move between contacts.", ""]
    return lines


def bench_lines(bench_json):
    """The bench's h20 figures and its ladder as tables."""
    if bench_json is None:
        return ["`fraccontact-bench springpot` was not available to this run (an older build): the table below "
                "is the only cost measurement.", ""]
    h = bench_json["h20"]
    d, c, f = h["dashpot"], h["compressed"], h["full"]
    lines = ["`fraccontact-bench springpot 1e5`, the C core alone timing itself (median of its repeats; the h20 "
             "impact in calls of 100 steps of dt_max = 1e-7 s, as an FMU takes them; then both memories over a "
             f"{bench_json['span'] * 1e3:g} ms span on N steps):", "",
             "| h20 impact | steps | ns per step | against the dashpot | F_peak [N] | eps | memory values |",
             "|---|---|---|---|---|---|---|"]
    for name, r in (("dashpot", d), ("springpot, compressed (memory 2)", c), ("springpot, full history (memory 1)", f)):
        lines.append(f"| {name} | {r['steps']} | {r['ns_per_step']:.0f} | {r['ns_per_step'] / d['ns_per_step']:.2f} | "
                     f"{r['F_peak']:.7f} | {r['eps']:.9f} | {r['memory_values']} |")
    lines += ["", "| N | compressed [ns/step] | full history [ns/step] | CPU, compressed [ms] | CPU, full [ms] | "
              "speed-up | F_peak difference | full history's heap [KiB] |", "|---|---|---|---|---|---|---|---|"]
    for r in bench_json["ladder"]:
        cc, ff = r["compressed"], r["full"]
        lines.append(f"| {r['N']:.0f} | {cc['ns_per_step']:.0f} | {ff['ns_per_step']:.0f} | "
                     f"{cc['seconds'] * 1e3:.3f} | {ff['seconds'] * 1e3:.1f} | {ff['seconds'] / cc['seconds']:.0f} | "
                     f"{e(rel(cc['F_peak'], ff['F_peak']))} | {ff['history_bytes'] / 1024:.0f} |")
    ladder = bench_json["ladder"]
    growth = log_slope([r["N"] for r in ladder], [r["full"]["seconds"] / r["compressed"]["seconds"] for r in ladder])
    lines += ["", f"At h20 the compressed memory's step costs {c['ns_per_step'] / d['ns_per_step']:.2f} times the "
              "dashpot's (the target is at most 5) and the full history's "
              f"{f['ns_per_step'] / c['ns_per_step']:.0f} times the compressed one's. The speed-up of the "
              f"compressed memory per impact grows as N^{growth:.2f} (like N, as expected). The "
              "compressed memory steps less often than N over the span: after separation it takes growing "
              "recovery steps (section 3) where the full history keeps stepping dt_max. "
              "`docs/benchmarks.md` carries the same subcommand's ladder to 1e6.", ""]
    return lines


def section_cost(rows, sizes, bench_json, kernel_m):
    first = rows[[r["N"] for r in rows].index(1e4)]
    lines = ["## 4. Cost per step and state size", ""]
    lines += bench_lines(bench_json)
    lines += ["The same from Python: CPU per internal step (`time.process_time` around one `fraccontact.impacts` "
              "batch of identical h20 impacts, best of three, one repetition for memory 1 at N = 1e5; the batch runs "
              "in the calling thread) at dt_max = t_contact / N, until the impact ends. The full history's step costs "
              "O(n) at its n-th step, so its mean over the impact grows like N; the compressed memory's step is O(M) "
              "with M fixed by the tolerance and dt_max (M = " + ", ".join(f"{m}" for m in kernel_m) + " here).", "",
              "| N (steps of the impact) | dt_max [s] | dashpot [ns/step] | compressed [ns/step] | full history "
              "[ns/step] | compressed / dashpot | full / compressed |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['compressed_steps']} | {e(r['dt'])} | {r['dashpot'] * 1e9:.0f} | "
                     f"{r['compressed'] * 1e9:.0f} | {r['full'] * 1e9:.0f} | {r['compressed'] / r['dashpot']:.2f} | "
                     f"{r['full'] / r['compressed']:.1f} |")
    slope = log_slope([r["N"] for r in rows[-3:]], [r["full"] for r in rows[-3:]])
    lines += ["", f"At the default dt_max ({first['compressed_steps']} steps) the compressed memory's step costs "
              f"{first['compressed'] / first['dashpot']:.2f} times the dashpot's, the full history's "
              f"{first['full'] / first['compressed']:.0f} times the compressed one's; over the last three N the full "
              f"history's cost per step grows as N^{slope:.2f}. These sit above the bench's at every N (by about "
              + (f"{(first['dashpot'] * 1e9 - bench_json['h20']['dashpot']['ns_per_step']):.0f} ns for the dashpot "
                 f"and {(first['compressed'] * 1e9 - bench_json['h20']['compressed']['ns_per_step']):.0f} ns for the "
                 "compressed memory at h20" if bench_json else "a few tens of ns")
              + "): the library's run loop (fc_run) advances one internal step per call, with its checks and a copy "
              "of the state, where the bench advances 100 steps a call.", ""]
    lines += ["The FMU's serialized state (`fmi2SerializeFMUstate` through fmpy) after one communication step of "
              "H = N dt_max from the start of the drop (contact from t = 0, so N internal steps of dt_max; the "
              f"library counts {sizes['steps_1e7']} steps for the 1e7 row's run):", "",
              "| damper / memory | dt_max [s] | M (modes) | internal steps | state [bytes] | CPU [s] |",
              "|---|---|---|---|---|---|"]
    for r in sizes["rows"]:
        lines.append(f"| {r['label']} | {e(r['dt'], 0)} | {r['modes'] or ''} | {r['steps']} | {r['size']} | "
                     f"{r['cpu']:.2f} |")
    comp = [r for r in sizes["rows"] if r["label"] == "compressed" and r["dt"] == 1e-10]
    full = [r for r in sizes["rows"] if r["label"] == "full history"]
    per = (full[-1]["size"] - full[0]["size"]) / (full[-1]["steps"] - full[0]["steps"])
    lines += ["", f"The compressed state is the same after {comp[0]['steps']} and {comp[1]['steps']} internal steps "
              f"({comp[0]['size']} and {comp[1]['size']} bytes, under the 4 KiB asked); its size depends on M, i.e. "
              "on dt_max and the tolerance, not on the run's length. The full history's grows by "
              f"{per:.1f} bytes a step (x2 at every step since t = 0) and is refused past 1 048 576 steps, before "
              "any work is done; asked for 0.2 s at dt_max = 1e-7 s the FMU answers:", "",
              f"> {sizes['refused']}", ""]
    return lines


def section_memory(k, agree, lad):
    lines = ["## 5. Error of the compressed memory against M", "",
             "`fraccontact.memory_kernel` gives the compressed kernel (a_i, b_i, the lumped spring b = 0 last, and "
             "the lumped dashpot eta for the kernel below dt_max). M counts the a_i (the lumped spring included, eta "
             "not); the kernel error is the largest relative error of sum a_i exp(-b_i tau) against "
             "tau^(-alpha)/Gamma(1-alpha) over [dt_max, 1000 s], on 400 log-spaced points a decade; dt_max = 1e-7 s "
             "(delta/T = 1e-10). F_peak and eps are the h20 impact's (c_alpha = 3e5 N s^alpha/m for every alpha), "
             "against the full G1 history (memory 1, same dt_max, ~14 000 steps) and against the compressed memory "
             "at tolerance 1e-12, which isolates the kernel's effect.", "", "![memory](fractional_damping_memory.png)",
             "", "| alpha | tolerance | M | kernel error | F_peak vs tol 1e-12 | eps vs tol 1e-12 | "
             "F_peak vs memory 1 | eps vs memory 1 |", "|---|---|---|---|---|---|---|---|"]
    for alpha in KERNEL_ALPHAS:
        a = agree[alpha]
        rows = [r for r in k["rows"] if r["alpha"] == alpha]
        for i, r in enumerate(rows):
            lines.append(f"| {alpha:g} | {e(r['tol'], 0)} | {r['M']} | {e(r['error'])} | {e(a['F_vs_finest'][i])} | "
                         f"{e(a['eps_vs_finest'][i])} | {e(a['F_vs_full'][i])} | {e(a['eps_vs_full'][i])} |")
    over = [r for r in k["rows"] if r["error"] > r["tol"]]
    lines += ["", "M grows about linearly in log(1/tolerance), ~12 modes a decade. The kernel error stays below the "
              "requested tolerance (at 0.4-0.8 of it) at every alpha and tolerance "
              + ("" if not over else "but " + ", ".join(f"alpha {r['alpha']:g} at {e(r['tol'], 0)} ({e(r['error'])}, "
                                                         f"{r['error'] / r['tol']:.2f} x the tolerance)" for r in over))
              + ". At the default tolerance the kernel's share of the F_peak difference to memory 1 is nil: from "
              "about 1e-5 on that difference no longer moves with the tolerance (next section)."]
    if k["broken"]:
        lines += ["", "**Found here: the kernel is not finite for small alpha at loose tolerances**, and the "
                  "parameter check lets it through, so the run fails at its first step. Scanning alpha over "
                  "0.002 ... 0.2 (step 0.002): "
                  + "; ".join(f"tolerance {e(b['tol'], 0)}: alpha {b['lo']:g} ... {b['hi']:g} ({b['count']} values)"
                              for b in k["broken"])
                  + f". `fraccontact.impact(damper=2, damper_order={k['broken'][0]['lo']:g}, memory_tolerance="
                  f"{e(k['broken'][0]['tol'], 0)})` says: \"{k['broken'][0]['failure']}\"."]
    lines += ["", "Against the published counts for tau^(-1/2) (docs/model.md §6, Jiang et al. 2017), the same alpha = 0.5 "
              "kernel with dt_max = delta/T x 1000 s:", "",
              "| tolerance | delta/T | published M | M here | kernel error here |", "|---|---|---|---|---|"]
    for r in k["published"]:
        lines.append(f"| {e(r['tol'], 0)} | {e(r['ratio'], 0)} | {r['published']} | {r['M']} | {e(r['error'])} |")
    pub = k["published"]
    beat = [r for r in pub if r["M"] <= r["published"]]
    lines += ["", f"This kernel (a trapezoidal rule in log-rate with a lumped spring and dashpot) meets or beats the "
              f"published count in {len(beat)} of {len(pub)} cells: at 1e-6 everywhere, at 1e-9 only for the longest "
              "span; at 1e-9 and 1e-12 on short spans it needs up to "
              f"{max(r['M'] / r['published'] for r in pub):.1f} times the published modes. The default (1e-6 over "
              "delta/T = 1e-10) needs 58."]
    d = lad["default"]
    lines += ["", "### Against the full history over the step", "",
              "The accuracy criterion, at the defaults (alpha 0.5, c_alpha 3e5, G1 spring law 1, tolerance 1e-6):", "",
              "| dt_max [s] | steps | F_peak, memory 1 [N] | F_peak, memory 2 [N] | relative difference | "
              "eps, memory 1 | eps, memory 2 | relative difference |", "|---|---|---|---|---|---|---|---|"]
    diffs = []
    for dt in LADDER:
        f, c = d[dt]["full"], d[dt]["comp"]
        diffs.append(rel(c.F_peak, f.F_peak))
        lines.append(f"| {e(dt, 0)} | {f.steps} | {f.F_peak:.7f} | {c.F_peak:.7f} | {e(rel(c.F_peak, f.F_peak))} | "
                     f"{f.eps:.9f} | {c.eps:.9f} | {e(rel(c.eps, f.eps))} |")
    lines += ["", "Observed order of the F_peak difference: " + ", ".join(f"{x:.2f}" for x in order(diffs, LADDER))
              + ". Both memories step the same grid and use the same G1 spring, whose first-order error "
              "(k x1^n Gamma(N+n)/(Gamma(N) N^n), N = steps since onset, docs/model.md §4) moves F_peak by "
              f"{e(rel(d[LADDER[-1]]['comp'].F_peak, d[LADDER[-2]]['comp'].F_peak))} between the last two rows: "
              "it is common to both and cancels in their difference.", "",
              "Each memory's own error, with the closed-form Hertz spring (law 2) and the compressed kernel at "
              "tolerance 1e-12 so that only the damper's time scheme remains, against the compressed memory at "
              f"dt_max = {e(COMPRESSED_LADDER[-1])} s (F_peak, eps relative):", "",
              "| alpha | dt_max [s] | memory 1 F_peak | memory 1 eps | memory 2 F_peak | memory 2 eps | "
              "memory 2 - memory 1, F_peak | eps |", "|---|---|---|---|---|---|---|---|"]
    for alpha, o in lad["own"].items():
        for dt in LADDER:
            lines.append(f"| {alpha:g} | {e(dt, 0)} | {e(o['full'][dt][0])} | {e(o['full'][dt][1])} | "
                         f"{e(o['comp'][dt][0])} | {e(o['comp'][dt][1])} | {e(o['diff'][dt][0])} | "
                         f"{e(o['diff'][dt][1])} |")
    lines += ["", "Observed orders in F_peak, step by step: memory 1 from its error above (8e-7 ... 1e-7 s), memory 2 "
              "from successive differences (8e-7 ... 1.25e-8 s; below that its differences reach 1e-12 and the "
              "orders are noise):", "", "| alpha | memory 1 | memory 2 |", "|---|---|---|"]
    for alpha, o in lad["own"].items():
        full_orders = order([o["full"][dt][0] for dt in LADDER], LADDER)
        lines.append(f"| {alpha:g} | " + ", ".join(f"{x:.2f}" for x in full_orders)
                     + " | " + ", ".join(f"{x:.2f}" for x in o["orders"]) + " |")
    o5 = lad["own"][0.5]
    lines += ["", "**What limits agreement.** At the default dt_max and tolerance the two memories agree to "
              f"{e(diffs[-1])} in F_peak and {e(rel(d[LADDER[-1]]['comp'].eps, d[LADDER[-1]]['full'].eps))} in eps, "
              "far inside the 1e-4 asked. Below a tolerance of about 1e-5 the remaining difference does not move "
              "with the tolerance (table above): it is the two time schemes', and mostly the full history's own "
              f"error (G1 with its shift correction and BDF2, second order: {e(o5['full'][LADDER[-1]][0])} in F_peak "
              f"at 1e-7 s for alpha 0.5), against {e(o5['comp'][LADDER[-1]][0])} for the compressed memory's SDIRK2 "
              "on its modes. The full history is second order at every alpha. The compressed memory is second "
              "order at alpha 0.25 and 0.75; at alpha 0.5 its error is smaller at the coarse steps (its dt^2 term "
              "nearly cancels in F_peak) and what remains converges at an observed order rising from near 0 "
              "to about 1.4 over the ladder: small (1e-9 at 1e-7 s), but not the clean second order of the others, "
              "and not explained here. Only loose tolerances (1e-2, 1e-3) show in F_peak and eps: there the "
              "kernel error is the difference.", ""]
    return lines


def write_report(args):
    cpu0, wall0 = cpu_with_children(), time.perf_counter()
    omega = frequency()
    print("force curves", flush=True)
    series = curves(omega)
    one = alpha_one_against_dashpot()
    print("drop heights", flush=True)
    h = heights(omega)
    print("recovery", flush=True)
    rec = recovery(omega)
    sens = recovery_sensitivity()
    sc = second_contact()
    print("kernels", flush=True)
    k = kernels()
    agree = memory_agreement()
    lad = ladder()
    print("cost per step", flush=True)
    rows = cost()
    sizes = state_sizes(args.fmu)
    bench_json = bench()
    kernel_m = [len(model.memory_kernel(damper=2, dt_max=r["dt"])[0]) for r in rows]
    cpu, wall = cpu_with_children() - cpu0, time.perf_counter() - wall0

    plot_curves(args.out / "fractional_damping_curves.png", series, omega)
    plot_heights(args.out / "fractional_damping_heights.png", h)
    plot_recovery(args.out / "fractional_damping_recovery.png", rec, sc)
    plot_cost(args.out / "fractional_damping_cost.png", rows, sizes["rows"], bench_json)
    plot_memory(args.out / "fractional_damping_memory.png", k, agree, lad)

    lines = ["# Fractional damping: the springpot", "",
             "Regenerate: `scripts/report fractional_damping` (writes this file and `fractional_damping_*.png`; "
             f"this run: {cpu:.0f} s of CPU, {wall:.0f} s wall, measurements only).", "",
             "The dashpot of the paper's model (docs/model.md §2) replaced by a springpot, F = c_alpha D^alpha x2 "
             "(docs/model.md §5; `damper = 2`, `damper_order` alpha, `c_alpha`), in series with the Hertz spring. Its "
             "memory is the compressed sum of exponentials (`memory = 2`, the default, docs/model.md §6) unless a row "
             "says memory 1 (the literal G1 history sum). Every figure below is measured by this run, in-process "
             "on the C library (`fraccontact.impact`, `impacts`, `simulate`, `memory_kernel`) and, for the state "
             "sizes, through the FMU with fmpy.", ""]
    lines += section_curves(series, omega, one)
    lines += section_heights(h)
    lines += section_recovery(rec, sens, sc)
    lines += ["![cost](fractional_damping_cost.png)", ""]
    lines += section_cost(rows, sizes, bench_json, kernel_m)
    lines += section_memory(k, agree, lad)
    atomic.write_text(args.out / "fractional_damping.md", "\n".join(lines) + "\n")
    print(f"wrote {args.out / 'fractional_damping.md'} ({cpu:.0f} s CPU)")


def main(argv=None, prog=None):
    parser = output.parser(prog, __doc__)
    output.add_fmu(parser)
    args = output.parse(parser, argv)
    write_report(args)
