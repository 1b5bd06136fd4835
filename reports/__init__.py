"""The reports under docs/, one module each with main(argv, prog), run from
the source tree: scripts/report NAME (python -m reports NAME). They are no
part of the package fraccontact, which they import; what they share with its
commands (the command line, numbers, figures) is fraccontact.output."""

import importlib
import pathlib
import pkgutil
import sys

from fraccontact.cli import quiet_on_closed_pipe

BAR = "{l_bar}{bar}| {n}/{total}"  # the reports' progress bars: what is being done, the bar, the count


def source_tree():
    """The repository a source-tree report works in (mutation, reliability:
    they build and test copies of it): the current folder, which
    scripts/report makes the repository's root."""
    root = pathlib.Path.cwd()
    if not (root / "CMakeLists.txt").exists() or not (root / "model").is_dir():
        raise SystemExit(f"{root} is not the fraccontact repository: run this report from its root (scripts/report does)")
    return root




def names():
    """The reports: the modules of this folder (not __main__)."""
    return sorted(m.name for m in pkgutil.iter_modules(__path__) if not m.name.startswith("_"))


def missing_module_hint(prog, error):
    """One line for a module the report needs that is not installed; None
    when the missing module is the source tree's own (a fault of the tree,
    not of the install)."""
    name = (error.name or "").partition(".")[0]
    if not name or name in ("fraccontact", __name__):
        return None
    return f"{prog} needs {name}, which is not installed: scripts/setup installs it (requirements.txt)"


def run(argv):
    """The report argv[0]'s main on the rest of argv; its exit status."""
    prog = "scripts/report"
    if not argv or argv[0] in ("-h", "--help"):
        print(f"usage: {prog} NAME [OPTIONS...]\n\nRegenerates a report under docs/ (NAME --help for its own).\n"
              f"NAME: {' | '.join(names())}", file=sys.stdout if argv else sys.stderr)
        return 0 if argv else 2
    if argv[0] not in names():
        print(f"{prog}: no report '{argv[0]}'; NAME is one of {', '.join(names())}", file=sys.stderr)
        return 2
    prog = f"{prog} {argv[0]}"
    try:
        return importlib.import_module(f"{__name__}.{argv[0]}").main(argv[1:], prog=prog) or 0
    except ModuleNotFoundError as e:
        hint = missing_module_hint(prog, e)
        if hint is None:
            raise
        print(hint, file=sys.stderr)
        return 2


def main(argv=None):
    """python -m reports NAME [OPTIONS...] (scripts/report's command)."""
    return quiet_on_closed_pipe(run, sys.argv[1:] if argv is None else argv)
