"""OMSimulator (OpenModelica's SSP master) and this project's three SSPs: the
SSDs carry the annotation it needs (its fixed-step master at the step the
other masters' annotation carries) and stay SSP 1.0; where it is installed
(docs/ssp.md; else those tests skip), it runs each scene as the other
masters and the references do, and `fraccontact scene --master omsimulator`
prints the figures."""

import json
import os
import pathlib
import subprocess
import sys
import zipfile

import numpy as np
import pytest
from lxml import etree

import fmpy.ssp
from fraccontact import fmu_path, omsimulator
from fraccontact.cosim import cosimulate
from fraccontact.scenes import masters, systems
from fraccontact.ssp import run_omsimulator, ssp_path

SCHEMA = pathlib.Path(fmpy.ssp.__file__).parent / "schema" / "SystemStructureDescription.xsd"
NS = {"ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
      "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
      "osp": "http://opensimulationplatform.com/SSP/OSPAnnotations",
      "oms": "https://raw.githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd"}
SSPS = {"drop_test": ssp_path(), **{scene: fmu_path().parent / f"{scene}.ssp" for scene in systems.SCENES}}
installed = pytest.mark.skipif(not omsimulator.available(), reason="OMSimulator is not installed (docs/ssp.md)")


def ssd(name):
    with zipfile.ZipFile(SSPS[name]) as z:
        return etree.fromstring(z.read("SystemStructure.ssd"))


@pytest.mark.parametrize("name", SSPS)
def test_each_ssd_is_ssp_1_0(name):
    etree.XMLSchema(file=str(SCHEMA)).assertValid(ssd(name))


@pytest.mark.parametrize("name", SSPS)
def test_each_ssd_names_omsimulators_fixed_step_master_at_the_other_masters_step(name):
    """OMSimulator reads the system's first annotation, and only one of type
    org.openmodelica holding oms:Annotations/oms:SimulationInformation; it
    matches the names with their prefixes (pugixml), so the prefix is oms."""
    root = ssd(name)
    first = root.find("ssd:System/ssd:Annotations/ssc:Annotation", NS)
    assert first is not None and first.get("type") == "org.openmodelica"
    [master] = first.findall("oms:Annotations/oms:SimulationInformation/oms:FixedStepMaster", NS)
    assert master.prefix == "oms" and master.get("description") == "oms-ma"
    [osp] = root.findall("ssd:DefaultExperiment/ssd:Annotations/ssc:Annotation/osp:Algorithm/"
                         "osp:FixedStepAlgorithm", NS)
    assert float(master.get("stepSize")) == float(osp.get("baseStepSize"))
    if name in systems.STEP:
        assert float(master.get("stepSize")) == systems.STEP[name]


# The FMUs' results do not depend on the master's rounding of its time: two
# Jacobi masters stepping from the outputs' initial values do the same
# arithmetic (test_ssp.py: fmpy, libcosim and our driver bit for bit), so
# 1e-12 tells rounding from a difference of physics (one step of lag is 2 %
# of the drop test's F_peak at H = 1e-5 s).
SAME = 1e-12


@installed
@pytest.mark.parametrize("H", (1e-3, 1e-4, 1e-5))
def test_omsimulator_runs_the_drop_test_as_our_jacobi_driver(H):
    got = run_omsimulator(ssp_path(), H)
    want = cosimulate(fmu_path(), os.environ.get("STRIKER_FMU", fmu_path().parent / "striker.fmu"), H,
                      "predictive", "jacobi")
    for key in ("F_peak", "eps", "E_diss"):
        assert got[key] == pytest.approx(want[key], rel=SAME, abs=0), key


@pytest.fixture(scope="module")
def traces():
    return {(scene, m): masters.run(scene, m) for scene in systems.SCENES for m in ("omsimulator", "libcosim")}


@installed
@pytest.mark.parametrize("scene", systems.SCENES)
def test_omsimulator_gives_libcosims_trace(scene, traces):
    """Both step every FMU from the last communication point, from the
    outputs' initial values, the bindings applied: one trace but for rounding."""
    a, b = traces[scene, "libcosim"], traces[scene, "omsimulator"]
    assert np.array_equal(a["t"], b["t"])
    for name in systems.RECORDED[scene]:
        scale = np.max(np.abs(a[name])) or 1.0
        assert np.max(np.abs(a[name] - b[name])) <= SAME * scale, name


def scene_command(*args, env=None):
    return subprocess.run([sys.executable, "-m", "fraccontact", "scene", *args], capture_output=True, text=True,
                          env=env or dict(os.environ), timeout=300)


def test_a_library_named_wrong_is_refused_on_one_line(tmp_path):
    missing = tmp_path / "libOMSimulator.so"
    r = scene_command("bumper", "--master", "omsimulator", env={**os.environ, "FRACCONTACT_OMSIMULATOR": str(missing)})
    assert r.returncode == 2 and r.stdout == ""
    assert f"FRACCONTACT_OMSIMULATOR = {missing} is invalid: it must name OMSimulator's library" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and "Traceback" not in r.stderr


def test_omsimulator_absent_is_refused_on_one_line(tmp_path):
    env = {k: v for k, v in os.environ.items() if k != "FRACCONTACT_OMSIMULATOR"}
    r = scene_command("bumper", "--master", "omsimulator", env=dict(env, PATH=str(tmp_path)))
    assert r.returncode == 2 and r.stdout == ""
    assert "OMSimulator is not installed: put OMSimulator on PATH or set FRACCONTACT_OMSIMULATOR" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and "Traceback" not in r.stderr
