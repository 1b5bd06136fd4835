"""What a fit prints and draws: the result as text (name = value ± error
unit), the joint fit's table of tests, the family of solutions; and the
measured data against the fitted model's."""

import numpy as np

from .. import hertz, model
from ..output import pyplot, save, significant, with_error
from . import runs
from .drops import K_CAP


def parameters_label(result):
    """'k = ... , c = ...' (or c_alpha, alpha) with errors, for a legend."""
    parts = [f"k = {with_error(result['k'], result.get('sigma_k'), 'N/m^1.5')}"]
    if "c" in result:
        parts.append(f"c = {with_error(result['c'], result.get('sigma_c'), 'N s/m')}")
    else:
        parts.append(f"c_alpha = {with_error(result['c_alpha'], result.get('sigma_c_alpha'), 'N s^alpha/m')}")
        parts.append(f"alpha = {with_error(result['alpha'], result.get('sigma_alpha'), '')}".rstrip())
    return ",\n".join(parts)


def plot_curves(path, curves, result, fitted, x):
    """Measured against fitted force [N] over time [ms], every curve."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.2))
    p = fitted.size
    for j, (c, test) in enumerate(zip(curves, result["tests"])):
        dots = ax.plot(c.t * 1e3, c.F, ".", ms=3, label=f"measured {c.source}" if len(curves) > 1 else "measured")
        tt = np.linspace(c.t.min(), c.t.max(), 800)
        tc = hertz.contact_time(fitted.k_ref, fitted.m, c.v)
        tm, Fm = runs.series(fitted, x[:p], c.v, tc / runs.ROWS_PER_CONTACT)
        ax.plot(tt * 1e3, np.interp(tt - test["t0"], tm, Fm, left=0.0, right=0.0), color="k" if len(curves) == 1
                else dots[0].get_color(), lw=1, label="fitted" if j == 0 else None)
    ax.set(xlabel="time [ms]", ylabel="contact force [N]", title="Measured against fitted force")
    ax.text(0.98, 0.97, parameters_label(result), transform=ax.transAxes, ha="right", va="top", fontsize=8)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    save(fig, path, dpi=110)


def plot_drops(path, drops, result, fitted, x):
    """F_max and eps against drop height, measured and fitted."""
    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    heights = np.array(drops.heights if drops.heights is not None else drops.v ** 2 / (2 * 9.81))
    h = np.linspace(0.5 * heights.min(), 1.1 * heights.max(), 60)
    F, eps = runs.figures(fitted, [x], [model.drop_velocity(a) for a in h])
    sF, sE = (drops.sigma_F, drops.sigma_eps) if drops.absolute else (None, None)
    for ax, measured, sigma, line, label in ((axes[0], drops.F, sF, F[0], "peak force F_max [N]"),
                                             (axes[1], drops.eps, sE, eps[0], "restitution coefficient eps")):
        ax.errorbar(heights * 1e3, measured, yerr=sigma, fmt="o", ms=4, label="measured")
        ax.plot(h * 1e3, line, label="fitted")
        ax.set(xlabel="drop height [mm]", ylabel=label)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    axes[1].text(0.98, 0.97, parameters_label(result), transform=axes[1].transAxes, ha="right", va="top", fontsize=8)
    fig.suptitle(f"Drop tests fitted at once ({runs.DAMPERS[fitted.damper]}, m = {fitted.m:g} kg)")
    save(fig, path, dpi=110)


def plot_family(path, fam, E_s):
    """The family of solutions: k, c_alpha and E_s against alpha."""
    plt = pyplot()
    rows = [mb for mb in fam["members"] if mb["in_family"]]
    a = np.array([mb["alpha"] for mb in rows])
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.8))
    series_ = ((axes[0], [mb["k"] for mb in rows], "k [N/m^1.5]"),
               (axes[1], [mb["c_alpha"] for mb in rows], "c_alpha [N s^alpha/m]"),
               (axes[2], [np.nan if e is None else e / 1e9 for e in E_s], "E_s [GPa]"))
    for ax, values, label in series_:
        ax.semilogy(a, values, "o-", ms=4)
        if fam["alpha_min"] is not None:
            ax.axvline(fam["alpha_min"], color="grey", ls=":", label=f"alpha_min = {fam['alpha_min']:.3f}")
        ax.set(xlabel="springpot order alpha", ylabel=label)
        ax.grid(alpha=0.3, which="both")
    axes[0].legend(fontsize=8)
    fig.suptitle("One drop test, three parameters: every member reproduces F_max and eps")
    save(fig, path, dpi=110)


def text_report(result):
    """The result as lines of 'name = value ± error unit'."""
    quantity = lambda key, unit: with_error(result[key], result.get(f"sigma_{key}"), unit)
    lines = [f"k      = {quantity('k', 'N/m^1.5')}"]
    if "c" in result:
        lines.append(f"c      = {quantity('c', 'N s/m')}")
    else:
        lines.append(f"c_alpha = {quantity('c_alpha', 'N s^alpha/m')}")
        lines.append(f"alpha  = {quantity('alpha', '')}" + ("   (fixed: --damper-order)" if result.get("alpha_fixed")
                                                            else "   (at its bound 1: the dashpot)"
                                                            if result.get("at_bound") else ""))
    if "t0" in result:
        lines.append(f"t0     = {quantity('t0', 's')}   (contact onset on the file's time axis)")
    lines.append(f"E_s    = {quantity('E_s', 'Pa')}")
    if "F_peak" in result:
        lines += [f"F_peak = {quantity('F_peak', 'N')}   (the model's, at the fitted values)",
                  f"eps    = {quantity('eps', '')}   (the model's, at the fitted values)"]
    second = "c" if "c" in result else "c_alpha"
    if "correlation" in result:
        lines.append(f"correlation of k and {second} = {result['correlation']:.3f}")
    if "correlations" in result:
        lines.append("correlations: " + ", ".join(f"{pair.replace(',', '-')} {value:.3f}"
                                                  for pair, value in result["correlations"].items()))
    if result.get("condition") is not None and (result.get("n_tests", 1) > 1 or "correlations" in result):
        lines.append(f"identifiable: {result['n_data']} data for {result['n_params']} parameters, condition number "
                     f"of the Jacobian {result['condition']:.3g}")
    if "rms_residual" in result:
        lines += [f"rms residual = {significant(result['rms_residual'], 3)} N",
                  f"lag-1 autocorrelation of the residuals = {result['residual_autocorrelation']:.3f}"]
    if "residual_scale" in result:
        lines.append(f"residual scale = {significant(result['residual_scale'], 3)} (relative F_max, absolute eps; "
                     f"{result['dof']} degrees of freedom)")
    if "chi2" in result:
        lines.append(f"chi-square = {significant(result['chi2'], 3)} for {result['dof']} degrees of freedom")
    if result.get("n_tests", 1) > 1 and "tests" in result:
        lines += test_table(result["tests"])
    lines.append(f"v = {result['v']:.6g} m/s, m = {result['m']:.6g} kg, law {result['law']}, damper "
                 f"{result.get('damper', 1)} ({runs.DAMPERS[result.get('damper', 1)]})" if "v" in result else
                 f"m = {result['m']:.6g} kg, law {result['law']}, damper {result['damper']} "
                 f"({runs.DAMPERS[result['damper']]})")
    return "\n".join(lines)


def test_table(tests):
    """The tests of a joint fit, one line each, measured beside the model's."""
    curves = "t0" in tests[0]
    if curves:
        head = ["height [m]", "v [m/s]", "t0 [s]", "rms [N]", "F_max [N]", "F_peak [N] (model)", "eps (model)"]
    else:
        head = ["height [m]", "v [m/s]", "F_max [N]", "F_peak [N] (model)", "eps", "eps (model)"]
    rows = []
    for t in tests:
        height = "-" if t.get("height") is None else f"{t['height']:.6g}"
        model_ = [with_error(t["F_peak"], t.get("sigma_F_peak"), ""), with_error(t["eps"], t.get("sigma_eps"), "")]
        if curves:
            rows.append([height, f"{t['v']:.6g}", with_error(t["t0"], t["sigma_t0"], ""),
                         significant(t["rms_residual"], 3), significant(t["F_max"], 6), *model_])
        else:
            rows.append([height, f"{t['v']:.6g}", with_error(t["F_max"], t.get("sigma_F_max"), ""), model_[0],
                         with_error(t["eps_measured"], t.get("sigma_eps_measured"), ""), model_[1]])
    widths = [max(len(r[j]) for r in rows + [head]) for j in range(len(head))]
    return ["  ".join(cell.rjust(w) for cell, w in zip(r, widths)) for r in [head] + rows]


def family_report(result):
    """The one-line verdict, then the family's table."""
    fam, one = result["family"], result["n_tests"] == 1
    lines = [f"not identifiable: {result['reason']}; " + (
        "for each alpha below, k and c_alpha reproduce F_max and eps (a one-parameter family):" if one else
        "for each alpha below, the best k and c_alpha; those marked * fit equally well (a one-parameter family):")]
    last = f"{'F_peak [N]':>11}  {'eps':>8}" if one else f"{'rms residual':>12}"
    lines.append(f"{'alpha':>5}  {'k [N/m^1.5]':>12}  {'c_alpha [N s^alpha/m]':>21}  {'E_s [Pa]':>9}  {last}")
    for mb, E_s in zip(fam["members"], result["E_s_family"]):
        if not mb["in_family"]:
            why = "needs k above the cap (a rigid spring)" if mb["k_capped"] else f"fits worse (rms {mb['rms']:.3g})"
            lines.append(f"{mb['alpha']:5.2f}  out of reach: {why}")
            continue
        figures_ = (f"{significant(mb['F_peak'][0], 6):>11}  {mb['eps'][0]:8.6f}" if one else
                    f"{significant(mb['rms'], 4):>12}")
        lines.append(f"{mb['alpha']:5.2f}{'' if one else '*'}  {significant(mb['k'], 6):>12}  "
                     f"{significant(mb['c_alpha'], 6):>21}  {'-' if E_s is None else significant(E_s, 4):>9}  {figures_}")
    if fam["alpha_min"] is not None and fam["alpha_min_bounded"]:
        lines.append(f"alpha_min = {fam['alpha_min']:.4f}: below it no k up to {fam['k_cap']:.3g} N/m^1.5 "
                     f"({K_CAP:g} x the elastic Hertz k of F_max: a rigid spring) {'reaches them' if one else 'fits as well'}")
    if any(E is None and mb["in_family"] for E, mb in zip(result["E_s_family"], fam["members"])):
        lines.append("E_s '-': k stiffer than the indenter alone allows (no specimen modulus gives it)")
    lines.append("--damper-order picks one member; several heights (--drops) or a force curve (--curve) identify alpha")
    lines.append(f"m = {result['m']:.6g} kg, law {result['law']}, damper 2 (springpot)")
    return "\n".join(lines)
