"""fraccontact run: the paper's h20 drop test through the FMU with fmpy: prints F_peak, eps,
contact time and permanent indentation for both spring laws next to the
paper's Table 1, and writes the time series (CSV) and a plot (PNG).

Regenerate: scripts/run   (fraccontact run --help)
"""

import csv
import sys

from fmpy import simulate_fmu
from fmpy.fmi1 import FMICallException

from . import atomic, fmu, model, output
from .options import positive

plt = output.pyplot()

PAPER = {"F_peak": 1004.0, "eps": 0.59}  # docs/model.md §1, Table 1, h20
LAWS = {1: "G1 history sum (law 1)", 2: "closed-form Hertz (law 2)"}
OUTPUTS = ["F", "x", "x1", "x2", "v_striker", "eps", "F_peak", "E_diss", "contact"]
# fmpy holds every row as a tuple of Python floats until the end of a run, and the CSV writes them all:
# the rows a run may make (stop time / output interval), within a desktop's memory and a few minutes.
MAX_ROWS = 1_000_000


def simulate(fmu, law, stop_time, output_interval):
    return simulate_fmu(str(fmu), start_values={"law": law}, stop_time=stop_time,
                        output_interval=output_interval, output=OUTPUTS)


def ended(result):
    """Whether the first impact has ended (the FMU's eps is 0 before one ends)."""
    return bool((result["eps"] > 0.0).any())


def summary(result):
    """Figures of the first impact, from the outputs once it has ended."""
    last = result[-1]
    # After separation the striker flies freely (no gravity here), so the
    # separation time follows from the gap it has opened since.
    t_sep = last["time"] - (last["x"] - last["x2"]) / last["v_striker"]
    return {"F_peak": float(last["F_peak"]), "eps": float(last["eps"]), "t_contact": float(t_sep),
            "x2": float(last["x2"]), "E_diss": float(last["E_diss"])}


def print_table(figures):
    print(f"{'':28s} {'F_peak [N]':>11s} {'eps':>8s} {'t_contact [ms]':>15s} "
          f"{'x2 [um]':>12s} {'E_diss [mJ]':>12s}")
    for law, f in figures.items():
        print(f"{LAWS[law]:28s} {f['F_peak']:11.2f} {f['eps']:8.4f} {f['t_contact'] * 1e3:15.5f} "
              f"{f['x2'] * 1e6:12.3f} {f['E_diss'] * 1e3:12.3f}")
    print(f"{'paper, Table 1 (h20)':28s} {PAPER['F_peak']:11.2f} {PAPER['eps']:8.4f}")


def write_csv(path, results):
    with atomic.replacing(path, newline="") as f:
        w = csv.writer(f)
        w.writerow(["time_s"] + [f"{n}_law{law}" for law in results for n in ("F_N", "x_m", "x1_m", "x2_m")])
        first = next(iter(results.values()))
        for i in range(len(first)):
            row = [f"{first['time'][i]:.9g}"]
            for r in results.values():
                row += [f"{r[n][i]:.10g}" for n in ("F", "x", "x1", "x2")]
            w.writerow(row)


def plot(path, results, figures):
    fig, (ax_t, ax_x, ax_d) = plt.subplots(1, 3, figsize=(15, 4.2))
    for law, r in results.items():
        inside = r["time"] <= figures[law]["t_contact"]
        ax_t.plot(r["time"][inside] * 1e3, r["F"][inside], label=LAWS[law])
        ax_x.plot(r["x"][inside] * 1e3, r["F"][inside], label=LAWS[law])
    # The two laws overlap at this scale: show their difference on its own.
    r1, r2 = results[1], results[2]
    inside = r1["time"] <= figures[2]["t_contact"]
    ax_d.plot(r1["time"][inside] * 1e3, r1["F"][inside] - r2["F"][inside], color="C2")
    ax_d.set(xlabel="time [ms]", ylabel="F(law 1) - F(law 2) [N]",
             title="G1 law minus Hertz (dt_max = 1e-7 s)")
    ax_d.grid(alpha=0.3)
    ax_t.axhline(PAPER["F_peak"], color="gray", ls=":", label="paper's F_max (1004 N)")
    ax_t.set(xlabel="time [ms]", ylabel="contact force F [N]", title="Force against time")
    ax_x.set(xlabel="total indentation x [mm]", ylabel="contact force F [N]",
             title="Force against indentation (loop = dissipation)")
    for ax in (ax_t, ax_x):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    h20 = model.defaults()
    k = f"{h20['k']:.4g}".replace("e+0", "e")
    fig.suptitle(f"h20 drop test: m = {h20['m']:g} kg, v0 = {h20['v']:.3g} m/s, k = {k} N/m^1.5, "
                 f"c = {h20['c']:g} N s/m")
    output.save(fig, path, dpi=110)


def check(parser, args):
    """The options together, before the run: the FMU is the contact element,
    and the rows (stop time / output interval) are at most MAX_ROWS."""
    try:
        fmu.description(args.fmu, ["law"] + OUTPUTS)
    except ValueError as e:
        parser.error(f"--fmu {args.fmu}: {e}; expected the contact FMU (fraccontact.fmu)")
    if args.output_interval > args.stop_time:
        parser.error(f"--output-interval {args.output_interval:g} s is longer than --stop-time {args.stop_time:g} s")
    rows = args.stop_time / args.output_interval
    if rows > MAX_ROWS:
        parser.error(f"--output-interval {args.output_interval:g} s over --stop-time {args.stop_time:g} s gives "
                     f"{rows:.3g} rows; at most {MAX_ROWS:.0e} (stop time / output interval)")


def main(argv=None, prog=None):
    parser = output.parser(prog, __doc__, "folder for h20_drop.csv and h20_drop.png (default: docs/)")
    output.add_fmu(parser)
    parser.add_argument("--stop-time", type=positive, default=3e-3, help="simulated time [s] (default 3e-3)")
    parser.add_argument("--output-interval", type=positive, default=2e-6,
                        help=f"output sampling [s] (default 2e-6; at most {MAX_ROWS:.0e} rows: stop time / interval)")
    args = output.parse(parser, argv, check)

    try:
        results = {law: simulate(args.fmu, law, args.stop_time, args.output_interval) for law in LAWS}
    except FMICallException as e:  # fmpy has printed the FMU's message, which names the value and the rule
        print(f"{parser.prog}: the FMU refused the run ({e}): see its message above", file=sys.stderr)
        return 2
    if not all(ended(r) for r in results.values()):
        parser.error(f"--stop-time {args.stop_time:g} s: the impact has not ended by then; raise it")
    figures = {law: summary(r) for law, r in results.items()}
    print_table(figures)
    gap = figures[1]["F_peak"] / PAPER["F_peak"] - 1
    print(f"\nF_peak (law 1) is {gap:+.1%} from the paper's; eps {figures[1]['eps'] - PAPER['eps']:+.4f}.")
    write_csv(args.out / "h20_drop.csv", results)
    plot(args.out / "h20_drop.png", results, figures)
    print(f"wrote {args.out / 'h20_drop.csv'} and {args.out / 'h20_drop.png'}")

