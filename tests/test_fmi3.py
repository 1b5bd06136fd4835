"""The FMI 3.0 FMU (build/fraccontact-fmi3.fmu) through fmpy: valid, the same
interface as the FMI 2.0 FMU, the same results bit for bit without early
return, and with early return communication points at contact onset and
separation. tests/test_fmi3.c calls its functions one by one."""

import os
import pathlib
import re
import subprocess
import xml.etree.ElementTree as ET
import zipfile

import fmpy
import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.validation import validate_fmu

import fraccontact

from conftest import FMU

FMU3 = pathlib.Path(os.environ.get("FRACCONTACT_FMU3", FMU.parent / "fraccontact-fmi3.fmu"))
ROOT = pathlib.Path(__file__).resolve().parent.parent
HEADERS = pathlib.Path(fmpy.__file__).parent / "c-code"
V0 = 0.626418  # the default impact velocity
GAP0 = 1e-4    # a gap, so that the onset falls inside a communication step


@pytest.fixture(scope="module")
def fmu3():
    if not FMU3.exists():
        pytest.fail(f"{FMU3} does not exist: build first (scripts/build)")
    return str(FMU3)


def test_validate_fmu_finds_no_problem(fmu3):
    assert validate_fmu(fmu3) == []


def fmi3_function_names():
    """Every function FMI 3.0 defines, from the standard's header."""
    text = (HEADERS / "fmi3FunctionTypes.h").read_text()
    return set(re.findall(r"\b(fmi3\w+)TYPE\b", text))


def test_binary_exports_every_fmi3_function_and_nothing_else(fmu3, tmp_path):
    # fmpy binds all of them when it loads an FMI 3.0 FMU: one missing and it fails.
    zipfile.ZipFile(fmu3).extractall(tmp_path)
    so = tmp_path / "binaries" / "x86_64-linux" / "fraccontact.so"
    out = subprocess.run(["nm", "-D", "--defined-only", str(so)], check=True, capture_output=True, text=True).stdout
    exported = {line.split()[-1] for line in out.splitlines() if line.split()[1] in "TtDdBbRr"}
    assert exported == fmi3_function_names()
    assert len(exported) == 75


def test_sources_build_as_the_build_description_says(fmu3, tmp_path):
    """A platform without a binary compiles what sources/buildDescription.xml
    lists, with the FMI 3.0 headers only: do that, and simulate the result."""
    folder = tmp_path / "fmu"
    zipfile.ZipFile(fmu3).extractall(folder)
    build = ET.parse(folder / "sources" / "buildDescription.xml").getroot()
    config = build.find("BuildConfiguration")
    assert config.get("modelIdentifier") == "fraccontact"
    files = [folder / "sources" / f.get("name") for f in config.iter("SourceFile")]
    libraries = [f"-l{lib.get('name')}" for lib in config.iter("Library")]
    assert {f.name for f in files} == {p.name for p in (folder / "sources").glob("*.c")}
    so = folder / "binaries" / "x86_64-linux" / "fraccontact.so"
    so.unlink()
    subprocess.run(["cc", "-std=c99", "-O2", "-shared", "-fPIC", "-fvisibility=hidden", f"-I{HEADERS}",
                    *map(str, files), "-o", str(so), *libraries], check=True)
    rebuilt = simulate_fmu(str(folder), output=["F_peak", "eps"])
    original = simulate_fmu(fmu3, output=["F_peak", "eps"])
    # The same sources and compiler: only flags may change the rounding (see
    # test_fmu_compliance.py for the 1e-13 bound over 13 160 steps).
    assert rebuilt["F_peak"][-1] == pytest.approx(original["F_peak"][-1], rel=1e-13, abs=0)
    assert rebuilt["eps"][-1] == pytest.approx(original["eps"][-1], rel=1e-13, abs=0)


# ------------------------------------------------- one interface, two versions

FMI3_TYPE = {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean"}


def fmi2_variables():
    root = ET.parse(ROOT / "modelDescription.xml").getroot()
    variables = {}
    for sv in root.find("ModelVariables"):
        typed = sv[0]
        variables[sv.get("name")] = dict(
            type=FMI3_TYPE[typed.tag], valueReference=sv.get("valueReference"), causality=sv.get("causality"),
            variability=sv.get("variability"), description=sv.get("description"),
            **{k: typed.get(k) for k in ("unit", "start", "min", "max")})
    return root, variables


def fmi3_variables():
    root = ET.parse(ROOT / "fmi3" / "modelDescription.xml").getroot()
    variables = {}
    for v in root.find("ModelVariables"):
        variables[v.get("name")] = dict(
            type=v.tag, **{k: v.get(k) for k in ("valueReference", "causality", "variability", "description",
                                                   "unit", "start", "min", "max")})
    return root, variables


def test_both_descriptions_declare_the_same_variables():
    """Names, value references, types, units, defaults, limits and
    descriptions: one interface. FMI 3.0 adds only its independent variable."""
    root2, v2 = fmi2_variables()
    root3, v3 = fmi3_variables()
    time = v3.pop("time")
    assert time["causality"] == "independent" and time["valueReference"] == "0"
    assert v3 == v2


def test_both_descriptions_agree_on_the_rest():
    root2, v2 = fmi2_variables()
    root3, _ = fmi3_variables()
    assert root3.get("instantiationToken") != root2.get("guid")  # a state of one is refused by the other
    for tag in ("UnitDefinitions", "LogCategories"):
        assert ET.tostring(root3.find(tag)) == ET.tostring(root2.find(tag)), tag
    assert root3.find("DefaultExperiment").attrib == root2.find("DefaultExperiment").attrib
    assert root3.find("CoSimulation").get("modelIdentifier") == root2.find("CoSimulation").get("modelIdentifier")
    # The model structure: FMI 2.0 names variables by index, 3.0 by reference.
    by_index = {str(i): v["valueReference"] for i, v in enumerate(v2.values(), start=1)}
    s2, s3 = root2.find("ModelStructure"), root3.find("ModelStructure")

    def fmi2_unknowns(tag):
        return {by_index[u.get("index")]: {by_index[d] for d in u.get("dependencies").split()}
                for u in s2.find(tag)}

    def fmi3_unknowns(tag):
        return {u.get("valueReference"): set(u.get("dependencies", "").split()) for u in s3.findall(tag)}

    assert fmi3_unknowns("Output") == fmi2_unknowns("Outputs")
    assert fmi3_unknowns("InitialUnknown") == fmi2_unknowns("InitialUnknowns")


# ------------------------------------------------------------------ results

CASES = {
    "h20 drop test": {},
    "closed-form Hertz": {"law": 2},
    "G1 with Richardson, a gap and gravity": {"law": 3, "gap0": GAP0, "g": 9.81},
    "springpot, compressed memory": {"damper": 2, "damper_order": 0.5},
    "springpot, full history": {"damper": 2, "damper_order": 0.3, "memory": 1},
}


@pytest.mark.parametrize("case", CASES)
def test_without_early_return_the_results_are_the_fmi2_results_bit_for_bit(fmu3, fmu_path, case):
    """Both glues drive the same model through the same steps."""
    r2 = simulate_fmu(str(fmu_path), start_values=CASES[case])
    r3 = simulate_fmu(fmu3, start_values=CASES[case])
    assert r2.dtype.names == r3.dtype.names
    for name in r2.dtype.names:
        assert np.array_equal(r2[name], r3[name]), name


def off_grid_times(result, H=1e-5):
    """The communication points an early return added to the grid of H."""
    t = result["time"]
    return sorted(set(t[np.abs(t / H - np.round(t / H)) > 1e-6]))


@pytest.fixture(scope="module")
def library_impact():
    """The same impact run by the C library in one go (its own grid of steps)."""
    return fraccontact.impact(gap0=GAP0)


@pytest.fixture(scope="module")
def event_mode_run(fmu3):
    return simulate_fmu(fmu3, start_values={"gap0": GAP0}, early_return_allowed=True, use_event_mode=True)


def test_early_return_puts_onset_and_separation_on_communication_points(event_mode_run, library_impact):
    onset, separation = off_grid_times(event_mode_run)
    # Free flight without gravity: the onset is gap0 / v, reached as the
    # communication point 1.5e-4 plus the rest of the gap over v: a few
    # roundings, 4 ulp (measured: 2).
    assert onset == pytest.approx(GAP0 / V0, rel=4 * 1.1e-16, abs=0)
    # The separation: the library steps from the onset in steps of dt_max,
    # the FMU in equal steps of at most dt_max over each communication step;
    # each locates it within the scheme's error in t_contact, 2.3e-9 relative
    # at dt_max = 1e-7 (docs/reliability.md), so they agree to twice that.
    # (Measured: 1.9e-9.)
    expected = library_impact.t_onset + library_impact.t_contact
    assert separation == pytest.approx(expected, rel=0, abs=2 * 2.3e-9 * library_impact.t_contact)


def test_event_mode_shows_the_discrete_outputs_before_and_after_each_event(event_mode_run):
    """fmpy records the step's end (left limit) and, after event mode, the
    updated discrete outputs at the same time."""
    r = event_mode_run
    onset, separation = off_grid_times(r)
    at_onset, at_separation = r[r["time"] == onset], r[r["time"] == separation]
    assert list(at_onset["contact"]) == [False, True]
    assert list(at_separation["contact"]) == [True, False]
    assert at_separation["eps"][0] == 0.0
    assert at_separation["eps"][1] == r["eps"][-1] and 0.5 < r["eps"][-1] < 0.7  # the impact's, at once
    # Everything continuous is the same in both rows: only event mode ran between them.
    for name in ("F", "x", "x1", "x2", "v_striker", "E_diss", "F_peak"):
        assert at_onset[name][0] == at_onset[name][1] and at_separation[name][0] == at_separation[name][1], name


def test_early_return_without_event_mode_updates_the_discrete_outputs_at_once(fmu3):
    r = simulate_fmu(fmu3, start_values={"gap0": GAP0}, early_return_allowed=True, use_event_mode=False)
    onset, separation = off_grid_times(r)
    assert list(r[r["time"] == onset]["contact"]) == [True]
    assert list(r[r["time"] == separation]["contact"]) == [False]


def test_early_return_gives_the_figures_of_a_run_without(fmu3, event_mode_run):
    """Returning at the onset ends a communication step there, and the next
    one starts there: the internal steps after it are the same as when the
    model crosses the onset inside one step (equal steps over the rest of
    the step), so only the rounding of the times differs. Measured: F_peak,
    eps, E_diss and x2 equal to the last bit."""
    plain = simulate_fmu(fmu3, start_values={"gap0": GAP0})
    for name in ("F_peak", "eps", "E_diss", "x2", "v_striker"):
        assert event_mode_run[name][-1] == pytest.approx(plain[name][-1], rel=1e-14, abs=0), name
