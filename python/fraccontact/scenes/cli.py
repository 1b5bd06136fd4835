"""fraccontact scene NAME: a crash scene (docs/scenes.md) run as its SSP in
a master, or its monolithic reference; prints its crash figures as JSON.

  fraccontact scene headform --master fmpy --H 1e-5 --headform child --gap0 0.05
  fraccontact scene bumper --master libcosim --v 1.1111
  fraccontact scene headform --ssp headform_exported.ssp    (its contacts exported FMUs, docs/export.md)
"""

import argparse
import json
import math
import pathlib
import sys
import zipfile

from ..options import OneLineParser, finite, positive
from .masters import HEADFORMS, MASTERS, figures, grid, run, ssp_path
from .systems import SCENES, STEP, T_END

# A run's communication steps at most (fmpy's SSP master takes about 60 us a step per FMU).
MAX_STEPS = 2_000_000
# The CFC 1000 filter wants samples at 10 kHz at least: the head's deceleration is sampled every H.
H_MAX = 1e-4
# The deceleration is the velocity's change over each step, and the CFC filter takes 3 samples at least.
MIN_STEPS = 3
# What else a run cut short reports of the part it ran.
LOWER_BOUND = {"headform": ", HIC15 a lower bound (HIC15_lower_bound)", "bumper": ""}
HEADFORM_OPTIONS = ("headform", "gap0", "k_p", "c_p", "m_p")
BUMPER_OPTIONS = ("v", "k_box", "zeta_box", "M", "m_b")


def non_negative(text):
    """argparse type: a finite number >= 0."""
    value = finite(text)
    if not value >= 0:
        raise argparse.ArgumentTypeError(f"{text} is negative: it must be >= 0")
    return value


def parser(prog=None):
    p = OneLineParser(prog=prog, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("name", choices=SCENES, metavar="NAME", help="headform | bumper")
    p.add_argument("--master", choices=MASTERS, default="fmpy",
                   help="fmpy (default) | libcosim | container | container-gs (its sequential mode) | omsimulator "
                        "(where installed, docs/ssp.md) | reference")
    p.add_argument("--H", type=positive, help=f"communication step [s] (default {STEP['headform']:g}; at most {H_MAX:g})")
    p.add_argument("--t-end", type=positive, help="simulated time [s] (default: headform "
                   f"{T_END['headform']:g}, bumper {T_END['bumper']:g}; at least {MIN_STEPS} steps of H; before the "
                   "contact ends: no duration, no restitution, HIC15 a lower bound)")
    p.add_argument("--headform", choices=HEADFORMS, help="headform: adult (4.5 kg, 11.1 m/s; default) | child")
    p.add_argument("--gap0", type=non_negative, help="headform: clearance to the hard point [m] (default 0.065)")
    p.add_argument("--k-p", type=positive, help="headform: the panel's bending stiffness [N/m]")
    p.add_argument("--c-p", type=non_negative, help="headform: the panel's damping [N s/m]")
    p.add_argument("--m-p", type=positive, help="headform: the panel's effective mass [kg]")
    p.add_argument("--v", type=positive, help="bumper: impact speed [m/s] (default 1.1176, 49 CFR 581)")
    p.add_argument("--k-box", type=positive, help="bumper: the crash box's stiffness [N/m]")
    p.add_argument("--zeta-box", type=non_negative, help="bumper: the crash box's damping ratio")
    p.add_argument("--M", type=positive, help="bumper: the vehicle body's mass [kg]")
    p.add_argument("--m-b", type=positive, help="bumper: the beam's mass [kg]")
    p.add_argument("--ssp", type=pathlib.Path, metavar="FILE",
                   help="another SSP of the scene (default the build's or the package's), such as one of exported "
                        "contacts (fraccontact export --ssp, docs/export.md): the values it fixes must be the scene's")
    return p


def options_of(p, args):
    """The scene's options given; an option of the other scene is a usage error."""
    own, other = (HEADFORM_OPTIONS, BUMPER_OPTIONS) if args.name == "headform" else (BUMPER_OPTIONS, HEADFORM_OPTIONS)
    for name in other:
        if getattr(args, name) is not None:
            p.error(f"--{name.replace('_', '-')} is an option of the other scene, not of {args.name}")
    return {name: getattr(args, name) for name in own if getattr(args, name) is not None}


def check_ssp(p, scene, path):
    """The scene's SSP (path, or ssp_path(scene) where None) is there and a zip archive, or a usage error."""
    try:
        path = ssp_path(scene) if path is None else path
    except FileNotFoundError as e:
        p.error(str(e))
    if not path.is_file():
        p.error(f"--ssp {path}: no such file")
    if not zipfile.is_zipfile(path):
        p.error(f"{path} is not an SSP (a zip archive): rebuild it (scripts/build)")


def main(argv=None, prog=None):
    p = parser(prog)
    args = p.parse_args(argv)
    H = STEP[args.name] if args.H is None else args.H
    t_end = T_END[args.name] if args.t_end is None else args.t_end
    if H > H_MAX:
        p.error(f"--H {H:g} is invalid: at most {H_MAX:g} s (the CFC 1000 filter needs 10 kHz samples)")
    if H > t_end:
        p.error(f"--H {H:g} is invalid: longer than --t-end {t_end:g} s")
    if t_end / H > MAX_STEPS:
        p.error(f"--t-end {t_end:g} in steps of --H {H:g} is {t_end / H:.3g} steps: at most {MAX_STEPS:.0e}")
    if len(grid(H, t_end)) <= MIN_STEPS:
        p.error(f"--t-end {t_end:g} is invalid: at least {MIN_STEPS} steps of --H {H:g} s "
                "(the deceleration's CFC filter takes 3 samples)")
    options = options_of(p, args)
    if args.master != "reference":
        check_ssp(p, args.name, args.ssp)
    elif args.ssp is not None:
        p.error("--ssp goes with a master, not with --master reference")
    try:
        trace = run(args.name, args.master, H, t_end, options, ssp=args.ssp)
        result = figures(trace, args.name, options)
    except (ValueError, RuntimeError, OSError) as e:
        p.error(str(e).splitlines()[0])
    except KeyboardInterrupt:
        print(f"{p.prog}: interrupted", file=sys.stderr)
        return 130
    for contact in result["not_ended"]:
        print(f"{p.prog}: warning: the {contact} contact had not ended by --t-end {t_end:g} s: duration and "
              f"restitution are null{LOWER_BOUND[args.name]}", file=sys.stderr)
    result = {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in result.items()}
    print(json.dumps(dict(scene=args.name, master=args.master, H=H, t_end=t_end, options=options, **result)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
