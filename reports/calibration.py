"""Calibration report: the paper's h20 row fitted (k, c, E_s next to the
paper's); the same row with a springpot (k, c_alpha, alpha), which it cannot
identify: the family of solutions, its accuracy, and what each member
predicts at other heights; the fit's identifiability and precision on data
made by one member (one test, repeats, several heights, curves); the
drop-height sweep (5 to 100 mm) at the paper's constants and at the fitted
ones; the sweep's throughput on one and two local Dask workers. Writes
docs/calibration.md, docs/calibration_sweep.png, docs/calibration_family.png.

Regenerate: scripts/report calibration   (about half a minute)
"""

import csv
import json
import math
import pathlib
import tempfile
import time

import numpy as np

from fraccontact import atomic, fit, model, output, sweep

# The paper's h20 row (docs/model.md §1, Table 1): what was measured, and the
# constants the paper fitted, which are the library's defaults.
H20 = model.defaults()
PAPER = dict(F_peak=1004.0, eps=0.59, height=0.020, m=H20["m"], k=H20["k"], c=H20["c"], E_s=H20["E_s"])


def heights_sweep(out, k, c, workers=2):
    assert sweep.main(["--vary", "height=0.005:0.1:0.005", "--set", "law=hertz", "--set", f"k={k}", "--set", f"c={c}",
                       "--workers",
                       str(workers), "--csv", "--out", str(out)]) == 0
    with open(out / "sweep.csv") as f:
        return [{key: float(v) for key, v in r.items() if key in ("height", "F_peak", "eps", "t_contact", "x2_end")}
                for r in csv.DictReader(f)]


def throughput(out, workers, n):
    assert sweep.main(["--monte-carlo", str(n), "--set", "law=hertz", "--scatter", "k=0.05", "--scatter", "c=0.1",
                       "--workers",
                       str(workers), "--out", str(out)]) == 0
    return json.loads((out / "sweep.json").read_text())


def plot(path, paper_rows, fitted_rows):
    plt = output.pyplot()
    fig, axes = plt.subplots(2, 2, figsize=(11, 7.5))
    spec = [("F_peak", 1, "peak force F_peak [N]"), ("eps", 1, "restitution coefficient eps"),
            ("t_contact", 1e3, "contact time [ms]"), ("x2_end", 1e6, "permanent indentation [um]")]
    for ax, (key, scale, label) in zip(axes.flat, spec):
        for rows, name in ((paper_rows, "paper's k, c"), (fitted_rows, "k, c fitted to the h20 row")):
            ax.plot([r["height"] * 1e3 for r in rows], [r[key] * scale for r in rows], marker=".", label=name)
        if key == "F_peak":
            ax.plot([20], [PAPER["F_peak"]], "k*", ms=10, label="paper, h20 (measured fit target)")
        if key == "eps":
            ax.plot([20], [PAPER["eps"]], "k*", ms=10)
        ax.set(xlabel="drop height [mm]", ylabel=label)
        ax.grid(alpha=0.3)
    axes.flat[0].legend(fontsize=8)
    fig.suptitle(f"Drop-height sweep, 5 to 100 mm (m = {PAPER['m']:g} kg, Hertz law)")
    output.save(fig, path)


# The springpot: the h20 row cannot identify k, c_alpha and alpha.

SHOWN = (1.0, 0.8, 0.6, 0.45, 0.35, 0.3)   # the family's members drawn and tabled in full
TRUTH_ALPHA = 0.6                         # the member whose data the identifiability section fits
HEIGHTS_MM = np.arange(5, 101, 5)         # the paper's campaign
CONVERGED = 8                             # the converged model: an eighth of the fit's step, kernel tolerance 1e-9


def modulus(k):
    """E_s [Pa] from k with the paper's indenter, or None when k is stiffer than the indenter allows."""
    try:
        return fit.specimen_modulus(k, H20["R"], H20["E_i"], H20["nu_i"], H20["nu_s"])
    except fit.Unreachable:
        return None


def k_of_rigid_specimen():
    """k of a rigid specimen (E_s -> infinity) on the paper's indenter: no E_s gives more."""
    return 4.0 / 3.0 * math.sqrt(H20["R"]) * H20["E_i"] / (1 - H20["nu_i"] ** 2)


def h20_drops():
    return fit.Drops(v=np.array([model.drop_velocity(PAPER["height"])]), F=np.array([PAPER["F_peak"]]),
                     eps=np.array([PAPER["eps"]]), heights=[PAPER["height"]])


def member_params(base, mb, v, dt_max=None):
    """The library's parameters of a family member at the impact velocity v (its own step unless dt_max)."""
    p = base.with_alpha(mb["alpha"]).library(np.array(mb["x"]))
    return dict(p, v=v, dt_max=dt_max or p["dt_max"], t_end=1.0)


def order_where_k_reaches(base, drops, k_target, lo, hi, x_hi):
    """The order at which the family's k reaches k_target (k falls as alpha rises), by bisection between
    lo (k above) and hi (k below, member x_hi)."""
    cap = fit.K_CAP * base.k_elastic(drops.F[0], drops.v[0])
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        x, _, capped = fit.solve_fixed_order(base.with_alpha(mid), drops, x_hi, cap)
        if not capped and base.k_ref * math.exp(x[0]) < k_target:
            hi, x_hi = mid, x
        else:
            lo = mid
    return hi


def family_section(out):
    """The h20 row with a springpot: the one-line verdict, the family, its accuracy, its predictions."""
    drops = h20_drops()
    v = float(drops.v[0])
    start = time.perf_counter()
    result, base, _ = fit.fit_drops(drops, PAPER["m"], damper=2)
    seconds = time.perf_counter() - start
    fam = result["family"]
    members = [mb for mb in fam["members"] if mb["in_family"]]
    k_rigid = k_of_rigid_specimen()
    last_with_modulus = min((mb for mb in members if modulus(mb["k"]) is not None), key=lambda mb: mb["alpha"])
    below = max((mb["alpha"] for mb in members if modulus(mb["k"]) is None), default=fam["alpha_min"])
    alpha_E = order_where_k_reaches(base, drops, k_rigid, below, last_with_modulus["alpha"],
                                    np.array(last_with_modulus["x"]))
    # accuracy: on the fit's step, against the converged model, against the full G1 history
    off = dict(fit=[0.0, 0.0], converged=[0.0, 0.0], full=[0.0, 0.0])
    for mb in members:
        p = member_params(base, mb, v)
        converged = model.impact(**dict(p, dt_max=p["dt_max"] / CONVERGED, memory_tolerance=1e-9))
        full = model.impact(**dict(p, memory=1))
        checks = dict(fit=(mb["F_peak"][0], mb["eps"][0]), converged=(converged.F_peak, converged.eps),
                      full=(full.F_peak, full.eps))
        for key, (F, eps) in checks.items():
            off[key] = [max(off[key][0], abs(F / PAPER["F_peak"] - 1)), max(off[key][1], abs(eps - PAPER["eps"]))]
    # predictions of each member: at h20 the contact time and dent, at every height F_max and eps
    heights = HEIGHTS_MM / 1e3
    predictions = []
    for mb in members:
        p = member_params(base, mb, v, base.dt_max / 2)
        at = model.impact(**p)
        campaign = model.impacts(**dict(p, v=np.array([model.drop_velocity(h) for h in heights])))
        series_ = model.simulate(output_interval=at.t_contact / 400, **p)
        predictions.append(dict(mb=mb, t_contact=at.t_contact, x2_end=at.x2_end, F=campaign["F_peak"],
                                eps=campaign["eps"], t=series_["t"], force=series_["F"]))
    plot_family(out / "calibration_family.png", members, [pr for pr in predictions if pr["mb"]["alpha"] in SHOWN],
                fam["alpha_min"], alpha_E, heights)
    verdict = fit.family_report(dict(result, E_s_family=[modulus(mb["k"]) if mb["in_family"] else None
                                                         for mb in fam["members"]])).splitlines()[0]
    dashpot, lowest = members[0], members[-1]
    lines = ["## The h20 row with a springpot: a family of solutions", "",
             f"`fraccontact fit --F-peak 1004 --eps 0.59 --height 0.020 --m {PAPER['m']:g} --damper 2` "
             f"({seconds:.1f} s in-process) answers with one line and a table:", "", "```", verdict, "```", "",
             "docs/model.md §1 gives F_max and eps at 20 mm only (the paper measured 5 to 100 mm but tabled h20 alone), "
             "so the springpot's three parameters meet two numbers. For each order alpha the k and c_alpha that "
             "reproduce them (least squares at that alpha, each solved from its neighbour):", "",
             "| alpha | k [N/m^1.5] | c_alpha [N s^alpha/m] | E_s [GPa] | t_contact at 20 mm [ms] | dent x2_end at "
             "20 mm [um] | F_max at 5 mm [N] | F_max at 100 mm [N] | eps at 5 mm | eps at 100 mm |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    by_alpha = {pr["mb"]["alpha"]: pr for pr in predictions}
    for mb in members:
        E_s = modulus(mb["k"])
        pr = by_alpha.get(mb["alpha"])
        lines.append(f"| {mb['alpha']:.2f} | {mb['k']:.4g} | {mb['c_alpha']:.4g} | "
                     f"{'none' if E_s is None else output.significant(E_s / 1e9, 3)} | {pr['t_contact'] * 1e3:.4f} | "
                     f"{pr['x2_end'] * 1e6:.2f} | {pr['F'][0]:.1f} | {pr['F'][-1]:.1f} | {pr['eps'][0]:.4f} | "
                     f"{pr['eps'][-1]:.4f} |")
    lines += ["", f"Below alpha = {members[-1]['alpha']:.2f} the table ends: the family's k rises without bound as "
              f"alpha falls to alpha_min = {fam['alpha_min']:.4f} (the bisection's limit with k up to {fit.K_CAP:g} "
              "times the elastic Hertz k of 1004 N, i.e. a rigid spring: the springpot alone). Below it no springpot "
              "reaches eps = 0.59 with F_max = 1004 N: a loss angle alpha pi/2 below "
              f"{fam['alpha_min'] * 90:.1f} degrees cannot dissipate the {100 * (1 - PAPER['eps'] ** 2):.0f} % of "
              "the impact energy that eps = 0.59 means. Earlier still, below alpha_E = "
              f"{alpha_E:.4f}, k exceeds {k_rigid:.4g} N/m^1.5, the Hertz constant of a rigid specimen on the "
              f"paper's indenter (E_i = {H20['E_i'] / 1e9:g} GPa, nu_i = {H20['nu_i']:g}, R = {H20['R'] * 1e3:g} mm): "
              "no specimen modulus gives it. So the physically admissible family is "
              f"**{alpha_E:.3f} < alpha <= 1**.", "",
              "![family](calibration_family.png)", "",
              "**Accuracy of the members.** On the fit's step (t_c / "
              f"{fit.SPRINGPOT_STEPS_PER_CONTACT}, dt_max = {base.dt_max:.3g} s, compressed memory) every member "
              f"reproduces F_max within {off['fit'][0]:.1e} (relative) and eps within {off['fit'][1]:.1e}. Run "
              f"converged (dt_max / {CONVERGED}, kernel tolerance 1e-9) they give F_max within "
              f"{off['converged'][0]:.1e} "
              f"and eps within {off['converged'][1]:.1e}; with the full G1 history (memory = 1, first order in the "
              f"step) at the fit's step within {off['full'][0]:.1e} and {off['full'][1]:.1e}. The family is the "
              "model's, to the solver's accuracy, not an artefact of the step.", "",
              "**What the family says.**", "",
              f"- No order is preferred by F_max and eps: every member from alpha = 1 (the dashpot, k = "
              f"{dashpot['k']:.4g}, c = {dashpot['c_alpha']:.4g}, the same as the dashpot fit above) to alpha = "
              f"{lowest['alpha']:.2f} reproduces them exactly.",
              f"- k rises as alpha falls, so E_s does: from {modulus(dashpot['k']) / 1e9:.3g} GPa at alpha = 1 to "
              f"{modulus(by_alpha[0.6]['mb']['k']) / 1e9:.3g} GPa at 0.6 and "
              f"{modulus(by_alpha[0.35]['mb']['k']) / 1e9:.3g} "
              "GPa at 0.35. The dashpot gives the family's lowest modulus: no springpot brings E_s from the paper's "
              "2.64 GPa towards the 1.2 GPa of impact-tensile tests; a springpot makes the gap larger.",
              f"- The members differ where h20's two numbers do not look. At 20 mm the contact time runs from "
              f"{by_alpha[1.0]['t_contact'] * 1e3:.3f} ms (alpha = 1) to {by_alpha[0.3]['t_contact'] * 1e3:.3f} ms "
              f"(alpha = 0.3) and the permanent dent from {by_alpha[1.0]['x2_end'] * 1e6:.1f} to "
              f"{by_alpha[0.3]['x2_end'] * 1e6:.1f} um. Over the campaign the peak force tells them apart most: at "
              f"100 mm {by_alpha[1.0]['F'][-1]:.0f} N for the dashpot, {by_alpha[0.6]['F'][-1]:.0f} N at alpha = 0.6 "
              f"({100 * (by_alpha[0.6]['F'][-1] / by_alpha[1.0]['F'][-1] - 1):+.1f} %), "
              f"{by_alpha[0.3]['F'][-1]:.0f} N at 0.3. The restitution barely does down to alpha = 0.6 (within "
              f"{np.max(np.abs(by_alpha[0.6]['eps'] - by_alpha[1.0]['eps'])):.4f} of the dashpot's from 5 to 100 mm); "
              "the lower orders flatten it: from 5 to 100 mm eps falls by "
              f"{by_alpha[1.0]['eps'][0] - by_alpha[1.0]['eps'][-1]:.3f} for the dashpot and by "
              f"{by_alpha[0.3]['eps'][0] - by_alpha[0.3]['eps'][-1]:.3f} at alpha = 0.3 (a springpot's loss angle "
              "does not depend on frequency). The h20 force curve, its contact time, or F_max at a second height "
              "would pick alpha: the next section measures how well.", ""]
    return lines, base, by_alpha[TRUTH_ALPHA]["mb"]


def plot_family(path, members, predictions, alpha_min, alpha_E, heights):
    plt = output.pyplot()
    import matplotlib.ticker
    fig, axes = plt.subplots(2, 2, figsize=(11, 8))
    ax = axes[0, 0]
    alphas = [mb["alpha"] for mb in members]
    ax.semilogy(alphas, [np.nan if modulus(mb["k"]) is None else modulus(mb["k"]) / 1e9 for mb in members], "o-",
                ms=4, label="E_s of the member [GPa]")
    ax.axhline(PAPER["E_s"] / 1e9, color="k", ls="--", lw=1, label="paper's E_s, 2.64 GPa")
    ax.axhline(1.2, color="grey", ls="--", lw=1, label="impact-tensile tests, 1.2 GPa")
    ax.axvline(alpha_E, color="C3", ls=":", label=f"alpha_E = {alpha_E:.3f} (E_s -> infinity)")
    ax.axvline(alpha_min, color="k", ls=":", label=f"alpha_min = {alpha_min:.3f} (k -> infinity)")
    ax.set(xlabel="springpot order alpha", ylabel="specimen modulus E_s [GPa]", ylim=(1, 60),
           title="h20: every member reproduces F_max = 1004 N, eps = 0.59")
    ax.yaxis.set_major_formatter(matplotlib.ticker.ScalarFormatter())
    ax.set_yticks([1, 1.2, 2, 2.64, 5, 10, 20, 50])
    ax.legend(fontsize=7)
    ax = axes[0, 1]
    for pr in predictions:
        ax.plot(pr["t"] * 1e3, pr["force"], label=f"alpha = {pr['mb']['alpha']:g}")
    ax.set(xlabel="time [ms]", ylabel="contact force [N]", title="their force curves at 20 mm")
    ax.legend(fontsize=7)
    for ax, key, label in ((axes[1, 0], "F", "peak force F_max [N]"),
                           (axes[1, 1], "eps", "restitution coefficient eps")):
        for pr in predictions:
            ax.plot(heights * 1e3, pr[key], marker=".", label=f"alpha = {pr['mb']['alpha']:g}")
        ax.plot([20], [PAPER["F_peak"] if key == "F" else PAPER["eps"]], "k*", ms=10, label="paper, h20")
        ax.set(xlabel="drop height [mm]", ylabel=label, title="their predictions over the paper's campaign")
    axes[1, 1].legend(fontsize=7)
    for ax in axes.flat:
        ax.grid(alpha=0.3)
    output.save(fig, path)


def synthetic_drops(params, heights, repeats, noise_F, noise_eps, seed, sigmas=False):
    """F_max and eps the member makes at the heights, repeated, with relative noise on F and absolute on eps."""
    r = model.impacts(**dict(params, v=np.array([model.drop_velocity(h) for h in heights])))
    rng = np.random.default_rng(seed)
    h = np.repeat(heights, repeats)
    F = np.repeat(r["F_peak"], repeats) * (1 + noise_F * rng.normal(size=len(h)))
    eps = np.repeat(r["eps"], repeats) + noise_eps * rng.normal(size=len(h))
    return fit.Drops(v=np.array([model.drop_velocity(x) for x in h]), F=F, eps=eps,
                     sigma_F=noise_F * F if sigmas else None, sigma_eps=np.full(len(h), noise_eps) if sigmas else None,
                     heights=h.tolist())


def synthetic_curve(params, height, noise, seed, interval=2e-6):
    s = model.simulate(output_interval=interval, **dict(params, v=model.drop_velocity(height)))
    F = s["F"] + np.random.default_rng(seed).normal(0.0, noise, len(s["F"]))
    return fit.Curve(s["t"], F, model.drop_velocity(height), height, f"{height * 1e3:g} mm")


def identifiability_section(base, truth_member):
    """Data sets made by one member of the h20 family, fitted with alpha free: what identifies it."""
    params = member_params(base, truth_member, None, base.dt_max / 2)   # the data at half the fit's step
    del params["v"]
    truth = dict(k=truth_member["k"], c_alpha=truth_member["c_alpha"], alpha=truth_member["alpha"])
    m = PAPER["m"]
    cases = [
        ("h20: F_max and eps (the paper's row, exact)", lambda: fit.fit_drops(
            synthetic_drops(params, [0.020], 1, 0.0, 0.0, None), m, damper=2)),
        ("h20, three repeats (1 % on F_max, 0.01 on eps)", lambda: fit.fit_drops(
            synthetic_drops(params, [0.020], 3, 0.01, 0.01, 51), m, damper=2)),
        ("5, 10, 20, 50, 100 mm, exact", lambda: fit.fit_drops(
            synthetic_drops(params, [0.005, 0.01, 0.02, 0.05, 0.1], 1, 0.0, 0.0, None), m, damper=2)),
        ("5, 10, 20, 50, 100 mm, sigmas given (1 %, 0.01)", lambda: fit.fit_drops(
            synthetic_drops(params, [0.005, 0.01, 0.02, 0.05, 0.1], 1, 0.01, 0.01, 52, sigmas=True), m, damper=2)),
        ("the campaign: 5 to 100 mm by 5, three repeats (1 %, 0.01)", lambda: fit.fit_drops(
            synthetic_drops(params, HEIGHTS_MM / 1e3, 3, 0.01, 0.01, 53), m, damper=2)),
        ("two heights, 10 and 50 mm, three repeats (1 %, 0.01)", lambda: fit.fit_drops(
            synthetic_drops(params, [0.01, 0.05], 3, 0.01, 0.01, 54), m, damper=2)),
        ("the h20 force curve (2 us sampling, 5 N noise)", lambda: fit.fit_curves(
            [synthetic_curve(params, 0.020, 5.0, 55)], m, damper=2)),
        ("force curves at 10, 20, 50 mm (5 N noise)", lambda: fit.fit_curves(
            [synthetic_curve(params, h, 5.0, 56 + i) for i, h in enumerate((0.01, 0.02, 0.05))], m, damper=2)),
    ]
    lines = ["## What identifies alpha: fits of data one member makes", "",
             f"The truth: the h20 family's member at alpha = {truth['alpha']:g} (k = {truth['k']:.4g} N/m^1.5, "
             f"c_alpha = {truth['c_alpha']:.4g} N s^alpha/m), which reproduces the paper's row. Its data are made at "
             "half the fit's step (never the fit's own discretisation), then fitted with alpha free "
             "(`fraccontact fit --drops FILE --damper 2`, `--curve FILE --height H --damper 2`). Errors are one "
             "standard error; (fit - truth) / error in brackets (for exact data the relative error).", "",
             "| data | verdict | k [N/m^1.5] | c_alpha [N s^alpha/m] | alpha | condition | time |",
             "|---|---|---|---|---|---|---|"]
    for label, run in cases:
        start = time.perf_counter()
        r = run()[0]
        seconds = time.perf_counter() - start
        if not r["identifiable"]:
            condition = r.get("condition")
            condition = "" if condition in (None, math.inf) else f"{condition:.3g}"
            lines.append(f"| {label} | not identifiable: {r['reason'].split(':')[0]} | | | | {condition} | "
                         f"{seconds:.1f} s |")
            continue
        cells = []
        for name in ("k", "c_alpha", "alpha"):
            if "exact" in label:     # no noise: the standard errors measure the model's 1e-6, show the deviation
                cells.append(f"{output.significant(r[name], 6)} (relative error {r[name] / truth[name] - 1:+.1e})")
                continue
            sigma = r[f"sigma_{name}"]
            cells.append(f"{output.with_error(r[name], sigma, '')} ({(r[name] - truth[name]) / sigma:+.1f})")
        lines.append(f"| {label} | identified | " + " | ".join(cells) + f" | {r['condition']:.3g} | {seconds:.1f} s |")
    lines += ["", "One drop test's two numbers cannot identify three parameters, and repeating the test adds "
              "scatter, not a direction (the Jacobian keeps rank 2). A second height does, through the peak force's "
              "growth with the impact speed, which depends on the order. A force curve does on its own: its shape, "
              "not just its peak and impulse, carries alpha. Over 40 noise draws the standard "
              "errors matched the scatter (tests/test_fit.py: (fit - truth) / error with standard deviations 0.95 "
              "to 1.06 for curves and 1.05 to 1.12 for tables with sigmas; with the common error scale estimated "
              "from few degrees of freedom the Student t widens that, 1.3 at 7)."]
    return lines + [""]


def main(argv=None, prog=None):
    parser = output.parser(prog, __doc__)
    parser.add_argument("--impacts", type=int, default=4000, help="impacts for the throughput runs (default 4000)")
    args = output.parse(parser, argv)
    output.pyplot()  # before the minutes of sweeps: a missing matplotlib is said at once
    with tempfile.TemporaryDirectory() as work:
        write_report(args, pathlib.Path(work))


def write_report(args, work):
    v = model.drop_velocity(PAPER["height"])
    k, c = fit.fit_peak_and_restitution(PAPER["F_peak"], PAPER["eps"], PAPER["m"], v)
    E_s = fit.specimen_modulus(k, H20["R"], H20["E_i"], H20["nu_i"], H20["nu_s"])
    at_paper = fit.run(PAPER["k"], PAPER["c"], PAPER["m"], v)
    paper_rows = heights_sweep(work / "paper", PAPER["k"], PAPER["c"])
    fitted_rows = heights_sweep(work / "fitted", k, c)
    plot(args.out / "calibration_sweep.png", paper_rows, fitted_rows)
    springpot, base, truth_member = family_section(args.out)
    identify = identifiability_section(base, truth_member)
    one = throughput(work / "one", 1, args.impacts)
    two = throughput(work / "two", 2, args.impacts)
    lines = ["# Calibration from drop tests", "",
             "Regenerate: `scripts/report calibration` (about half a minute; writes this file, "
             "`calibration_sweep.png` and `calibration_family.png`).", "",
             "## The paper's h20 row", "",
             f"`fraccontact fit --F-peak 1004 --eps 0.59 --height 0.020 --m {PAPER['m']:g}` (Hertz law; indenter "
             f"E_i = {H20['E_i'] / 1e9:g} GPa, nu_i = {H20['nu_i']:g}, nu_s = {H20['nu_s']:g}, "
             f"R = {H20['R'] * 1e3:g} mm):", "",
             "| | k [N/m^1.5] | c [N s/m] | E_s [GPa] | F_peak [N] | eps |", "|---|---|---|---|---|---|",
             f"| paper, Table 1 | {PAPER['k']:.4g} | {PAPER['c']:.4g} | {PAPER['E_s'] / 1e9:.3g} | 1004 (measured) | "
             f"0.59 (measured) |",
             f"| this model with the paper's k, c | {PAPER['k']:.4g} | {PAPER['c']:.4g} | | {at_paper.F_peak:.1f} | "
             f"{at_paper.eps:.4f} |",
             f"| fitted here | {k:.4g} | {c:.4g} | {E_s / 1e9:.3g} | 1004.0 | 0.5900 |", "",
             f"The fit gives k {100 * (k / PAPER['k'] - 1):+.1f} %, c {100 * (c / PAPER['c'] - 1):+.1f} % and E_s "
             f"{100 * (E_s / PAPER['E_s'] - 1):+.1f} % against the paper: its constants were fitted through its own "
             "discrete scheme, which with them gives 1004 N where the exact model gives "
             f"{at_paper.F_peak:.0f} N. Either way the modulus stays about twice the 1.2 GPa of impact-tensile "
             "tests, as the paper says.", ""] + springpot + identify + [
             "## Drop-height sweep", "",
             "`fraccontact sweep --vary height=0.005:0.1:0.005 --set law=hertz --set k=... --set c=...`, at the "
             "paper's constants and at "
             "the fitted ones. Peak force rises and contact time falls with the impact energy, as the paper's "
             "measurements do.", "", "![sweep](calibration_sweep.png)", "",
             "| height [mm] | F_peak [N], paper's k, c | eps | F_peak [N], fitted | eps |", "|---|---|---|---|---|"]
    for p, f in zip(paper_rows, fitted_rows):
        lines.append(f"| {p['height'] * 1e3:.0f} | {p['F_peak']:.1f} | {p['eps']:.4f} | {f['F_peak']:.1f} | "
                     f"{f['eps']:.4f} |")
    lines += ["", "## Throughput", "",
              f"A Monte Carlo campaign of {args.impacts} impacts (k and c scattered by 5 % and 10 %, Hertz law, "
              "dt = 1e-7 s, about 13 000 internal steps an impact) on a local Dask cluster, each task a chunk of "
              "impacts in one call of the C library (`fraccontact sweep`, four tasks per worker):", "",
              "| workers | impacts per second | wall time |", "|---|---|---|",
              f"| 1 | {one['impacts_per_second']:.0f} | {one['wall_seconds']:.1f} s |",
              f"| 2 | {two['impacts_per_second']:.0f} | {two['wall_seconds']:.1f} s |", "",
              f"Two workers on this 2-core machine: {two['impacts_per_second'] / one['impacts_per_second']:.2f} times "
              "one. The same command takes `--scheduler tcp://HOST:8786` to spread a campaign over the workers of "
              "any running Dask scheduler (whose workers must have the package installed)."]
    atomic.write_text(args.out / "calibration.md", "\n".join(lines) + "\n")
    print((args.out / "calibration.md").read_text())

