"""The two-FMU co-simulation (fraccontact/cosim.py) against the monolithic drop
test, and the same scene in libcosim, an independent FMI 2.0 importer."""

import os
import pathlib
import subprocess
import sys

import pytest

from fraccontact.cosim import cosimulate, cosimulate_libcosim, monolithic

ROOT = pathlib.Path(__file__).resolve().parent.parent
CONTACT = pathlib.Path(os.environ.get("FRACCONTACT_FMU", ROOT / "build" / "fraccontact.fmu"))
STRIKER = pathlib.Path(os.environ.get("STRIKER_FMU", ROOT / "build" / "striker.fmu"))


@pytest.fixture(scope="module")
def reference():
    return monolithic(CONTACT)


@pytest.mark.parametrize("H", [1e-5, 1e-4, 1e-3])
def test_mass_aware_gauss_seidel_is_the_monolithic_drop_test(reference, H):
    """The proxy striker is the striker and F_avg its exact impulse: with H
    a multiple of dt_max the runs agree to rounding, whatever the step."""
    r = cosimulate(CONTACT, STRIKER, H, "mass-aware", "gauss-seidel")
    # the same internal steps: only rounding differs (measured 1e-14, docs/coupling.md)
    assert r["F_peak"] == pytest.approx(reference["F_peak"], rel=1e-12, abs=0)
    assert r["eps"] == pytest.approx(reference["eps"], rel=1e-12, abs=0)
    assert r["energy_error"] == pytest.approx(reference["energy_error"], rel=0, abs=1e-12)


def test_zero_order_hold_converges_and_then_fails(reference):
    """Gauss-Seidel with held values: close at small steps (its error falls
    ~ H^2: 6e-8 at 1e-6 s), off by far at the contact's time scale."""
    small = cosimulate(CONTACT, STRIKER, 1e-6, "zoh", "gauss-seidel")
    large = cosimulate(CONTACT, STRIKER, 1e-3, "zoh", "gauss-seidel")
    assert small["F_peak"] == pytest.approx(reference["F_peak"], rel=2e-7, abs=0)  # 3x the measured 6e-8
    assert abs(large["F_peak"] / reference["F_peak"] - 1) > 0.1
    assert large["energy_error"] > 0.01  # the exchange creates energy


def test_jacobi_lags_by_one_step(reference):
    """Jacobi's error is first order: ten times the step, ten times the error."""
    e1 = cosimulate(CONTACT, STRIKER, 1e-6, "mass-aware", "jacobi")["F_peak"] / reference["F_peak"] - 1
    e10 = cosimulate(CONTACT, STRIKER, 1e-5, "mass-aware", "jacobi")["F_peak"] / reference["F_peak"] - 1
    assert 8 < e10 / e1 < 12


@pytest.mark.parametrize("coupling", ["zoh", "mass-aware", "predictive"])
def test_libcosim_runs_the_scene_as_our_jacobi_master_does(coupling):
    """libcosim (OSP, via libcosimpy) steps both FMUs from the last values:
    its results are our driver's Jacobi results."""
    ours = cosimulate(CONTACT, STRIKER, 2e-5, coupling, "jacobi")
    theirs = cosimulate_libcosim(CONTACT, STRIKER, 2e-5, coupling)
    for key in ("F_peak", "eps", "energy_error"):
        assert theirs[key] == pytest.approx(ours[key], rel=1e-12, abs=1e-15), key


# A child process with its own TMPDIR: fmpy's extract() makes its folders with
# tempfile.mkdtemp() ("tmp" + 8 characters in the temp dir), so counting them
# there sees only this driver's, not those of tests running alongside.
COUNT_EXTRACTIONS = """
import pathlib, tempfile
from fraccontact.cosim import cosimulate, monolithic
folders = lambda: len(list(pathlib.Path(tempfile.gettempdir()).glob("tmp*")))
for H in (1e-4, 2e-4, 5e-4):
    cosimulate({contact!r}, {striker!r}, H, "mass-aware", "gauss-seidel")
    monolithic({contact!r}, H=H)
    print(folders())
"""


def test_each_fmu_is_extracted_once_and_removed_at_exit(tmp_path):
    """One folder per FMU file while the process runs
    (not one per instance: hundreds per study), none left after it."""
    code = COUNT_EXTRACTIONS.format(contact=str(CONTACT), striker=str(STRIKER))
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=dict(os.environ, TMPDIR=str(tmp_path)), timeout=300)
    assert run.returncode == 0, run.stderr
    assert [int(n) for n in run.stdout.split()] == [2, 2, 2]  # the contact FMU and the striker FMU
    assert list(tmp_path.glob("tmp*")) == []
