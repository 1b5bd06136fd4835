"""The method a configuration runs is named once, by the model
(contact_method, docs/model.md §16), and the solver's JSON, the library
(fc_method_name) and the package (Run.method) report that name. Every
configuration class maps to the method the rules of §16 give it, and the
steps taken show that method ran: the uniform grids step through the
flight to the specimen one dt_max at a time, the fixed steps fly in one exact
step and then takes fixed steps in contact, ESDIRK 5(4) and Radau IIA
take the few steps their controller allows."""

import json
import os
import pathlib
import subprocess
import warnings

import numpy as np
import pytest

from fraccontact import model

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOLVE = os.environ.get("FRACCONTACT_SOLVE", str(ROOT / "build" / "fraccontact-solve"))

# The striker starts GAP0 from the specimen at the default v = 0.626 m/s:
# its flight takes 1.6e-4 s, and the run stops at T_END, in contact. With
# dt_max = 0 (the default) fixed steps are DT long, error-controlled ones
# have no cap.
GAP0, T_END, DT = 1e-4, 3e-4, 1e-7
GRID_STEPS = round(T_END / DT)

SPRINGPOT = dict(damper="springpot")
CLASSES = [  # (parameters, the method docs/model.md §16 gives them)
    (dict(law=1), "gradient"),
    (dict(law=2), "gradient"),
    (dict(law=3), "gradient"),
    (dict(law=2, tolerance=1e-6), "esdirk54"),
    (dict(law=1, g1_nodes=100, tolerance=1e-6), "esdirk54"),
    (dict(law=1, tolerance=1e-6), "gradient"),  # g1_nodes = 0 counts steps: fixed steps
    (dict(scheme="central"), "central"),
    (dict(scheme="central", law=2, tolerance=1e-6), "central"),
    (dict(SPRINGPOT, memory="compressed"), "gradient"),
    (dict(SPRINGPOT, memory="compressed", law=2, tolerance=1e-6), "radau_iia"),
    (dict(SPRINGPOT, memory="compressed", law=1, g1_nodes=100, tolerance=1e-6), "radau_iia"),
    (dict(SPRINGPOT, memory="full"), "g1_history"),
    (dict(SPRINGPOT, memory="full", law=2, tolerance=1e-6), "g1_history"),
]


def options(params):
    """The solver's options for the package's parameters."""
    words = {"damper": {"springpot": 2}, "memory": {"full": 1, "compressed": 2}}
    out = []
    for name, value in params.items():
        out += [f"--{name.replace('_', '-')}", str(words.get(name, {}).get(value, value))]
    return out


def run(params):
    with warnings.catch_warnings():  # a tolerance the method ignores warns: not what is checked here
        warnings.simplefilter("ignore", model.ParameterWarning)
        return model.impact(gap0=GAP0, t_end=T_END, **params)


@pytest.mark.parametrize("params, method", CLASSES, ids=[m + str(p) for p, m in CLASSES])
def test_each_configuration_runs_its_named_method(params, method):
    r = run(params)
    assert r.method == method
    if method in ("central", "g1_history"):  # the grid throughout, flight included
        assert r.steps == GRID_STEPS
    elif method == "gradient":  # one step of flight, then fixed steps of dt_max in contact
        flight = GAP0 / 0.626418
        assert abs(r.steps - 1 - (T_END - flight) / DT) <= 1
    else:  # the controller's steps: far fewer than fixed steps would take
        assert r.steps < GRID_STEPS / 10


@pytest.mark.parametrize("params, method", CLASSES, ids=[m + str(p) for p, m in CLASSES])
def test_solver_and_package_name_the_same_method(params, method):
    done = subprocess.run([SOLVE, "--gap0", str(GAP0), "--t-end", str(T_END), *options(params),
                           "--json", "--quiet"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["method"] == method
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", model.ParameterWarning)
        batch = model.impacts(gap0=GAP0, t_end=T_END, **{**params, "v": np.array([0.5, 0.626418])})
    assert batch.method.tolist() == [method, method]
