"""Material identification (scripts/fit.py): known k and c are recovered
from data the solver made, with and without noise; unreachable pairs are
refused with a message; the paper's h20 row is fitted."""

import json
import math
import subprocess
import sys

import numpy as np
import pytest

import fit

M, V0 = 0.7437, math.sqrt(2 * 9.81 * 0.020)


@pytest.mark.parametrize("k, c", [(3.299e8, 6080.0), (1.0e8, 2000.0), (1.0e9, 30000.0)])
def test_peak_and_restitution_give_back_k_and_c(k, c):
    """Noise-free data: the solver's own F_max and eps at k, c. The model is
    accurate to ~1e-7 at the fit's step (t_c / 4000), so k and c come back to
    1e-5."""
    r = fit.simulate(k, c, M, V0)
    k_fit, c_fit = fit.fit_peak_and_restitution(r["F_peak"], r["eps"], M, V0)
    assert k_fit == pytest.approx(k, rel=1e-5) and c_fit == pytest.approx(c, rel=1e-5)


def test_noisy_peak_and_restitution_move_k_and_c_by_their_sensitivity():
    """0.5 % on F_max and 0.005 on eps: the fitted pair reproduces the noisy
    targets exactly, and stays within a few per cent of the truth."""
    r = fit.simulate(3.299e8, 6080.0, M, V0)
    F, eps = r["F_peak"] * 1.005, r["eps"] - 0.005
    k, c = fit.fit_peak_and_restitution(F, eps, M, V0)
    check = fit.simulate(k, c, M, V0)
    assert check["F_peak"] == pytest.approx(F, rel=1e-6) and check["eps"] == pytest.approx(eps, abs=1e-6)
    assert k == pytest.approx(3.299e8, rel=0.05) and c == pytest.approx(6080.0, rel=0.05)


@pytest.mark.parametrize("F, eps, says", [(1004.0, 1.2, "0 < eps < 1"), (1004.0, 0.0, "0 < eps < 1"),
                                          (-5.0, 0.5, "positive")])
def test_unreachable_pairs_are_refused(F, eps, says):
    with pytest.raises(fit.Unreachable, match=says):
        fit.fit_peak_and_restitution(F, eps, M, V0)


def test_specimen_modulus_inverts_the_hertz_constant():
    k = 4 / 3 * math.sqrt(6.35e-3) / ((1 - 0.09) / 210e9 + (1 - 0.16) / 2.64e9)
    assert fit.specimen_modulus(k, 6.35e-3, 210e9, 0.3, 0.4) == pytest.approx(2.64e9, rel=1e-12)
    with pytest.raises(fit.Unreachable, match="stiffer than the indenter"):
        fit.specimen_modulus(1e15, 6.35e-3, 210e9, 0.3, 0.4)


@pytest.fixture(scope="module")
def measured(tmp_path_factory):
    """A force curve made by the solver at k = 3e8, c = 5000, sampled every
    2 us; returned clean and with Gaussian noise of 5 N (0.5 % of the peak)."""
    path = tmp_path_factory.mktemp("curve") / "model.csv"
    fit.simulate(3e8, 5000.0, M, V0, "hertz", path, 2e-6)
    data = np.loadtxt(path, delimiter=",", skiprows=1, usecols=(0, 1))
    noisy = data[:, 1] + np.random.default_rng(7).normal(0.0, 5.0, len(data))
    return data[:, 0], data[:, 1], noisy


def test_curve_fit_without_noise_is_exact(measured):
    t, F, _ = measured
    r = fit.fit_curve(t, F, M, V0)
    assert r["k"] == pytest.approx(3e8, rel=1e-5) and r["c"] == pytest.approx(5000.0, rel=1e-5)


def test_curve_fit_with_noise_is_within_its_uncertainty(measured):
    """The standard errors come from the Jacobian and the residual; the truth
    must lie within 4 of them, and the residual must be the noise's 5 N."""
    t, _, noisy = measured
    r = fit.fit_curve(t, noisy, M, V0)
    assert abs(r["k"] - 3e8) < 4 * r["sigma_k"] and abs(r["c"] - 5000.0) < 4 * r["sigma_c"]
    assert r["rms_residual"] == pytest.approx(5.0, rel=0.1)
    assert r["sigma_k"] < 1e-3 * r["k"] and r["sigma_c"] < 1e-2 * r["c"]


def test_the_command_line_fits_the_paper_h20_row(tmp_path):
    done = subprocess.run([sys.executable, fit.__file__, "--fmax", "1004", "--eps", "0.59", "--height", "0.020",
                           "--mass", "0.7437", "--json"], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    r = json.loads(done.stdout)
    assert r["F_max_model"] == pytest.approx(1004.0, rel=1e-6) and r["eps_model"] == pytest.approx(0.59, abs=1e-6)
    # The paper's k = 3.299e8, c = 6080, E_s = 2.64 GPa came from its own scheme: ours are near, not equal.
    assert 0.8 < r["k"] / 3.299e8 < 1.1 and 0.8 < r["c"] / 6080 < 1.1 and 0.8 < r["E_s"] / 2.64e9 < 1.1


def test_the_command_line_says_why_it_cannot(tmp_path):
    done = subprocess.run([sys.executable, fit.__file__, "--fmax", "1004", "--eps", "1.5", "--height", "0.020",
                           "--mass", "0.7437"], capture_output=True, text=True, timeout=600)
    assert done.returncode == 2 and "not reachable" in done.stderr
