"""build/drop_test.ssp (ssp/): its contents against the SSP 1.0 schema and
the FMUs it holds, and the scene run by two SSP importers (fmpy, libcosim)
against this project's own Jacobi driver and the library's drop test."""

import os
import pathlib
import zipfile

import pytest
from fmpy import read_model_description
from lxml import etree

import fmpy.ssp
import fraccontact
from fraccontact.cosim import cosimulate
from fraccontact.ssp import run_fmpy, run_libcosim

ROOT = pathlib.Path(__file__).resolve().parent.parent
CONTACT = pathlib.Path(os.environ.get("FRACCONTACT_FMU", ROOT / "build" / "fraccontact.fmu"))
STRIKER = pathlib.Path(os.environ.get("STRIKER_FMU", ROOT / "build" / "striker.fmu"))
SSP = pathlib.Path(os.environ.get("DROP_TEST_SSP") or CONTACT.parent / "drop_test.ssp")
SCHEMA = pathlib.Path(fmpy.ssp.__file__).parent / "schema"  # the SSP 1.0 XSDs fmpy ships
NS = {"ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
      "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
      "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues"}
STEPS = (1e-3, 1e-4, 1e-5)
# The importers and our driver do the same arithmetic (the FMU's results do
# not depend on the master's rounding of its time), measured bit for bit.
# A physical difference, F_avg instead of F_avg_next (one step of lag), is
# 2 % of F_peak at H = 1e-5 s: 1e-12 tells rounding from physics.
SAME = 1e-12
# Against the library's drop test: the contact's internal steps are dt_max
# up to an ulp, so the runs differ by rounding only, a few ulp per step (4
# allowed) carried on over the impact's 13 160 steps (as in test_jacobi.py).
ROUNDING = 4 * 2.220446049250313e-16 * 13160


@pytest.fixture(scope="module")
def ssp():
    if not SSP.exists():
        pytest.fail(f"{SSP} does not exist: build first (scripts/build)")
    return zipfile.ZipFile(SSP)


@pytest.fixture(scope="module")
def ssd(ssp):
    return etree.fromstring(ssp.read("SystemStructure.ssd"))


@pytest.fixture(scope="module")
def descriptions(ssp, ssd, tmp_path_factory):
    """Each component's model description, read from the FMU inside the SSP."""
    folder = tmp_path_factory.mktemp("ssp")
    out = {}
    for c in ssd.iterfind("ssd:System/ssd:Elements/ssd:Component", NS):
        path = folder / pathlib.PurePosixPath(c.get("source")).name
        path.write_bytes(ssp.read(c.get("source")))
        out[c.get("name")] = read_model_description(str(path))
    return out


def test_the_zip_holds_the_scene_its_parameters_and_this_builds_fmus(ssp):
    files = {n for n in ssp.namelist() if not n.endswith("/")}
    assert files == {"SystemStructure.ssd", "resources/h20.ssv", "resources/fraccontact.fmu",
                     "resources/striker.fmu"}
    assert ssp.read("resources/fraccontact.fmu") == CONTACT.read_bytes()
    assert ssp.read("resources/striker.fmu") == STRIKER.read_bytes()


@pytest.mark.parametrize("member, xsd", [("SystemStructure.ssd", "SystemStructureDescription.xsd"),
                                         ("resources/h20.ssv", "SystemStructureParameterValues.xsd")])
def test_valid_against_the_ssp_1_0_schema(ssp, member, xsd):
    schema = etree.XMLSchema(file=str(SCHEMA / xsd))
    schema.assertValid(etree.fromstring(ssp.read(member)))


def connectors(ssd):
    """{(component, connector): (kind, type, unit)} as the SSD declares them."""
    out = {}
    for c in ssd.iterfind("ssd:System/ssd:Elements/ssd:Component", NS):
        for k in c.iterfind("ssd:Connectors/ssd:Connector", NS):
            typed = k[0]
            out[c.get("name"), k.get("name")] = (k.get("kind"), etree.QName(typed).localname, typed.get("unit"))
    return out


def test_connectors_are_the_fmus_variables_with_their_causality_type_and_unit(ssd, descriptions):
    for (component, name), (kind, type_, unit) in connectors(ssd).items():
        variables = {v.name: v for v in descriptions[component].modelVariables}
        assert name in variables, f"{component}.{name}"
        v = variables[name]
        assert (v.causality, v.type, v.unit) == (kind, type_, unit), f"{component}.{name}"


def test_connections_join_an_output_to_an_input_and_feed_every_input(ssd):
    declared = connectors(ssd)
    ends = []
    for c in ssd.iterfind("ssd:System/ssd:Connections/ssd:Connection", NS):
        start, end = (c.get("startElement"), c.get("startConnector")), (c.get("endElement"), c.get("endConnector"))
        assert declared[start][0] == "output" and declared[end][0] == "input", (start, end)
        assert declared[start][1] == declared[end][1], (start, end)  # same type
        ends.append(end)
    inputs = [k for k, (kind, _, _) in declared.items() if kind == "input"]
    assert sorted(ends) == sorted(inputs)  # each input fed exactly once (fmpy requires it)
    pairs = {(c.get("startElement") + "." + c.get("startConnector"), c.get("endElement") + "." + c.get("endConnector"))
             for c in ssd.iterfind("ssd:System/ssd:Connections/ssd:Connection", NS)}
    assert pairs == {("striker.v", "contact.v"), ("contact.F_avg_next", "striker.F")}  # for Jacobi masters


def test_the_parameter_set_holds_only_what_differs_from_the_fmus_defaults(ssp, ssd, descriptions):
    binding = ssd.find("ssd:System/ssd:Elements/ssd:Component[@name='contact']/ssd:ParameterBindings/"
                       "ssd:ParameterBinding", NS)
    assert binding.get("source") == "resources/h20.ssv"
    variables = {v.name: v for v in descriptions["contact"].modelVariables}
    values = {}
    for p in etree.fromstring(ssp.read(binding.get("source"))).iterfind("ssv:Parameters/ssv:Parameter", NS):
        typed = p[0]
        v = variables[p.get("name")]
        assert (v.causality, v.type) == ("parameter", etree.QName(typed).localname), p.get("name")
        assert int(typed.get("value")) != int(v.start), f"{p.get('name')} repeats the FMU's default"
        values[p.get("name")] = int(typed.get("value"))
    assert values == {"scene": 2, "law": 2, "coupling": 2}
    # the proxy striker of the mass-aware coupling: the contact's m is the striker's by default
    striker_m = next(v for v in descriptions["striker"].modelVariables if v.name == "m")
    assert float(variables["m"].start) == float(striker_m.start) > 0


@pytest.fixture(scope="module")
def runs(ssp):
    """Every step of STEPS in both importers and our driver, and the library's drop test."""
    out = {"monolithic": fraccontact.impact(law=2)}
    for H in STEPS:
        out["fmpy", H] = run_fmpy(SSP, H)
        out["libcosim", H] = run_libcosim(SSP, H)
        out["driver", H] = cosimulate(CONTACT, STRIKER, H, "predictive", "jacobi")
    return out


def test_libcosim_applies_the_parameter_bindings(runs):
    # it only warns when it cannot: a silent scene = 1 would be the monolithic test
    assert runs["libcosim", STEPS[0]]["applied"] == {"scene": 2, "law": 2, "coupling": 2}


@pytest.mark.parametrize("H", STEPS)
@pytest.mark.parametrize("importer", ["fmpy", "libcosim"])
def test_each_importer_runs_our_jacobi_scene(runs, importer, H):
    """Both SSP masters are Jacobi masters: their results are our driver's
    Jacobi run with F_avg_next at the same step, to rounding."""
    for key in ("F_peak", "eps", "E_diss"):
        assert runs[importer, H][key] == pytest.approx(runs["driver", H][key], rel=SAME, abs=0), key


@pytest.mark.parametrize("H", STEPS)
@pytest.mark.parametrize("importer", ["fmpy", "libcosim"])
def test_the_scene_is_the_drop_test_at_any_step(runs, importer, H):
    """F_avg_next reaches the striker in the step it belongs to: the scene is
    the library's drop test to rounding, up to a step of 1 ms. (fmpy's
    master starts every connector at 0, so its impact begins a step late,
    the same impact; libcosim passes the striker's v0 on at initialization.)"""
    truth = runs["monolithic"]
    assert runs[importer, H]["F_peak"] == pytest.approx(truth.F_peak, rel=ROUNDING, abs=0)
    assert runs[importer, H]["eps"] == pytest.approx(truth.eps, rel=ROUNDING, abs=0)
    assert runs[importer, H]["E_diss"] == pytest.approx(truth.E_diss, rel=ROUNDING, abs=0)
