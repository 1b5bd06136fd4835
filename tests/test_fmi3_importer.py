"""The FMI 3.0 co-simulation FMU (fraccontact-fmi3.fmu) in importers that share
no code with fmpy, against fmpy's own run of the same FMU.

- ecos (ecospy 0.7.2, PyPI; its C++ core loads FMI 3.0 through fmi4c, built
  into libecosc.so): fixed communication steps, no event mode, no early
  return. Always run: scripts/setup installs it (requirements.txt, and
  Debian's libtbb12 that libecosc.so links).
- fmi-sim 0.7.0 (crates.io, Rust: the fmi crates' own bindings, fmusim's
  master algorithm): with event mode and early return as well. Run when
  FMI_SIM names it, or `fmi-sim` is on PATH or in .venv/bin
  (FRACCONTACT_FMI_SIM=1 scripts/setup builds it there); skipped otherwise.
  Not in CI: cold, Debian's cargo-web took 20 s and the build 3.6 min
  (--debug; release 11 min) on this 2-core machine under a load of 4, and
  0.8 GB of disk while building.

The FMU: FRACCONTACT_FMU3 (CMake sets it), else fraccontact-fmi3.fmu beside
the FMI 2.0 FMU, as in test_fmi3.py.

Tolerances. Each importer calls the same binary with the same start values at
the same communication points; only how a master forms its times differs.
fmpy and fmi-sim step from t_n to t_{n+1} = (n+1) H, so H_n = t_{n+1} - t_n
differs from H by a few ulp: they run bit for bit alike (measured: 0
difference). ecos steps by exactly H and accumulates t += H, so its t_n drift
from n H by at most n ulp(t) (measured 6.9e-18 s after 300 steps). The FMU
takes the master's t_n and splits each step into ceil(H_n / dt_max) equal
internal steps, forgiving a few ulp, so both see 100 internal steps per step
whose lengths differ by ulp: the outputs differ by rounding only (measured
3.3e-14 relative on F, 5e-15 on F_peak, 1e-15 on eps). rel 1e-12 is the bound
the FMI 2.0 tests use for "the same internal steps, only rounding differs"
(test_cosim.py); times are compared to abs 1e-15 s (1e-10 of a step, well
above the drift); the Boolean contact must agree exactly, row for row.
"""

import csv
import os
import pathlib
import re
import shutil
import subprocess
import zipfile

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu

from conftest import FMU

ROOT = pathlib.Path(__file__).resolve().parent.parent
FMU3 = pathlib.Path(os.environ.get("FRACCONTACT_FMU3", FMU.parent / "fraccontact-fmi3.fmu"))

STOP, H = 3e-3, 1e-5  # the default experiment
REALS = ("F", "F_peak", "E_diss", "eps")
NAMES = REALS + ("contact",)
V0 = 0.626418  # the striker's default speed, m/s (modelDescription.xml)
GAP0 = 1e-4  # m: free flight (g = 0) to onset at GAP0 / V0 = 1.5964e-4 s, inside the 16th step
REL, T_ABS = 1e-12, 1e-15


@pytest.fixture(scope="module")
def fmu3():
    if not FMU3.exists():
        pytest.fail(f"{FMU3} does not exist: build first (scripts/build)")
    md = read_model_description(str(FMU3))
    assert md.fmiVersion == "3.0" and md.coSimulation is not None, "an FMI 3.0 co-simulation FMU"
    return FMU3


@pytest.fixture(scope="module")
def model3(fmu3):
    return read_model_description(str(fmu3))


def as_bool(x):
    return np.asarray(x, dtype=float) != 0.0


# ---------------------------------------------------------------- importers


def run_fmpy(fmu, start_values=None, **options):
    r = simulate_fmu(str(fmu), fmi_type="CoSimulation", stop_time=STOP, output_interval=H,
                     start_values=dict(start_values or {}), output=list(NAMES), **options)
    out = {"time": np.asarray(r["time"], dtype=float)}
    out.update({n: np.asarray(r[n], dtype=float) for n in REALS})
    out["contact"] = as_bool(r["contact"])
    return out


def run_ecos(fmu, start_values=None):
    """ecos's fixed-step master: init, then step(H) until STOP, sampling the
    outputs at t = 0 and after each step (the rows fmpy records)."""
    from ecospy.EcosSimulation import EcosSimulation
    from ecospy.EcosSimulationStructure import EcosSimulationStructure

    rows = []
    with EcosSimulationStructure() as structure:
        structure.add_model("c", str(fmu))
        if start_values:
            structure.add_parameter_set("start", {f"c::{k}": float(v) for k, v in start_values.items()})
        with EcosSimulation(structure=structure, step_size=H) as sim:
            assert sim.init(parameter_set="start" if start_values else None), "ecos could not initialize the FMU"

            def sample():
                rows.append([sim.get_time()] + [sim.get_real(f"c::{n}") for n in REALS]
                            + [float(sim.get_bool("c::contact"))])

            sample()
            while sim.get_time() < STOP - H / 2:
                sim.step()
                sample()
            sim.terminate()
    a = np.array(rows, dtype=float)
    out = {"time": a[:, 0]}
    out.update({n: a[:, 1 + i] for i, n in enumerate(REALS)})
    out["contact"] = as_bool(a[:, -1])
    return out


def fmi_sim():
    venv = ROOT / ".venv" / "bin" / "fmi-sim"
    exe = os.environ.get("FMI_SIM") or shutil.which("fmi-sim") or (str(venv) if venv.exists() else None)
    if not exe:
        pytest.skip("fmi-sim is not installed (FRACCONTACT_FMI_SIM=1 scripts/setup)")
    return exe


def without_variable_units(fmu, tmp_path):
    """A copy of the FMU for fmi-sim 0.7: its parser (fmi-schema 0.8) rejects
    the unit attribute that FMI 3.0 allows on a Float64 variable ("unknown
    field unit in element FmiFloat64"; it knows units only through
    declaredType). The copy drops those attributes, which no simulation reads;
    the binary and every other byte are the FMU's."""
    copy = tmp_path / fmu.name
    with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(copy, "w", zipfile.ZIP_DEFLATED) as dst:
        for item in src.infolist():
            data = src.read(item)
            if item.filename == "modelDescription.xml":
                data = re.sub(rb'(<Float64\b[^>]*?)\s+unit="[^"]*"', rb"\1", data)
            dst.writestr(item, data)
    return copy


def run_fmi_sim(fmu, tmp_path, start_values=None, events=False):
    out_csv = tmp_path / ("events.csv" if events else "fixed.csv")
    cmd = [fmi_sim(), "--model", str(without_variable_units(fmu, tmp_path)), "-o", str(out_csv), "co-simulation",
           "-f", repr(STOP), "--output-interval", repr(H)]
    for k, v in (start_values or {}).items():
        cmd += ["--init-values", f"{k}={v!r}"]
    if events:
        cmd += ["--event-mode-used", "--early-return-allowed"]
    run = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    with open(out_csv, newline="") as f:
        table = list(csv.DictReader(f))
    out = {"time": np.array([float(r["time"]) for r in table])}
    out.update({n: np.array([float(r[n]) for r in table]) for n in REALS})
    out["contact"] = np.array([r["contact"].strip().lower() in ("true", "1") for r in table])
    return out


# ---------------------------------------------------------------- comparisons


def contact_span(r):
    """The first and the last communication point with contact true."""
    on = np.flatnonzero(r["contact"])
    assert on.size, "no contact in the run"
    return r["time"][on[0]], r["time"][on[-1]]


def figures(r):
    first, last = contact_span(r)
    return {"F_peak": r["F_peak"][-1], "eps": r["eps"][-1], "E_diss": r["E_diss"][-1],
            "contact_first": first, "contact_last": last}


def assert_same_run(theirs, ours):
    assert theirs["time"].shape == ours["time"].shape, (theirs["time"].size, ours["time"].size)
    np.testing.assert_allclose(theirs["time"], ours["time"], rtol=0, atol=T_ABS)
    for n in REALS:
        np.testing.assert_allclose(theirs[n], ours[n], rtol=REL, atol=0, err_msg=n)
    np.testing.assert_array_equal(theirs["contact"], ours["contact"], err_msg="contact")
    a, b = figures(theirs), figures(ours)
    for key in ("F_peak", "eps", "E_diss"):
        assert a[key] == pytest.approx(b[key], rel=REL, abs=0), key
    for key in ("contact_first", "contact_last"):
        assert a[key] == pytest.approx(b[key], rel=0, abs=T_ABS), key
    return a, b


def off_grid(times):
    """The distinct communication points that are not multiples of H: the
    early returns."""
    t = np.unique(times)
    return t[np.abs(t / H - np.round(t / H)) > 1e-6]


# ---------------------------------------------------------------- tests


def test_ecos_runs_the_default_drop_test_as_fmpy_does(fmu3):
    ours = run_fmpy(fmu3)
    theirs = run_ecos(fmu3)
    a, b = assert_same_run(theirs, ours)
    assert a["F_peak"] > 0 and 0 < a["eps"] < 1  # a real impact, not two empty runs
    assert a["contact_last"] > a["contact_first"]


def test_ecos_sets_start_values_as_fmpy_does(fmu3):
    """gap0 is a fixed parameter: set before initialization by both."""
    start = {"gap0": GAP0}
    ours = run_fmpy(fmu3, start)
    theirs = run_ecos(fmu3, start)
    a, _ = assert_same_run(theirs, ours)
    # no contact before the step holding gap0 / v
    assert a["contact_first"] > GAP0 / V0


def test_fmi_sim_runs_the_default_drop_test_as_fmpy_does(fmu3, tmp_path):
    theirs = run_fmi_sim(fmu3, tmp_path)
    ours = run_fmpy(fmu3)
    assert_same_run(theirs, ours)


def test_fmi_sim_returns_early_at_onset_and_separation_as_fmpy_does(fmu3, model3, tmp_path):
    """Event mode and early return: the communication points include the
    onset (free flight, g = 0: gap0 / v to rounding) and the separation (as
    fmpy's run with the same options finds it), and the runs agree."""
    cs = model3.coSimulation
    if not (cs.hasEventMode and cs.mightReturnEarlyFromDoStep):
        pytest.skip("the FMU declares no event mode / early return")
    start = {"gap0": GAP0}
    theirs = run_fmi_sim(fmu3, tmp_path, start, events=True)
    ours = run_fmpy(fmu3, start, use_event_mode=True, early_return_allowed=True)
    early_theirs, early_ours = off_grid(theirs["time"]), off_grid(ours["time"])
    assert early_ours.size == 2, early_ours  # one impact: onset, separation
    onset, separation = early_ours
    assert onset == pytest.approx(GAP0 / V0, rel=REL, abs=0)
    assert GAP0 / V0 < separation < STOP
    np.testing.assert_allclose(early_theirs, early_ours, rtol=REL, atol=0)
    # Both record an early return's point twice, before and after the event
    # update, and agree row for row (measured: bit for bit).
    assert theirs["time"].shape == ours["time"].shape == (301 + 2 * 2,)
    np.testing.assert_allclose(theirs["time"], ours["time"], rtol=REL, atol=T_ABS)
    for n in REALS:
        np.testing.assert_allclose(theirs[n], ours[n], rtol=REL, atol=0, err_msg=n)
    np.testing.assert_array_equal(theirs["contact"], ours["contact"])
    # The discrete outputs change in event mode, not before: contact false
    # then true at the onset; true then false, and eps set, at the separation.
    for t, contact, eps_set in ((onset, [False, True], [False, False]), (separation, [True, False], [False, True])):
        rows = np.flatnonzero(theirs["time"] == t)
        assert theirs["contact"][rows].tolist() == contact, t
        assert (theirs["eps"][rows] > 0).tolist() == eps_set, t
