"""build/drop_test.ssp (ssp/): its contents against the SSP 1.0 schema and
the FMUs it holds, and the scene run by two SSP importers (fmpy, libcosim)
against this project's own Jacobi driver and the monolithic drop test."""

import math
import os
import pathlib
import zipfile

import pytest
from fmpy import read_model_description
from lxml import etree

import fmpy.ssp
from fraccontact.cosim import cosimulate, monolithic
from fraccontact.ssp import run_fmpy, run_libcosim

ROOT = pathlib.Path(__file__).resolve().parent.parent
CONTACT = pathlib.Path(os.environ.get("FRACCONTACT_FMU", ROOT / "build" / "fraccontact.fmu"))
STRIKER = pathlib.Path(os.environ.get("STRIKER_FMU", ROOT / "build" / "striker.fmu"))
SSP = pathlib.Path(os.environ.get("DROP_TEST_SSP") or CONTACT.parent / "drop_test.ssp")
SCHEMA = pathlib.Path(fmpy.ssp.__file__).parent / "schema"  # the SSP 1.0 XSDs fmpy ships
NS = {"ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
      "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
      "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues"}
STEPS = (1e-5, 1e-6, 1e-7)
# The importers and our driver do the same arithmetic; only the time stamps
# may round differently (libcosim counts integer nanoseconds), measured
# below 1e-14. The smallest physical difference in reach, one step of lag
# at H = 1e-7 s, is 2e-4 of F_peak: 1e-12 tells rounding from physics.
SAME = 1e-12


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
    assert pairs == {("striker.v", "contact.v"), ("contact.F_avg", "striker.F")}  # the mass-aware coupling


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
    assert values == {"scene": 2, "law": 2}
    # the proxy striker of the mass-aware coupling: the contact's m is the striker's by default
    striker_m = next(v for v in descriptions["striker"].modelVariables if v.name == "m")
    assert float(variables["m"].start) == float(striker_m.start) > 0


@pytest.fixture(scope="module")
def runs(ssp):
    """Every step of STEPS in both importers and our driver, and the monolithic drop test."""
    out = {"monolithic": monolithic(CONTACT)}
    for H in STEPS:
        out["fmpy", H] = run_fmpy(SSP, H)
        out["libcosim", H] = run_libcosim(SSP, H)
        out["driver", H] = cosimulate(CONTACT, STRIKER, H, "mass-aware", "jacobi")
    return out


def test_libcosim_applies_the_parameter_bindings(runs):
    # it only warns when it cannot: a silent scene = 1 would be the monolithic test
    assert runs["libcosim", STEPS[0]]["applied"] == {"scene": 2, "law": 2}


@pytest.mark.parametrize("H", STEPS)
@pytest.mark.parametrize("importer", ["fmpy", "libcosim"])
def test_each_importer_runs_our_jacobi_scene(runs, importer, H):
    """Both SSP masters are Jacobi masters: their results are our driver's
    Jacobi mass-aware run at the same step, to rounding."""
    for key in ("F_peak", "eps", "E_diss"):
        assert runs[importer, H][key] == pytest.approx(runs["driver", H][key], rel=SAME, abs=0), key


def errors(runs, key):
    ref = runs["monolithic"][key]
    return [abs(runs["fmpy", H][key] / ref - 1) for H in STEPS]


@pytest.mark.parametrize("key", ["F_peak", "eps", "E_diss"])
def test_the_scene_converges_to_the_drop_test_at_first_order(runs, key):
    """Jacobi lags the force by one step: the error falls as H (measured
    order 1.000 from 1e-5 to 1e-7 s), and H = 1e-7 s lands on the
    first-order estimate from the two larger steps."""
    e = errors(runs, key)
    for (e1, H1), (e2, H2) in zip(zip(e, STEPS), zip(e[1:], STEPS[1:])):
        order = math.log(e1 / e2) / math.log(H1 / H2)
        assert order == pytest.approx(1, abs=0.05), (H1, H2)
    estimate = e[1] * STEPS[2] / STEPS[1]
    assert e[2] == pytest.approx(estimate, rel=0.01)
    assert e[2] < 1e-3  # the smallest step is the drop test within 0.1 %
