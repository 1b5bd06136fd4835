"""Material identification from drop tests, as the paper does it: find the
Hertz constant k and the dashpot c that reproduce a test's peak force and
restitution coefficient, then the specimen's Young's modulus from k
(MODEL.md §2, §6). Or fit k and c to a whole measured force-time curve by
least squares, with their uncertainty and a plot.

  scripts/fit --fmax 1004 --eps 0.59 --height 0.020 --mass 0.7437 --json
  scripts/fit --curve test.csv --height 0.020 --mass 0.7437 --plot fit.png

The model is fraccontact-solve (build/), the Hertz law by default.
"""

import argparse
import csv
import json
import math
import os
import pathlib
import subprocess
import sys
import tempfile

import numpy as np
from scipy.optimize import brentq, least_squares

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOLVER = pathlib.Path(os.environ.get("FRACCONTACT_SOLVE", ROOT / "build" / "fraccontact-solve"))
G = 9.81


class Unreachable(Exception):
    """No k, c of this model reproduce what was asked."""


def hertz_time(k, m, v0):
    """The Hertz contact time of k, m, v0: the scale of every step here."""
    return 2.94327 * (5 * m * v0 ** 2 / (4 * k)) ** 0.4 / v0


def simulate(k, c, m, v0, law="hertz", csv_path=None, interval=None):
    """One impact with fraccontact-solve; its JSON (and a CSV if asked)."""
    t_c = hertz_time(k, m, v0)
    args = [SOLVER, "--json", "--quiet", "--law", law, "--k", k, "--c", c, "--m", m, "--v0", v0,
            "--dt", t_c / 4000, "--t-end", 1000 * t_c + 1.0]
    if csv_path:
        args += ["--csv", csv_path, "--output-interval", interval]
    done = subprocess.run([str(a) for a in args], capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"fraccontact-solve failed: {done.stderr.strip()}")
    return json.loads(done.stdout)


def specimen_modulus(k, R, E_i, nu_i, nu_s):
    """E_s from k = (4/3) E* sqrt(R), 1/E* = (1 - nu_i^2)/E_i + (1 - nu_s^2)/E_s."""
    inv_E_star = 4.0 * math.sqrt(R) / (3.0 * k)
    rest = inv_E_star - (1 - nu_i ** 2) / E_i
    if rest <= 0:
        raise Unreachable(f"k = {k:.6g} N/m^1.5 is stiffer than the indenter alone allows "
                          f"(E_i = {E_i:g} Pa, R = {R:g} m): no specimen modulus gives it")
    return (1 - nu_s ** 2) / rest


def k_for_peak(F_max, c, m, v0, law):
    """The k that gives the peak force F_max with dashpot c. F_max(k) rises
    with k towards c v0 (a rigid spring leaves the dashpot alone), so it is
    reachable only below that."""
    if F_max >= c * v0:
        raise Unreachable(f"F_max = {F_max:g} N needs c > F_max / v0 = {F_max / v0:g} N s/m")
    k0 = (F_max / (1.25 * m * v0 ** 2) ** 0.6) ** 2.5           # Hertz, no dashpot
    f = lambda log_k: simulate(math.exp(log_k), c, m, v0, law)["F_peak"] / F_max - 1
    lo, hi = math.log(k0) - 1, math.log(k0) + 1
    while f(lo) > 0:
        lo -= 2
    while f(hi) < 0:
        hi += 2
        if hi > math.log(k0) + 60:
            raise Unreachable(f"F_max = {F_max:g} N is out of reach with c = {c:g} N s/m")
    return math.exp(brentq(f, lo, hi, xtol=1e-11, rtol=1e-11))


def fit_peak_and_restitution(F_max, eps, m, v0, law="hertz"):
    """k, c reproducing F_max and eps. For each c, k follows from F_max; eps
    then rises with c, from 0 (a soft dashpot never lets go) towards 1."""
    if not (0 < eps < 1):
        raise Unreachable(f"eps = {eps:g}: this model gives 0 < eps < 1")
    if not (F_max > 0 and m > 0 and v0 > 0):
        raise Unreachable("F_max, the mass and the impact velocity must be positive")

    def eps_error(log_c):
        c = math.exp(log_c)
        return simulate(k_for_peak(F_max, c, m, v0, law), c, m, v0, law)["eps"] - eps

    lo = math.log(F_max / v0) + 0.02                              # just above c v0 = F_max
    hi = lo + 2
    while eps_error(hi) < 0:
        hi += 2
        if hi > lo + 60:
            raise Unreachable(f"eps = {eps:g} is out of reach with F_max = {F_max:g} N")
    if eps_error(lo) > 0:
        raise Unreachable(f"eps = {eps:g} is too small for F_max = {F_max:g} N at v0 = {v0:g} m/s: even the "
                          f"softest dashpot that reaches F_max rebounds more")
    c = math.exp(brentq(eps_error, lo, hi, xtol=1e-10, rtol=1e-10))
    return k_for_peak(F_max, c, m, v0, law), c


def read_curve(path):
    """Time [s] and force [N] columns of a CSV (the first two, a header allowed)."""
    t, F = [], []
    with open(path) as f:
        for row in csv.reader(f):
            try:
                t.append(float(row[0]))
                F.append(float(row[1]))
            except (ValueError, IndexError):
                if t:
                    raise SystemExit(f"fit: {path}: a row that is not two numbers: {row}")
    if len(t) < 5:
        raise SystemExit(f"fit: {path}: fewer than 5 (time, force) rows")
    return np.array(t), np.array(F)


def model_curve(k, c, m, v0, t, law):
    """The model's force at the times t (linear interpolation of a fine series)."""
    interval = hertz_time(k, m, v0) / 2000
    with tempfile.TemporaryDirectory() as tmp:
        path = pathlib.Path(tmp) / "run.csv"
        simulate(k, c, m, v0, law, path, interval)
        data = np.loadtxt(path, delimiter=",", skiprows=1, usecols=(0, 1))
    return np.interp(t, data[:, 0], data[:, 1], right=0.0)


def fit_curve(t, F, m, v0, law="hertz"):
    """Least squares on log k, log c. The start: F_max from the curve, eps
    from its impulse (m v0 (1 + eps)), through fit_peak_and_restitution."""
    impulse = float(np.trapezoid(F, t)) if hasattr(np, "trapezoid") else float(np.trapz(F, t))
    eps0 = min(max(impulse / (m * v0) - 1, 0.05), 0.95)
    k0, c0 = fit_peak_and_restitution(float(F.max()), eps0, m, v0, law)
    residual = lambda x: model_curve(math.exp(x[0]), math.exp(x[1]), m, v0, t, law) - F
    result = least_squares(residual, [math.log(k0), math.log(c0)], diff_step=1e-5, xtol=1e-10, ftol=1e-10)
    k, c = np.exp(result.x)
    dof = max(len(t) - 2, 1)
    s2 = float(result.fun @ result.fun) / dof
    cov_log = s2 * np.linalg.inv(result.jac.T @ result.jac)
    return dict(k=float(k), c=float(c), sigma_k=float(k * math.sqrt(cov_log[0, 0])),
                sigma_c=float(c * math.sqrt(cov_log[1, 1])), correlation=float(cov_log[0, 1] / math.sqrt(
                    cov_log[0, 0] * cov_log[1, 1])), rms_residual=math.sqrt(s2), cov_log=cov_log.tolist())


def plot_curve(path, t, F, fitted, m, v0, law):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import atomic
    fig, ax = plt.subplots(figsize=(7, 4.2))
    ax.plot(t * 1e3, F, ".", ms=3, label="measured")
    tt = np.linspace(0, t.max(), 800)
    ax.plot(tt * 1e3, model_curve(fitted["k"], fitted["c"], m, v0, tt, law), label=(
        f"fitted: k = {fitted['k']:.4g} ± {fitted['sigma_k']:.2g} N/m^1.5, c = {fitted['c']:.4g} ± "
        f"{fitted['sigma_c']:.2g} N s/m"))
    ax.set(xlabel="time [ms]", ylabel="contact force [N]", title="Measured against fitted force")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    atomic.save_figure(fig, path, dpi=110, metadata={"Software": None})


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    what = parser.add_mutually_exclusive_group(required=True)
    what.add_argument("--fmax", type=float, help="measured peak force [N] (with --eps)")
    what.add_argument("--curve", type=pathlib.Path, help="CSV of the measured force: time [s], force [N]")
    parser.add_argument("--eps", type=float, help="measured restitution coefficient (with --fmax)")
    speed = parser.add_mutually_exclusive_group(required=True)
    speed.add_argument("--height", type=float, help="drop height [m]: v0 = sqrt(2 g h)")
    speed.add_argument("--v0", type=float, help="impact velocity [m/s]")
    parser.add_argument("--mass", type=float, required=True, help="striker mass [kg]")
    parser.add_argument("--R", type=float, default=6.35e-3, help="striker tip radius [m] (default 6.35e-3)")
    parser.add_argument("--E-i", type=float, default=210e9, help="indenter Young's modulus [Pa] (default 210e9)")
    parser.add_argument("--nu-i", type=float, default=0.3, help="indenter Poisson ratio (default 0.3)")
    parser.add_argument("--nu-s", type=float, default=0.4, help="specimen Poisson ratio (default 0.4)")
    parser.add_argument("--law", choices=("hertz", "g1", "g1x"), default="hertz",
                        help="spring law of the model fitted (default hertz)")
    parser.add_argument("--plot", type=pathlib.Path, help="with --curve: a PNG of measured against fitted")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    args = parser.parse_args(argv)
    if args.fmax is not None and args.eps is None:
        parser.error("--fmax needs --eps")
    if not SOLVER.exists():
        parser.error(f"{SOLVER} does not exist: run scripts/build (scripts/fit does)")
    if args.height is not None and not args.height > 0:
        parser.error("--height must be positive")
    v0 = math.sqrt(2 * G * args.height) if args.height is not None else args.v0
    try:
        if args.curve:
            t, F = read_curve(args.curve)
            result = fit_curve(t, F, args.mass, v0, args.law)
            if args.plot:
                plot_curve(args.plot, t, F, result, args.mass, v0, args.law)
        else:
            k, c = fit_peak_and_restitution(args.fmax, args.eps, args.mass, v0, args.law)
            check = simulate(k, c, args.mass, v0, args.law)
            result = dict(k=k, c=c, F_max_model=check["F_peak"], eps_model=check["eps"])
        result["E_s"] = specimen_modulus(result["k"], args.R, args.E_i, args.nu_i, args.nu_s)
        if "sigma_k" in result:  # dE_s/dk by a relative step of 1e-6
            dk = 1e-6 * result["k"]
            result["sigma_E_s"] = abs(specimen_modulus(result["k"] + dk, args.R, args.E_i, args.nu_i, args.nu_s)
                                      - result["E_s"]) / dk * result["sigma_k"]
    except Unreachable as e:
        print(f"fit: not reachable by this model: {e}", file=sys.stderr)
        return 2
    result.update(v0=v0, mass=args.mass, law=args.law)
    result.pop("cov_log", None)
    if args.json:
        print(json.dumps(result))
    else:
        for key, value in result.items():
            print(f"{key:14s} {value}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
