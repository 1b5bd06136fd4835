"""The console command fraccontact (fraccontact/cli.py and the commands it
runs): every bad option or file is one line on stderr naming the option, its
value and what is wrong, exit status 2, before anything runs and with
nothing left on disk; a missing module names the extra that installs it;
a reader that closes the pipe early gets no traceback; an impact that has
not ended reports no eps; fit's hints follow what is actually wrong."""

import argparse
import json
import math
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

if os.environ.get("FRACCONTACT_SANITIZED") == "1":
    # The commands import matplotlib and fmpy's plotting, whose C++ extension
    # does not load under the preloaded AddressSanitizer; the commands' Python
    # is checked by the normal build's run, the C beneath them by this one's.
    pytest.skip("the commands' Python needs matplotlib, which does not load under ASan", allow_module_level=True)

import reports  # noqa: E402
from fraccontact import cli, cosim, fit, output  # noqa: E402
from fraccontact import run as h20_drop  # noqa: E402
from reports import calibration, stability  # noqa: E402
from test_package import PYPROJECT  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
CONTACT = pathlib.Path(os.environ.get("FRACCONTACT_FMU", ROOT / "build" / "fraccontact.fmu"))
STRIKER = pathlib.Path(os.environ.get("STRIKER_FMU", ROOT / "build" / "striker.fmu"))


def outcome(capsys, main, argv):
    """(exit status, stdout, stderr) of main(argv) in this process."""
    try:
        status = main([str(a) for a in argv])
    except SystemExit as e:
        status = e.code
    out, err = capsys.readouterr()
    return status, out, err


@pytest.fixture
def command(capsys):
    """command(*argv) -> (exit status, stdout, stderr) of fraccontact run in this process."""
    return lambda *argv: outcome(capsys, cli.main, argv)


@pytest.fixture
def report(capsys):
    """report(*argv) -> the same of scripts/report (python -m reports) in this process."""
    return lambda *argv: outcome(capsys, reports.main, argv)


def one_line(err, *says):
    """stderr is one line, no traceback, saying each of says."""
    assert err.count("\n") == 1 and "Traceback" not in err, err
    for s in says:
        assert s in err, (s, err)


def no_run(*args, **kwargs):
    raise AssertionError("the run started before the options were checked")


# fraccontact run checks every option before the run.

RUN_REFUSED = [
    (["--output-interval", "0"], ["--output-interval", "0 is not positive"]),
    (["--output-interval", "-1"], ["--output-interval", "-1 is not positive"]),
    (["--stop-time", "nan"], ["--stop-time", "nan is not a finite number"]),
    (["--stop-time", "inf"], ["--stop-time", "inf is not a finite number"]),
    (["--stop-time", "-1"], ["--stop-time", "-1 is not positive"]),
    (["--output-interval", "1e-12"], ["--output-interval 1e-12", "3e+09 rows", "at most 1e+06"]),
    (["--stop-time", "1", "--output-interval", "1e-7"], ["--stop-time 1 s", "1e+07 rows", "at most 1e+06"]),
    (["--output-interval", "0.01"], ["--output-interval 0.01 s is longer than --stop-time 0.003 s"]),
]


@pytest.mark.parametrize("options, says", RUN_REFUSED, ids=[" ".join(o) for o, _ in RUN_REFUSED])
def test_run_refuses_a_bad_option_before_the_run(command, monkeypatch, tmp_path, options, says):
    monkeypatch.setattr(h20_drop, "simulate", no_run)
    status, out, err = command("run", "--fmu", CONTACT, "--out", tmp_path / "new", *options)
    assert status == 2 and out == ""
    one_line(err, *says)
    assert "raise --stop-time" not in err and not (tmp_path / "new").exists()


@pytest.mark.parametrize("stop_time, refused", [(1.0, False), (1.0 + 2e-6, True)])
def test_run_bounds_the_rows_where_its_help_says(command, stop_time, refused):
    """The bound the help states is the one enforced, at its edge: a million
    rows of fmpy's tuples, some 400 bytes each, fit in memory."""
    status, out, err = command("run", "--help")
    assert status == 0 and "at most 1e+06 rows: stop time / interval" in " ".join(out.split())
    parser = output.parser("fraccontact run", "")
    args = argparse.Namespace(fmu=CONTACT, stop_time=stop_time, output_interval=1e-6)
    if refused:
        with pytest.raises(SystemExit):
            h20_drop.check(parser, args)
    else:
        h20_drop.check(parser, args)


def test_run_says_the_fmus_refusal_in_one_line(command, monkeypatch, tmp_path):
    """A step the FMU refuses (no option of run's makes it refuse one since
    free flight costs one internal step: fmpy's doStep is made to fail as an
    FMU's refusal does) ends in one line and no traceback."""
    from fmpy.fmi1 import FMICallException
    from fmpy.fmi2 import FMU2Slave

    def refused(self, *args, **kwargs):
        raise FMICallException("fmi2DoStep", 3)
    monkeypatch.setattr(FMU2Slave, "doStep", refused)
    status, out, err = command("run", "--fmu", CONTACT, "--out", tmp_path)
    assert status == 2
    one_line(err, "the FMU refused the run")


def test_run_says_an_impact_that_has_not_ended_is_the_stop_times(command, tmp_path):
    status, out, err = command("run", "--fmu", CONTACT, "--out", tmp_path, "--stop-time", "1e-5")
    assert status == 2
    one_line(err, "--stop-time 1e-05 s: the impact has not ended")
    assert not any(tmp_path.iterdir())


# The wrong file as an FMU, and values the FMUs refuse.

def test_run_refuses_the_striker_fmu(command, monkeypatch, tmp_path):
    monkeypatch.setattr(h20_drop, "simulate", no_run)
    status, out, err = command("run", "--fmu", STRIKER, "--out", tmp_path / "new")
    assert status == 2
    one_line(err, f"--fmu {STRIKER}", "the FMU striker lacks the variables law", "expected the contact FMU")


def not_an_fmu(tmp_path):
    path = tmp_path / "curve.csv"
    path.write_text("t_s,F_N\n0,0\n")
    return path


COSIM_REFUSED = [
    (lambda tmp: ["--contact", "/nonexistent.fmu"], ["--contact /nonexistent.fmu: no such file"]),
    (lambda tmp: ["--contact", STRIKER], [f"--contact {STRIKER}: the FMU striker lacks the variables law"]),
    (lambda tmp: ["--striker", CONTACT], [f"--striker {CONTACT}: the FMU fraccontact lacks the variables v0"]),
    (lambda tmp: ["--contact", not_an_fmu(tmp)], ["--contact", "curve.csv: not an FMU"]),
    (lambda tmp: ["--contact", tmp], ["--contact", ": not a file"]),
    (lambda tmp: ["--step", "inf"], ["--step", "inf is not a finite number"]),
    (lambda tmp: ["--step", "0.01"], ["--step 0.01 s is longer than --t-end 0.003 s"]),
    (lambda tmp: ["--gravity", "nan"], ["--gravity", "nan is not a finite number"]),
    (lambda tmp: ["--k-s", "inf"], ["--k-s", "inf is not a finite number"]),
    (lambda tmp: ["--t-end", "100", "--step", "1e-3"], ["--t-end 100 s", "1e+07 steps; at most 1e+06"]),
]


@pytest.mark.parametrize("options, says", COSIM_REFUSED,
                         ids=["missing", "striker as contact", "contact as striker", "csv", "folder", "step inf",
                              "step beyond t_end", "gravity nan", "k_s inf", "too many steps"])
def test_cosim_refuses_a_bad_fmu_or_value_before_the_run(command, monkeypatch, tmp_path, options, says):
    monkeypatch.setattr(cosim, "cosimulate", no_run)
    monkeypatch.setattr(cosim, "cosimulate_libcosim", no_run)
    status, out, err = command("cosim", *options(tmp_path))
    assert status == 2 and out == ""
    one_line(err, *says)


def test_cosim_says_what_the_fmu_refused(command):
    """A value only the FMU can judge: its own message, on one line."""
    status, out, err = command("cosim", "--gravity", "1e300", "--contact-knows-gravity")
    assert status == 2 and out == ""
    one_line(err, "the contact FMU refused its start values: g = 1e+300 is invalid")


def test_cosim_spares_libcosim_a_value_the_fmu_refuses():
    """libcosim ends the process on an FMU's error (C++ terminate): the
    values are tried first, and the refusal is the same one line. In a
    process of its own, for libcosim would end pytest's."""
    done = subprocess.run([sys.executable, "-m", "fraccontact", "cosim", "--gravity", "1e300",
                           "--contact-knows-gravity", "--order", "libcosim", "--coupling", "predictive"],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 2 and done.stdout == ""
    one_line(done.stderr, "the contact FMU refused its start values: g = 1e+300 is invalid")


def test_cosim_says_what_the_fmu_refused_during_the_run(command):
    """Gravity the contact does not know drives the striker to a speed the
    contact refuses, in the first step's exchange."""
    status, out, err = command("cosim", "--gravity", "1e300")
    assert status == 2 and out == ""
    one_line(err, "the contact FMU refused v = 1e+295", "exceeds double precision")


# No eps before an impact has ended.

@pytest.mark.parametrize("t_end, says", [("0", "0 is not positive"), ("-1", "-1 is not positive"),
                                         ("nan", "nan is not a finite number")])
def test_cosim_refuses_a_bad_end_time(command, t_end, says):
    status, out, err = command("cosim", "--t-end", t_end)
    assert status == 2 and out == ""
    one_line(err, "--t-end", says)


@pytest.mark.parametrize("options", [[], ["--order", "libcosim", "--coupling", "predictive"], ["--k-s", "1e5"]])
def test_cosim_reports_no_eps_before_the_impact_has_ended(command, options):
    """0.1 ms into the h20 impact (a contact of about 1.3 ms) the striker
    still moves into the specimen: no restitution to report. The reference
    is taken at the same time, so F_peak agrees with it (the same model,
    the same internal steps up to the coupling's error)."""
    status, out, err = command("cosim", "--t-end", "1e-4", *options)
    assert status == 0
    one_line(err, "the impact has not ended by --t-end 0.0001 s")
    r = json.loads(out)
    assert r["impact_ended"] is False and r["eps"] is None and r["eps_contact"] is None and r["eps_error"] is None
    assert r["v_end"] > 0  # still moving towards the specimen: the impact has indeed not ended
    if not options:  # the mass-aware coupling is exact at H = n dt_max (tests/test_cosim.py): 1e-12 is rounding
        assert r["F_peak"] == pytest.approx(r["monolithic"]["F_peak"], rel=1e-12, abs=0)
        assert r["monolithic"]["eps"] is None


def test_cosim_reports_eps_once_the_impact_has_ended(command):
    status, out, err = command("cosim")
    assert status == 0 and err == ""
    r = json.loads(out)
    assert r["impact_ended"] is True and 0 < r["eps"] < 1 and 0 < r["eps_contact"] < 1


# The report's folder before the computing; report without NAME.

class Stop(Exception):
    pass


@pytest.mark.parametrize("name", ["calibration", "stability"])
def test_a_report_makes_its_folder_before_computing(report, monkeypatch, tmp_path, name):
    out = tmp_path / "a" / "b"
    seen = []

    def first_computation(*args, **kwargs):
        seen.append(out.is_dir())
        raise Stop

    monkeypatch.setattr(*{"calibration": (calibration, "write_report"),
                          "stability": (stability.dashpot, "convergence")}[name], first_computation)
    with pytest.raises(Stop):
        report(name, "--out", out)
    assert seen == [True]


def test_stability_springpot_alone_needs_the_report_it_rewrites(report, monkeypatch, tmp_path):
    monkeypatch.setattr(stability.springpot, "convergence", no_run)
    status, out, err = report("stability", "--springpot", "--out", tmp_path)
    assert status == 2 and out == "" and list(tmp_path.iterdir()) == []
    one_line(err, f"--springpot rewrites the springpot part of {tmp_path / 'stability.md'}: it has none")


def test_stability_springpot_alone_keeps_the_rest_of_the_report(report, monkeypatch, tmp_path):
    """--springpot computes the springpot's part alone and replaces it,
    every line before its heading kept as it was."""
    page = tmp_path / "stability.md"
    page.write_text("# head\n\ndashpot\n\n# The springpot (damper = 2)\n\nold\n")
    monkeypatch.setattr(stability, "over", lambda *args: [])
    monkeypatch.setattr(stability.dashpot, "convergence", no_run)
    monkeypatch.setattr(stability.springpot_report, "section",
                        lambda *args: ["", "# The springpot (damper = 2)", "", "new"])
    monkeypatch.setattr(stability.springpot_report, "summary", lambda *args: ("springpot: none run", []))
    status, out, _ = report("stability", "--springpot", "--out", tmp_path)
    assert status == 0 and out == "springpot: none run\n"
    assert page.read_text() == "# head\n\ndashpot\n\n# The springpot (damper = 2)\n\nnew\n"


def test_a_report_refuses_a_folder_it_cannot_make(report, monkeypatch, tmp_path):
    monkeypatch.setattr(calibration, "write_report", no_run)
    (tmp_path / "file").write_text("")
    status, out, err = report("calibration", "--out", tmp_path / "file" / "sub")
    assert status == 2 and out == ""
    one_line(err, f"--out {tmp_path / 'file' / 'sub'}: cannot make the folder")


def test_report_without_a_name_is_a_usage_error(report):
    status, out, err = report()
    assert status == 2 and out == "" and err.startswith("usage: scripts/report NAME")


# A missing module names its extra.

EXTRAS = PYPROJECT["project"]["optional-dependencies"]
DISTRIBUTION = {"dask": "dask[distributed]", "distributed": "dask[distributed]"}  # module -> requirement

# (command and options, a module it imports); each module is blocked in turn
MISSING = [(["run"], "fmpy"), (["run"], "matplotlib"), (["fit", "--F-peak", "1004", "--eps", "0.59", "--height",
                                                         "0.02", "--m", "0.7437"], "scipy"),
           (["sweep"], "dask"), (["cosim"], "fmpy"), (["cosim"], "scipy"),
           (["cosim", "--order", "libcosim", "--coupling", "predictive"], "libcosimpy")]
# (report, a module it imports)
REPORT_MISSING = [("calibration", "matplotlib"), ("benchmarks", "differint")]
REQUIREMENTS = {line.partition("==")[0].lower() for line in (ROOT / "requirements.txt").read_text().splitlines()
                if line and not line.startswith("#")}


def block(monkeypatch, module):
    """As if the module were not installed: it and its submodules cannot be
    imported, and the package's and the reports' modules are imported afresh (each restored
    after the test)."""
    monkeypatch.setitem(sys.modules, module, None)
    for name in list(sys.modules):
        if name.startswith(module + "."):
            monkeypatch.setitem(sys.modules, name, None)
        elif name.startswith(("fraccontact.", "reports.")) and name not in ("fraccontact.cli", "fraccontact.model",
                                                                            "fraccontact._lib"):
            parent, _, child = name.rpartition(".")
            if parent in sys.modules and hasattr(sys.modules[parent], child):  # a removed parent is made afresh
                monkeypatch.setattr(sys.modules[parent], child, getattr(sys.modules[parent], child))
            monkeypatch.delitem(sys.modules, name)


@pytest.mark.parametrize("argv, module", MISSING, ids=[f"{a[0]}-{m}" for a, m in MISSING])
def test_a_missing_module_names_the_extra_that_installs_it(command, monkeypatch, argv, module):
    block(monkeypatch, module)
    status, out, err = command(*argv)
    extra = cli.EXTRAS[argv[0]]
    assert status == 2 and out == ""
    assert err == f"fraccontact {argv[0]} needs {module}, which is not installed: pip install 'fraccontact[{extra}]'\n"
    assert DISTRIBUTION.get(module, module) in EXTRAS[extra]  # and that extra installs it


@pytest.mark.parametrize("name, module", REPORT_MISSING, ids=[f"{n}-{m}" for n, m in REPORT_MISSING])
def test_a_report_names_what_installs_a_missing_module(report, monkeypatch, name, module):
    block(monkeypatch, module)
    status, out, err = report(name)
    assert status == 2 and out == ""
    assert err == f"scripts/report {name} needs {module}, which is not installed: scripts/setup installs it " \
                  f"(requirements.txt)\n"
    assert module in REQUIREMENTS  # and scripts/setup installs it


def test_every_command_has_an_extra():
    assert set(cli.EXTRAS) == set(cli.COMMANDS) and set(cli.EXTRAS.values()) <= set(EXTRAS)


# A closed pipe; the usage line.

@pytest.mark.parametrize("argv", [["fraccontact", "fit", "--F-peak", "1004", "--eps", "0.59", "--height", "0.02", "--m",
                                   "0.7437"], ["fraccontact", "--help"], ["reports", "--help"]],
                         ids=["fit", "help", "report help"])
def test_a_closed_pipe_ends_the_command_quietly(argv):
    """fraccontact ... | head -3, the reader gone before the command writes
    (it closes its end at once; the command needs a second to start)."""
    child = subprocess.Popen([sys.executable, "-m", *argv], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
    child.stdout.close()
    err = child.stderr.read()
    child.wait(timeout=300)
    assert "Traceback" not in err and "BrokenPipe" not in err and "Exception ignored" not in err, err
    assert child.returncode in (0, 1)  # argparse's help ignores a failed write itself; the commands stop with 1


def test_the_usage_line_requires_the_command_alone(command):
    status, out, err = command()
    assert status == 2
    assert "the following arguments are required: COMMAND\n" in err and "options" not in err.splitlines()[-1]


# fit --curve's hints follow what is wrong.

M, V0 = 0.7437, math.sqrt(2 * 9.81 * 0.020)


@pytest.fixture(scope="module")
def curve():
    """The model's curve at k = 3e8, c = 5000, every 2 us (about 700 rows, a
    contact of 1.4 ms), with 5 N of noise."""
    t, F = fit.force_series(3e8, 5000.0, M, V0, "hertz", 2e-6)
    return t, F + np.random.default_rng(7).normal(0.0, 5.0, len(F))


def rows(t, F):
    return "t_s,F_N\n" + "".join(f"{a:.17g},{b:.17g}\n" for a, b in zip(t, F))


# (name, the file from the clean curve, what the message must say, what it must not)
HINTS = [
    ("milliseconds", lambda t, F: rows(t * 1e3, F), ["column 1 (time [s])", "times in milliseconds"],
     ["microseconds", "kN"]),
    ("microseconds", lambda t, F: rows(t * 1e6, F), ["column 1 (time [s])", "times in microseconds"],
     ["milliseconds", "kN?"]),
    ("kilonewtons", lambda t, F: rows(t, F / 1e3), ["column 2 (force [N])", "forces in kN"], ["seconds"]),
    ("forces of 1e300", lambda t, F: rows(t, F * 1e300 / F.max()), ["no unit", "--m"],
     ["in milliseconds?", "in kN?"]),
    ("cut after 200 rows", lambda t, F: rows(t[:200], F[:200]), ["row 201, column 2", "the curve ends at",
                                                                 "whole contact"], ["kN?", "milliseconds?"]),
    ("starts at row 500", lambda t, F: rows(t[500:], F[500:]), ["row 2, column 2", "the curve starts at",
                                                                "whole contact"], ["kN?", "milliseconds?"]),
    ("a tenth of the mass", lambda t, F: rows(t, F * 10), ["no unit", "--m"], ["in milliseconds?", "in kN?"]),
]


@pytest.mark.parametrize("name, contents, says, not_says", HINTS, ids=[h[0] for h in HINTS])
def test_a_wrong_impulse_is_blamed_on_what_is_wrong(command, monkeypatch, tmp_path, curve, name, contents, says,
                                                    not_says):
    for model_call in ("run", "force_series", "figures", "series"):
        monkeypatch.setattr(fit.runs, model_call, no_run)
    path = tmp_path / "curve.csv"
    path.write_text(contents(*curve))
    status, out, err = command("fit", "--curve", path, "--height", "0.020", "--m", M)
    assert status == 2 and out == ""
    one_line(err, "the impulse", *says)
    for s in not_says:
        assert s not in err, (s, err)
