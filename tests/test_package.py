"""The fraccontact package in-process: impact, impacts, simulate, parameters,
fmu_path, against independent truths (scipy's solve of the same ODE,
closed forms, identities) and against each other (a batch is the same runs
one by one); the files `pip install .` puts in the package, where the
package finds them, and docs/python.md's account of them, its commands and
the scenes' API."""

import math
import pathlib
import re
import tomllib

import numpy as np
import pytest
from fmpy import read_model_description
from fraccontact.scipy_contact import solve_drop

import fraccontact
from closed_forms import EPS, HERTZ_TC, SCHEME_RTOL, hertz_k
from doc_pages import section, text
from fmu_driver import C, K, M, V0
from fraccontact import cli, crash, shipped, ssp
from fraccontact.scenes import bumper, headform, masters

ROOT = pathlib.Path(__file__).resolve().parent.parent
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())


def test_impact_is_the_drop_test_of_scipy():
    """The Hertz law at the default step against scipy's DOP853 at 1e-13: the
    scheme's error (SCHEME_RTOL, measured 3x below it) and nothing else."""
    r = fraccontact.impact(law="hertz", v=V0)  # the exact sqrt(2 g h); the default is 0.626418
    ref = solve_drop(K, C, M, V0, rtol=1e-13)
    for key, ours in (("F_peak", r.F_peak), ("eps", r.eps), ("t_contact", r.t_contact), ("x2", r.x2_end),
                      ("E_diss", r.E_diss)):
        assert ours == pytest.approx(ref[key], rel=SCHEME_RTOL[key], abs=0), key
    assert r.per_impact == [fraccontact.Impact(r.t_onset, r.v_onset, r.F_peak, r.eps, r.t_contact, r.x2_end,
                                               r.E_diss)]
    assert r.stopped == "impacts" and r.impacts == 1 and r.t_onset == 0 and r.v_onset == V0
    assert r.end.t == r.t_contact and r.end.x2 == r.x2_end and r.end.x1 == 0
    assert r.end.v == pytest.approx(-r.eps * V0, rel=2 ** -52, abs=0)  # eps = -v / v_onset, one rounding
    assert fraccontact.impact().v_onset == 0.626418  # the FMU's start value


def test_height_is_the_free_fall_velocity():
    assert fraccontact.impact(height=0.05).v_onset == pytest.approx(math.sqrt(2 * 9.81 * 0.05), rel=1e-15, abs=0)


def test_a_batch_is_the_same_runs_one_by_one():
    """Broadcasting (3, 1) heights against 4 dashpots: twelve runs in one
    library call, bit for bit the runs of impact()."""
    heights = np.array([[0.01], [0.02], [0.05]])
    c = np.array([2e3, 4e3, 6e3, 8e3])
    a = fraccontact.impacts(height=heights, c=c, law="hertz")
    assert a["F_peak"].shape == (3, 4)
    for i in range(3):
        for j in range(4):
            r = fraccontact.impact(height=float(heights[i, 0]), c=float(c[j]), law="hertz")
            for key in ("F_peak", "eps", "t_contact", "x2_end", "E_diss", "t_onset", "v_onset"):
                assert a[key][i, j] == getattr(r, key), (key, i, j)
            assert a["impacts"][i, j] == 1 and a["stopped"][i, j] == "impacts"
            for key in ("t", "F_peak", "x2", "v"):
                assert a["end"][key][i, j] == getattr(r.end, key), (key, i, j)


def test_word_values_as_arrays():
    a = fraccontact.impacts(law=np.array(["g1", "hertz", "g1x"]))
    for i, law in enumerate(("g1", "hertz", "g1x")):
        assert a["F_peak"][i] == fraccontact.impact(law=law).F_peak


def test_momentum_and_energy_of_every_impact():
    """Three bounces under gravity: each impact's dent x2 grows by its
    impulse / c (the dashpot carries the force) and its dissipation is the
    kinetic energy it took plus gravity's work during the contact, m g times
    the dent's growth (x1 = 0 at onset and separation): exactly, as the
    fixed step keeps the energy (docs/model.md §11), to rounding, 4 ulp of
    the impact energy per internal step."""
    r = fraccontact.impact(g=9.81, impacts=3, law="hertz")
    assert len(r.per_impact) == 3 and r.stopped == "impacts"
    x2 = 0.0
    for i in r.per_impact:
        impulse = M * i.v_onset * (1 + i.eps) + M * 9.81 * i.t_contact
        assert i.x2_end - x2 == pytest.approx(impulse / C, rel=1e-11, abs=0)
        kinetic = 0.5 * M * i.v_onset ** 2 * (1 - i.eps ** 2)
        gravity = M * 9.81 * (i.x2_end - x2)
        assert i.E_diss - kinetic == pytest.approx(gravity, abs=4 * EPS * r.steps * 0.5 * M * V0 ** 2, rel=0)
        x2 = i.x2_end


def test_elastic_limit_is_hertz_with_k_from_the_materials():
    """c = 1e15, k = 0: the elastic Hertz impact with k of docs/model.md §2:
    x_max and the contact time of the closed forms to the scheme's error."""
    k = hertz_k(6.35e-3, 210e9, 0.3, 1.2e9, 0.4)
    r = fraccontact.impact(k=0, E_s=1.2e9, c=1e15, law="hertz", v=V0)
    x_max = (5 * M * V0 ** 2 / (4 * k)) ** 0.4
    assert r.F_peak == pytest.approx(k * x_max ** 1.5, rel=SCHEME_RTOL["F_peak"], abs=0)
    assert r.t_contact == pytest.approx(HERTZ_TC * x_max / V0, rel=SCHEME_RTOL["t_contact"], abs=0)


def test_simulate_gives_the_run_and_rows_on_its_grid():
    s = fraccontact.simulate(output_interval=1e-5, law="hertz")
    run = s["run"]
    assert s["t"][0] == 0 and np.all(np.diff(s["t"]) > 0)
    on_grid = s["t"][1:-1][np.abs(s["t"][1:-1] / 1e-5 - np.round(s["t"][1:-1] / 1e-5)) < 1e-9]
    assert len(on_grid) == math.floor(run.end.t / 1e-5)
    assert s["F"].max() <= run.F_peak and s["F"].max() > 0.999 * run.F_peak
    assert s["x"] == pytest.approx(s["x1"] + s["x2"], rel=1e-15, abs=1e-20)
    assert run == fraccontact.impact(law="hertz")  # the rows change nothing
    assert len(fraccontact.simulate(output_interval=0, law="hertz")["t"]) >= run.t_contact / 1e-7


@pytest.mark.parametrize("params, says", [
    (dict(c=-1.0), "c = -1 is invalid"), (dict(dt_max=-1e-7), "dt_max = -1e-07 is invalid"),
    (dict(law="rk4"), "law = 'rk4' is invalid"), (dict(impacts=0), "impacts = 0 is invalid"),
    (dict(height=-1.0), "height = -1.0 is invalid"), (dict(v=1e300), "v = 1e+300 is invalid")])
def test_bad_values_raise_the_librarys_message(params, says):
    with pytest.raises(ValueError, match=says.replace("+", r"\+")):
        fraccontact.impact(**params)


def test_bad_values_in_a_batch_name_the_case():
    with pytest.raises(ValueError, match=r"case \(1, 2\): c = -1 is invalid"):
        fraccontact.impacts(c=np.array([[1e3, 2e3, 3e3], [4e3, 5e3, -1.0]]))


def test_unknown_names_are_refused():
    with pytest.raises(TypeError, match="unknown parameter v0"):
        fraccontact.impact(v0=1.0)


# What only a master feeds the FMU (the library's run has none; v2 and m2, the
# second body, it takes): the package's list, which refuses them with the reason.
COSIMULATION_ONLY = {"coupling", "a", "a2"}


def test_parameters_are_the_fmus_variables(model_description):
    """Every FMU parameter and input has the same name, unit and default in
    the library's table (modelDescription.xml is the FMU's own declaration),
    but for the co-simulation's own (COSIMULATION_ONLY)."""
    table = {p["name"]: p for p in fraccontact.parameters()}
    assert not COSIMULATION_ONLY & set(table) and set(fraccontact.model.CO_SIMULATION_ONLY) == COSIMULATION_ONLY
    for v in model_description.modelVariables:
        if v.causality in ("parameter", "input") and v.name not in COSIMULATION_ONLY:
            assert v.name in table, v.name
            assert float(v.start) == table[v.name]["default"], v.name
            assert (v.unit or "1") == table[v.name]["unit"], v.name


def test_fmu_path_is_an_fmu(fmu_path):
    assert fraccontact.fmu_path() == fmu_path
    assert read_model_description(str(fraccontact.fmu_path("striker"))).coSimulation.modelIdentifier == "striker"
    with pytest.raises(ValueError):
        fraccontact.fmu_path("other")


def test_warning_names_a_material_without_effect():
    assert "E_s = 1.2e+09 has no effect" in fraccontact.warning(E_s=1.2e9)
    assert fraccontact.warning() is None and fraccontact.warning(k=0, E_s=1.2e9) is None


# ------------------------------------------------ what the package ships, and docs/python.md

def test_the_package_ships_the_scene_its_reports_run():
    """pip install . builds with FRACCONTACT_PACKAGE: the SSPs (the drop
    test, the crash scenes) are made and installed into the package beside
    the FMUs, where ssp_path() and scenes.masters.ssp_path() look (scripts/test
    installs the package and runs the scenes)."""
    cmake = (ROOT / "CMakeLists.txt").read_text()
    package = re.search(r"if\(FRACCONTACT_PACKAGE\)\n(.*?)\n  return\(\)", cmake, re.S).group(1)
    assert "add_subdirectory(ssp)" in package and "include(ssp/scenes.cmake)" in package
    installed = re.search(r'install\(FILES (.*?) DESTINATION fraccontact\)', package, re.S).group(1)
    for name in ("${SSP_FILE}", "${FMU_FILE}", "body.fmu", "${SCENE_SSP_FILES}"):
        assert name in installed, name
    ssp_cmake = (ROOT / "ssp" / "CMakeLists.txt").read_text()
    assert 'set(SSP_FILE "${CMAKE_BINARY_DIR}/drop_test.ssp" PARENT_SCOPE)' in ssp_cmake
    scenes_cmake = (ROOT / "ssp" / "scenes.cmake").read_text()
    assert "foreach(scene headform bumper)" in scenes_cmake
    assert 'list(APPEND SCENE_SSP_FILES "${ssp_file}")' in scenes_cmake
    assert PYPROJECT["tool"]["scikit-build"]["wheel"]["packages"] == ["python/fraccontact"]


def test_the_scene_is_found_beside_the_installed_fmus(monkeypatch, tmp_path):
    """An installed package: no environment variables, the FMUs and the scene in the package's folder."""
    for name in ("fraccontact.fmu", "drop_test.ssp", "headform.ssp", "bumper.ssp"):
        (tmp_path / name).write_bytes(b"")
    monkeypatch.setattr(shipped, "_HERE", tmp_path)
    for variable in ("FRACCONTACT_FMU", "DROP_TEST_SSP"):
        monkeypatch.delenv(variable, raising=False)
    assert ssp.ssp_path() == tmp_path / "drop_test.ssp"
    for scene in ("headform", "bumper"):
        assert masters.ssp_path(scene) == tmp_path / f"{scene}.ssp"


def installed_files():
    """The names of the files `pip install .` puts in the package beside its
    library: CMakeLists.txt's install(FILES ...) of the package build, the
    scenes' SSPs from ssp/scenes.cmake's loop."""
    cmake = (ROOT / "CMakeLists.txt").read_text()
    listed = re.search(r"install\(FILES (.*?) DESTINATION fraccontact\)", cmake, re.S).group(1)
    names = set(re.findall(r"/([\w.]+\.(?:fmu|ssp))\"", listed))
    variables = {"${FMU_FILE}": re.search(r'set\(FMU_FILE "\$\{CMAKE_BINARY_DIR\}/([\w.]+)"\)', cmake).group(1),
                 "${FMU3_FILE}": re.search(r'set\(FMU3_FILE "\$\{CMAKE_BINARY_DIR\}/([\w.-]+)"\)', cmake).group(1),
                 "${SSP_FILE}": re.search(r'set\(SSP_FILE "\$\{CMAKE_BINARY_DIR\}/([\w.]+)"',
                                          (ROOT / "ssp" / "CMakeLists.txt").read_text()).group(1)}
    names |= {name for variable, name in variables.items() if variable in listed}
    assert "${SCENE_SSP_FILES}" in listed
    scenes = re.search(r"foreach\(scene ([\w ]+)\)", (ROOT / "ssp" / "scenes.cmake").read_text()).group(1).split()
    return names | {f"{scene}.ssp" for scene in scenes}


def test_the_package_page_names_every_file_the_package_ships():
    shipped = installed_files()
    assert {"fraccontact.fmu", "fraccontact-fmi3.fmu", "striker.fmu", "body.fmu", "drop_test.ssp", "headform.ssp",
            "bumper.ssp"} <= shipped
    prose = " ".join(section("In Python: the `fraccontact` package").split())
    assert [name for name in sorted(shipped) if f"`{name}`" not in prose] == []


def test_the_package_page_names_every_command():
    prose = " ".join(text("docs/python.md").split())
    assert [c for c in cli.COMMANDS if f"`fraccontact {c}" not in prose and f"`{c}`" not in prose] == []
    assert "`fraccontact scene NAME`" in prose


def test_the_scene_api_the_page_names_exists():
    """Every `module.name(` the scenes' section calls is a function of that
    module of the package."""
    body = section("The crash scenes and their figures in Python")
    called = set(re.findall(r"`(masters|headform|bumper|crash)\.(\w+)\(", body))
    assert {("masters", "run"), ("masters", "figures"), ("crash", "figures")} <= called
    modules = {"masters": masters, "headform": headform, "bumper": bumper, "crash": crash}
    assert [f"{m}.{f}" for m, f in sorted(called) if not callable(getattr(modules[m], f, None))] == []
