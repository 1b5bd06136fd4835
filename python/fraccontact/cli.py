"""The console command: fraccontact COMMAND [OPTIONS...], each command
documented by its own --help. Option names are the library's parameter
names (--m, --v, --c, --E-s, --t-end: '-' for '_')."""

import argparse
import importlib
import os
import sys

COMMANDS = {
    "run": "the paper's h20 drop test through the FMU: figures, docs/h20_drop.csv and .png",
    "fit": "k and a dashpot (c) or springpot (c_alpha, alpha), and E_s, from drop tests (F_peak and eps, a table "
           "of heights) or measured force curves",
    "sweep": "parameter sweeps and Monte Carlo campaigns on Dask, a library call per task",
    "cosim": "the drop test as two FMUs (striker + contact) coupled through fmpy or libcosim",
    "scene": "a crash scene (headform, bumper) as its SSP in fmpy, libcosim, a container FMU, or its reference",
    "export": "the contact of one scene as its own FMU: only what the scene sets or reads, the rest fixed",
}
MODULES = {"run": "fraccontact.run", "fit": "fraccontact.fit", "sweep": "fraccontact.sweep",
           "cosim": "fraccontact.cosim", "scene": "fraccontact.scenes.cli",
           "export": "fraccontact.export"}
# The extra of pyproject.toml's optional-dependencies that installs what each command imports.
EXTRAS = {"run": "run", "fit": "fit", "sweep": "sweep", "cosim": "cosim", "scene": "cosim", "export": "cosim"}


def parser():
    commands = "".join(f"  {name:<8} {what}\n" for name, what in COMMANDS.items())
    p = argparse.ArgumentParser(prog="fraccontact", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog=f"commands:\n{commands}")
    p.add_argument("command", choices=COMMANDS, metavar="COMMAND", help="one of " + ", ".join(COMMANDS))
    options = p.add_argument("options", nargs=argparse.REMAINDER, help="the command's options (COMMAND --help)")
    options.required = False  # argparse calls a REMAINDER positional required, yet it may be empty
    return p


def missing_module_hint(prog, command, error):
    """One line for a module the command needs that is not installed (a
    plain `pip install .` installs numpy alone); None when the missing
    module is the package's own (a fault of the package, not the install)."""
    name = (error.name or "").partition(".")[0]
    if not name or name == __package__:
        return None
    return f"{prog} needs {name}, which is not installed: pip install 'fraccontact[{EXTRAS[command]}]'"


def run(argv):
    args = parser().parse_args(argv)
    prog = f"fraccontact {args.command}"
    try:
        return importlib.import_module(MODULES[args.command]).main(args.options, prog=prog) or 0
    except ModuleNotFoundError as e:
        hint = missing_module_hint(prog, args.command, e)
        if hint is None:
            raise
        print(hint, file=sys.stderr)
        return 2


def main(argv=None):
    return quiet_on_closed_pipe(run, argv)


def quiet_on_closed_pipe(command, argv):
    """command(argv)'s exit status; 1, and no traceback, where the reader of
    its output has gone."""
    try:
        status = command(argv)
        sys.stdout.flush()  # here, where a closed pipe can still be caught, not at the interpreter's exit
        return status
    except BrokenPipeError:
        # The reader has gone (fraccontact fit ... | head -3): stop quietly. stdout goes to /dev/null so that
        # Python's own flush at exit does not meet the closed pipe again.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
