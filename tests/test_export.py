"""fraccontact export (docs/export.md): an exported FMU gives the full FMU's
results at the same values to the last bit, passes fmpy's validation and
fmu-manipulation-toolbox's checker, exposes only its scene's variables, and
refuses a hostile file of fixed values at instantiation with a message
naming the file, the line, the variable, the value and the rule."""

import json
import os
import pathlib
import re
import shutil
import subprocess
import sys
import zipfile
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi3 import FMU3Slave
from fmpy.validation import validate_fmu

import fraccontact
from fraccontact.export import COUPLINGS
from fraccontact.fixed_values import FIXED_VALUES
from doc_pages import fenced_blocks
from fmu_driver import Slave

ROOT = pathlib.Path(__file__).resolve().parent.parent
FMU2 = fraccontact.fmu_path("fraccontact")
FMU3 = fraccontact.fmu_path("fraccontact-fmi3")
STOP, INTERVAL = 3e-3, 1e-5

# Configurations: (fmi, scene, bodies, coupling, values, keep). The values
# differ from the defaults, so that an FMU ignoring its file would differ.
CONFIGURATIONS = {
    "fmi2-drop-dashpot-hertz": (2, "drop", 1, "gauss-seidel", dict(k=3.1e8, c=5200.0, law="hertz", v=0.7), ()),
    "fmi3-drop-springpot": (3, "drop", 1, "gauss-seidel",
                            dict(damper="springpot", c_alpha=2.5e5, damper_order=0.6, k=3.2e8), ("c_alpha",)),
    "fmi2-drop-two-bodies-gravity-jacobi": (2, "drop", 2, "jacobi", dict(m2=1.5, v2=-0.1, g=9.81, c=7000.0), ()),
    "fmi2-driven-two-bodies-springpot-jacobi": (2, "driven", 2, "jacobi",
                                                dict(damper="springpot", memory="compressed", memory_tolerance=1e-4,
                                                     m=0.5, m2=2.0, v=0.8, a=-3.0, g=9.81), ("memory_tolerance",)),
    "fmi3-driven-dashpot-gravity": (3, "driven", 1, "gauss-seidel", dict(m=0.9, v=0.5, g=9.81, c=4000.0, a=2.0), ()),
}


# Model Exchange: (fmi, scene, bodies, values). The values differ from the defaults, as above.
MODEL_EXCHANGE = {
    "fmi2-me-drop-dashpot": (2, "drop", 1, dict(law="hertz", k=3.1e8, c=5200.0, v=0.7)),
    "fmi3-me-drop-two-bodies-springpot-gravity": (3, "drop", 2, dict(law="hertz", damper="springpot",
                                                                     c_alpha=2.5e5, damper_order=0.6, m2=1.5,
                                                                     v2=-0.1, g=9.81)),
    "fmi2-me-driven-springpot": (2, "driven", 1, dict(law="hertz", damper="springpot", v=0.4, m=0.0)),
    "fmi3-me-driven-two-bodies-dashpot": (3, "driven", 2, dict(law="hertz", c=4000.0, v=0.5, v2=-0.2, m=0.0)),
}


def full_names(fmu):
    return {v.name: v for v in read_model_description(str(fmu)).modelVariables}


def exported(tmp_path, name):
    fmi, scene, bodies, coupling, values, keep = CONFIGURATIONS[name]
    path = tmp_path / f"{name}.fmu"
    out = fraccontact.export(path, scene=scene, bodies=bodies, coupling=coupling, fmi=fmi, values=values, keep=keep)
    return path, out


def full_values(name):
    """What an importer sets on the full FMU for the configuration: its values, the scene's and the coupling's
    codes."""
    fmi, scene, bodies, coupling, values, keep = CONFIGURATIONS[name]
    words = fraccontact.model.WORDS
    codes = {n: words[n][x] if isinstance(x, str) else x for n, x in values.items()}
    return dict(codes, scene=words["scene"][scene], coupling=COUPLINGS[coupling])


def run(fmu, outputs, **start):
    return simulate_fmu(str(fmu), start_values=start, stop_time=STOP, output_interval=INTERVAL, output=outputs,
                        fmi_type="CoSimulation")


@pytest.mark.parametrize("name", CONFIGURATIONS)
def test_an_exported_fmu_gives_the_full_fmus_results_to_the_last_bit(tmp_path, name):
    """Every output of the exported FMU, at every communication point, has
    the bits of the full FMU's run with the same values set by the importer;
    and the full FMU at its defaults differs (the file is read)."""
    path, out = exported(tmp_path, name)
    fmi = CONFIGURATIONS[name][0]
    full = FMU2 if fmi == 2 else FMU3
    md = read_model_description(str(path))
    outputs = [v.name for v in md.modelVariables if v.causality == "output"]
    mine, theirs = run(path, outputs), run(full, outputs, **full_values(name))
    for column in ["time"] + outputs:
        assert mine[column].tobytes() == theirs[column].tobytes(), column
    defaults = run(full, outputs)
    assert defaults["F_peak"][-1] != mine["F_peak"][-1]


@pytest.mark.parametrize("name", [name for name, c in CONFIGURATIONS.items() if c[5]])
def test_a_kept_variable_stays_tunable_and_starts_at_its_given_value(tmp_path, name):
    """A kept variable is in the exported modelDescription.xml with the given
    value as its start; set to another value it gives the full FMU's run at
    that value, bit for bit."""
    keep = CONFIGURATIONS[name][5]
    path, out = exported(tmp_path, name)
    full = FMU2 if CONFIGURATIONS[name][0] == 2 else FMU3
    variables = {v.name: v for v in read_model_description(str(path)).modelVariables}
    given = full_values(name)
    for n in keep:
        assert float(variables[n].start) == given[n]
        other = given[n] * 0.5
        mine = run(path, ["F_peak", "x2"], **{n: other})
        theirs = run(full, ["F_peak", "x2"], **dict(given, **{n: other}))
        assert mine["F_peak"].tobytes() == theirs["F_peak"].tobytes()
        assert mine["x2"].tobytes() == theirs["x2"].tobytes()


def exported_any(tmp_path, name):
    """A co-simulation configuration's export, or a Model Exchange one's; and its FMI version."""
    if name in CONFIGURATIONS:
        return (*exported(tmp_path, name), CONFIGURATIONS[name][0])
    fmi, scene, bodies, values = MODEL_EXCHANGE[name]
    path = tmp_path / f"{name}.fmu"
    out = fraccontact.export(path, scene=scene, bodies=bodies, coupling="model-exchange", fmi=fmi, values=values)
    return path, out, fmi


@pytest.mark.parametrize("name", [*CONFIGURATIONS, *MODEL_EXCHANGE])
def test_exported_fmus_pass_fmpys_validation_and_the_toolbox_checker(tmp_path, name):
    path, out, _ = exported_any(tmp_path, name)
    assert validate_fmu(str(path)) == []
    done = subprocess.run([str(pathlib.Path(sys.executable).parent / "fmutool"), "-input", str(path), "-check"],
                          capture_output=True, text=True)
    log = done.stdout + done.stderr
    assert done.returncode == 0, log
    assert "No semantic error" in log and "seems to be compliant" in log and "ERROR" not in log, log


@pytest.mark.parametrize("name", [*CONFIGURATIONS, *MODEL_EXCHANGE])
def test_the_model_structure_is_renumbered_consistently(tmp_path, name):
    """FMI 2.0: every Unknown's index and dependency is the 1-based position
    of the same variable in the exported ModelVariables as in the full one;
    FMI 3.0: every reference is a value reference of an exposed variable. An
    output keeps its dependencies on the knowns only, the inputs and the states
    (a co-simulation export has no states: its outputs depend on nothing)."""
    path, out, fmi = exported_any(tmp_path, name)
    full = ET.fromstring(zipfile.ZipFile(FMU2 if fmi == 2 else FMU3).read("modelDescription.xml"))
    mine = ET.fromstring(zipfile.ZipFile(path).read("modelDescription.xml"))

    def unknowns(root):
        """{(section, variable name): dependency names} of the ModelStructure."""
        names = [v.get("name") for v in root.find("ModelVariables")]
        by_vr = {v.get("valueReference"): v.get("name") for v in root.find("ModelVariables")}
        name_of = (lambda i: names[int(i) - 1]) if fmi == 2 else by_vr.__getitem__
        key = "index" if fmi == 2 else "valueReference"
        out = {}
        for element in root.find("ModelStructure").iter():
            if element.get(key) is not None:
                section = element.tag if fmi == 3 else next(s.tag for s in root.find("ModelStructure")
                                                           if element in list(s))
                out[section, name_of(element.get(key))] = {name_of(d) for d in
                                                           element.get("dependencies", "").split()}
        return out
    def knowns(root):
        """What an output may depend on: the inputs, and the states, those a derivative names."""
        variables = list(root.find("ModelVariables"))
        names = [v.get("name") for v in variables]
        by_vr = {v.get("valueReference"): v.get("name") for v in variables}
        derivatives = [e.get("derivative") for e in root.iter() if e.get("derivative") is not None]
        return ({v.get("name") for v in variables if v.get("causality") == "input"}
                | {names[int(d) - 1] if fmi == 2 else by_vr[d] for d in derivatives})
    exposed = set(out["variables"])
    outputs = {("Outputs", "Output")[fmi - 2]}
    expected = {key: deps & (knowns(mine) if key[0] in outputs else exposed)
                for key, deps in unknowns(full).items() if key[1] in exposed}
    assert unknowns(mine) == expected


def run_model_exchange(fmu, outputs, **start):
    return simulate_fmu(str(fmu), start_values=start, stop_time=STOP, output_interval=INTERVAL, output=outputs,
                        fmi_type="ModelExchange")


@pytest.mark.parametrize("name", MODEL_EXCHANGE)
def test_a_model_exchange_export_gives_the_full_fmus_model_exchange_results_to_the_last_bit(tmp_path, name):
    """export --coupling model-exchange: an FMU of Model Exchange alone,
    with every state, derivative and event indicator of the full FMU and
    none of the co-simulation's averages; fmpy's CVode run of it has, at
    every output point, the bits of the full FMU's Model Exchange run at the
    same values; it passes fmpy's validation; the full FMU at its defaults'
    law 2 differs (the file is read)."""
    fmi, scene, bodies, values = MODEL_EXCHANGE[name]
    path, out, _ = exported_any(tmp_path, name)
    md = read_model_description(str(path))
    assert md.modelExchange is not None and md.coSimulation is None
    full = FMU2 if fmi == 2 else FMU3
    full_md = read_model_description(str(full))
    assert len(md.derivatives) == len(full_md.derivatives) > 4
    assert [d.variable.name for d in md.derivatives] == [d.variable.name for d in full_md.derivatives]
    assert [d.variable.derivative.name for d in md.derivatives] == \
        [d.variable.derivative.name for d in full_md.derivatives]
    assert md.numberOfEventIndicators == full_md.numberOfEventIndicators == 2
    assert not {"F_avg", "F_avg_next", "a", "a2", "coupling"} & set(out["variables"])
    assert "\nomit F_avg\n" in out["fixed"] and "\nomit F_avg_next\n" in out["fixed"]
    outputs = [v.name for v in md.modelVariables if v.causality == "output"]
    words = fraccontact.model.WORDS
    given = dict({n: words[n][x] if isinstance(x, str) else x for n, x in values.items()},
                 scene=words["scene"][scene])
    mine, theirs = run_model_exchange(path, outputs), run_model_exchange(full, outputs, **given)
    for column in ["time"] + outputs:
        assert mine[column].tobytes() == theirs[column].tobytes(), column
    assert mine["F_peak"][-1] > 0
    assert run_model_exchange(full, outputs, law=2)["F_peak"][-1] != mine["F_peak"][-1]
    assert validate_fmu(str(path)) == []


def test_a_one_body_dashpot_from_a_fit_exposes_its_inputs_outputs_and_kept_parameters(tmp_path):
    """fraccontact fit --json, then export --fit: the FMU has v and m, the
    outputs a Gauss-Seidel master reads (all but F_avg_next), and c; its
    description names the material, the fit's source and residual figures;
    the fitted k and c are its values."""
    fit = tmp_path / "fit.json"
    done = subprocess.run([sys.executable, "-m", "fraccontact", "fit", "--F-peak", "1004", "--eps", "0.59",
                           "--height", "0.020", "--m", "0.7437", "--json"], capture_output=True, text=True,
                          check=True)
    fit.write_text(done.stdout)
    fitted = json.loads(done.stdout)
    path = tmp_path / "pp.fmu"
    done = subprocess.run([sys.executable, "-m", "fraccontact", "export", str(path), "--fit", str(fit), "--keep", "c",
                           "--material", "PP"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    md = read_model_description(str(path))
    names = {v.name for v in md.modelVariables}
    full = full_names(FMU2)
    outputs = {n for n, v in full.items() if v.causality == "output"}
    assert names == {"v", "m", "c"} | (outputs - {"F_avg_next"})
    assert len(names) == 14 < len(full) == 365
    assert "PP" in md.description and str(fit) in md.description and "F_peak" in md.description
    starts = {v.name: v.start for v in md.modelVariables}
    assert float(starts["c"]) == fitted["c"] and float(starts["m"]) == 0.7437
    text = zipfile.ZipFile(path).read(FIXED_VALUES).decode()
    assert f"\nk {fitted['k']!r}\n" in text


# ---------------------------------------------------------------------------------------------------------------
# The file of fixed values, hostile.

HOSTILE = [
    ("cc 1\nend\n", 'line 1: no variable of this FMU is named "cc"'),
    ("c 5000\nk\nend\n", 'line 2: "k" alone, where a line holds a name and a value (a truncated line?)'),
    ("c 5000\n", 'truncated: no line "end" after line 1'),
    ("c 5e3x\nend\n", "line 1: c = 5e3x is not a Real"),
    ("law 1.5\nend\n", "line 1: law = 1.5 is not an Integer"),
    ("c -1\nend\n", "line 1: c = -1 is invalid: the dashpot constant must be positive, finite and not denormal"),
    ("law 4\nend\n", "line 1: law = 4 is invalid"),
    ("# a comment\nc 1000\n\nc 2000\nend\n", "line 4: c = 2000: c is already set on line 2"),
    ("F 1\nend\n", "line 1: F is an output, which has no value to fix"),
    ("c 1 2\nend\n", "line 1: 3 words, where a line holds a name and a value"),
    ("end\nc 1\n", 'line 2: text after the line "end"'),
    ("guid {a}\nguid {b}\nend\n", "line 2: guid is already set on line 1; it takes one line"),
    ("c 1\0\nend\n", "holds a NUL byte"),
    ("omit c\nend\n", "line 1: omit c: an input or a parameter, which the FMU has to offer"),
    ("omit cc\nend\n", "line 1: omit cc: no variable of this FMU has that name"),
    ("omit F\n\nomit F\nend\n", "line 3: omit F: already on line 1"),
    ("#" * 20000 + "\nend\n", "is larger than 16384 bytes"),
]


def unpacked_with(tmp_path, fmu, text):
    """The FMU unpacked into a folder whose name has a space (a %20 in FMI 2.0's URI), its file of fixed values
    replaced by text."""
    folder = tmp_path / "un packed"
    shutil.rmtree(folder, ignore_errors=True)
    extract(str(fmu), unzipdir=str(folder))
    (folder / "resources").mkdir(exist_ok=True)
    (folder / FIXED_VALUES).write_bytes(text.encode())
    return folder


def instantiate_fmi3(md, folder):
    messages = []

    def log(env, status, category, message):
        messages.append(message.decode())
    fmu = FMU3Slave(guid=md.guid, unzipDirectory=str(folder), modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="hostile")
    try:
        fmu.instantiate(logMessage=log)
    except Exception:
        return messages
    fmu.freeInstance()
    raise AssertionError(f"instantiated: {messages}")


@pytest.mark.parametrize("text, message", HOSTILE)
def test_a_hostile_file_of_fixed_values_is_refused_at_instantiation(tmp_path, text, message):
    """Both FMI versions: no instance, and an error naming the function, the
    file, the line, the variable, the value and the rule."""
    md = read_model_description(str(FMU2))
    folder = unpacked_with(tmp_path, FMU2, text)
    with pytest.raises(Exception):
        Slave(md, str(folder), start=False, instance_name="hostile")
    error = fraccontact.fmu._RECENT[-1][2]
    file = folder / FIXED_VALUES
    assert error.startswith(f"fmi2Instantiate: {file}") and message in error, error
    md3 = read_model_description(str(FMU3))
    folder = unpacked_with(tmp_path, FMU3, text)
    errors = instantiate_fmi3(md3, folder)
    assert errors and errors[-1].startswith(f"fmi3InstantiateCoSimulation: {file}") and message in errors[-1]


def test_an_exported_fmu_has_its_own_guid_which_its_binary_takes_from_its_file(tmp_path):
    """Each export its own GUID (the same for the same export), in its
    modelDescription.xml and its file: the binary takes it, and refuses the
    full FMU's GUID for that file, the file's GUID for the full FMU, and the
    exported FMU whose file was removed."""
    path, out = exported(tmp_path, "fmi2-drop-dashpot-hertz")
    full = read_model_description(str(FMU2))
    mine = read_model_description(str(path))
    assert mine.guid != full.guid and f"\nguid {mine.guid}\nend\n" in out["fixed"]
    second = tmp_path / "second.fmu"
    fmi, scene, bodies, coupling, values, keep = CONFIGURATIONS["fmi2-drop-dashpot-hertz"]
    fraccontact.export(second, scene=scene, bodies=bodies, coupling=coupling, fmi=fmi, values=values, keep=keep)
    assert read_model_description(str(second)).guid == mine.guid
    other = tmp_path / "other.fmu"
    fraccontact.export(other, values=dict(c=1000.0))
    assert read_model_description(str(other)).guid != mine.guid
    folder = tmp_path / "unpacked"
    extract(str(path), unzipdir=str(folder))
    with pytest.raises(Exception):
        Slave(full, str(folder), start=False, instance_name="full-guid")
    assert fraccontact.fmu._RECENT[-1][2] == f"fmi2Instantiate: fmuGUID does not match modelDescription.xml ({mine.guid})"
    folder = unpacked_with(tmp_path, FMU2, f"guid {mine.guid}\nend\n")
    with pytest.raises(Exception):
        Slave(full, str(folder), start=False, instance_name="file-guid")
    assert fraccontact.fmu._RECENT[-1][2] == f"fmi2Instantiate: fmuGUID does not match modelDescription.xml ({mine.guid})"
    # an exported FMU whose file was removed: its GUID is unknown to the binary
    folder = tmp_path / "unpacked"
    (folder / FIXED_VALUES).unlink()
    with pytest.raises(Exception):
        Slave(mine, str(folder), start=False, instance_name="no-file")
    assert fraccontact.fmu._RECENT[-1][2] == (f"fmi2Instantiate: fmuGUID does not match modelDescription.xml "
                                             f"({full.guid}; an exported FMU names its own in "
                                             f"resources/fixed_values.txt, which this FMU has not)")


SOAK = os.environ.get("FRACCONTACT_SOAK", str(ROOT / "build" / "fraccontact-soak"))


def soak_memory(*args):
    done = subprocess.run([SOAK, "memory", *args], capture_output=True, text=True, check=True)
    return json.loads(done.stdout)


@pytest.mark.skipif(os.environ.get("FRACCONTACT_SANITIZED") == "1",
                    reason="AddressSanitizer's allocator keeps its own account of the heap")
def test_a_gauss_seidel_export_keeps_no_prediction_and_holds_what_the_page_says(tmp_path):
    """A one-body dashpot exported for the drop test (Gauss-Seidel) omits
    F_avg_next: its instance holds at most 2 KiB, less than the full FMU's
    by at least the contact model it keeps no second copy of, the page's
    figures as fraccontact-soak measures them; a Jacobi export omits F_avg
    and keeps its prediction (no smaller than the full FMU's)."""
    path = tmp_path / "gs.fmu"
    out = fraccontact.export(path)  # the h20 drop test's values
    assert "\nomit F_avg_next\n" in out["fixed"] and "\nomit F_avg\n" not in out["fixed"]
    folder = tmp_path / "gs"
    extract(str(path), unzipdir=str(folder))
    guid = read_model_description(str(path)).guid
    mine = soak_memory((folder / "resources").as_uri(), guid)["instance_bytes"]
    full = soak_memory()
    dashpot = full["configurations"][0]
    assert (dashpot["damper"], dashpot["memory"]) == (1, 2) and mine <= 2048
    # the same file without its omission: the prediction back, a contact model and its few scalars, in a
    # block of its own (malloc's header), less the list entry the omission took
    (folder / FIXED_VALUES).write_text(out["fixed"].replace("\nomit F_avg_next\n", "\n"))
    predicting = soak_memory((folder / "resources").as_uri(), guid)["instance_bytes"]
    assert full["bytes_contact_model"] <= predicting - mine <= full["bytes_contact_model"] + 64
    said = re.search(r"<!-- export-memory -->([\d,]+) B per instance, against the full FMU's ([\d,]+) "
                     r"B<!-- /export-memory -->", PAGE)
    assert said and [int(x.replace(",", "")) for x in said.groups()] == [mine, dashpot["instance_bytes"]]
    jacobi = tmp_path / "jacobi.fmu"
    out = fraccontact.export(jacobi, coupling="jacobi")
    assert "\nomit F_avg\n" in out["fixed"] and "\nomit F_avg_next\n" not in out["fixed"]
    folder = tmp_path / "jacobi"
    extract(str(jacobi), unzipdir=str(folder))
    held = soak_memory((folder / "resources").as_uri(), read_model_description(str(jacobi)).guid)
    assert held["instance_bytes"] >= dashpot["instance_bytes"]


def test_an_instance_without_f_avg_next_refuses_it_and_the_jacobi_coupling(tmp_path):
    """A file that omits F_avg_next: reading it is an error naming it, before
    and after a reset (the omission is set again); an FMU state set again
    steps as before; coupling = 2 is refused
    when set and, from the file, at initialization; the full FMU reads it."""
    md = read_model_description(str(FMU2))
    folder = unpacked_with(tmp_path, FMU2, "omit F_avg_next\nend\n")
    s = Slave(md, str(folder), start=True, instance_name="lean")
    vr = next(v.valueReference for v in md.modelVariables if v.name == "F_avg_next")
    # an FMU state taken in the impact and set again: the same steps from it, to the bit
    for _ in range(30):
        s.step(INTERVAL)
    state, t = s.fmu.getFMUstate(), s.t
    ahead = [s.step(INTERVAL) or s.get("F_avg") for _ in range(100)]
    s.fmu.setFMUstate(state)
    s.t = t
    assert [s.step(INTERVAL) or s.get("F_avg") for _ in range(100)] == ahead and max(ahead) > 0
    for reset in (False, True):
        if reset:
            s.fmu.reset()
            s.enter()
        with pytest.raises(Exception):
            s.fmu.getReal([vr])
        assert fraccontact.fmu._RECENT[-1][2].startswith(f"F_avg_next (value reference {vr}): this exported FMU "
                                                         "does not offer it"), fraccontact.fmu._RECENT[-1]
    folder = unpacked_with(tmp_path, FMU2, "end\n")
    assert len(Slave(md, str(folder), start=True, instance_name="full").fmu.getReal([vr])) == 1
    folder = unpacked_with(tmp_path, FMU2, "omit F_avg_next\nend\n")
    s = Slave(md, str(folder), start=False, instance_name="set")
    with pytest.raises(Exception):
        s.set(coupling=2)
    assert "coupling = 2 is invalid: this FMU does not offer F_avg_next" in fraccontact.fmu._RECENT[-1][2]
    folder = unpacked_with(tmp_path, FMU2, "coupling 2\nomit F_avg_next\nend\n")
    s = Slave(md, str(folder), start=False, instance_name="file")
    with pytest.raises(Exception):
        s.start()
    assert "coupling = 2 is invalid: this FMU does not offer F_avg_next" in fraccontact.fmu._RECENT[-1][2]


def test_a_reset_sets_the_fixed_values_again(tmp_path):
    """fmi2Reset and fmi3Reset: the instance as instantiated, its fixed
    values set again (read through the full FMU's references)."""
    md = read_model_description(str(FMU2))
    folder = unpacked_with(tmp_path, FMU2, "c 5000\nlaw 2\nend\n")
    s = Slave(md, str(folder), start=True, instance_name="reset")
    assert (s.get("c"), s.get("law")) == (5000.0, 2)
    s.fmu.reset()
    s.enter()
    assert (s.get("c"), s.get("law")) == (5000.0, 2)
    md3 = read_model_description(str(FMU3))
    folder = unpacked_with(tmp_path, FMU3, "c 5000\nend\n")
    fmu = FMU3Slave(guid=md3.guid, unzipDirectory=str(folder), modelIdentifier="fraccontact", instanceName="reset")
    fmu.instantiate()
    c = next(v.valueReference for v in md3.modelVariables if v.name == "c")
    fmu.reset()
    fmu.enterInitializationMode()
    assert fmu.getFloat64([c]) == [5000.0]
    fmu.freeInstance()


# ---------------------------------------------------------------------------------------------------------------
# The command's refusals.


@pytest.mark.parametrize("args, message", [
    (["--c", "-1"], "c = -1 is invalid: the dashpot constant must be positive"),
    (["--law", "cubic"], "law = 'cubic' is invalid: it must be a whole number that fits a C int or one of g1, "
                         "hertz, g1x"),
    # Model Exchange's rules, as the FMU words them at initialization
    (["--coupling", "model-exchange"], "law = 1 is invalid: Model Exchange takes the closed-form force, law = 2"),
    (["--coupling", "model-exchange", "--law", "hertz", "--damper", "2", "--memory", "1", "--fmi", "3"],
     "memory = 1 is invalid: Model Exchange takes the springpot's compressed memory"),
    (["--keep", "F"], "keep = 'F' is invalid: it must name a parameter or input of the FMU"),
    (["--m2", "2"], "m2 = 2.0 is invalid with bodies = 1"),
    # the FMU's own rules, met at the instantiation export tries
    (["--scene", "driven", "--a", "nan"], "fmi2Instantiate: "),
    (["--scene", "driven", "--a", "nan", "--fmi", "3"], "fmi3InstantiateCoSimulation: "),
])
def test_the_command_refuses_a_bad_value_and_writes_nothing(tmp_path, args, message):
    path = tmp_path / "x.fmu"
    done = subprocess.run([sys.executable, "-m", "fraccontact", "export", str(path)] + args, capture_output=True,
                          text=True)
    assert done.returncode == 2 and message in done.stderr, done.stderr
    assert os.listdir(tmp_path) == []


# ---------------------------------------------------------------------------------------------------------------
# docs/export.md, run and measured.

PAGE = (ROOT / "docs" / "export.md").read_text()


def page_blocks(language):
    return [body for _, lang, body in fenced_blocks(PAGE) if lang == language]


def test_the_pages_counts_are_what_export_writes(tmp_path):
    """The table of exposed variables per scene and bodies, for both FMI
    versions and both couplings, and the full FMUs' counts the page names."""
    table = PAGE.split("<!-- export-counts:begin -->")[1].split("<!-- export-counts:end -->")[0]
    rows = re.findall(r"^\| (drop|driven) \| (\d) \| (\d+) \| (\d+) \| (\d+) \| (\d+) \|$", table, re.M)
    assert len(rows) == 4
    for scene, bodies, *counts in rows:
        for (fmi, couplings), count in zip(((2, COUPLINGS), (3, COUPLINGS), (2, ["model-exchange"]),
                                            (3, ["model-exchange"])), counts):
            for coupling in couplings:
                values = dict(law="hertz") if coupling == "model-exchange" else {}
                out = fraccontact.export(tmp_path / "x.fmu", scene=scene, bodies=int(bodies), coupling=coupling,
                                         fmi=fmi, values=values)
                assert len(out["variables"]) == int(count), (scene, bodies, fmi, coupling)
    assert "against the full FMU's 365 variables (FMI 2.0) and 366 (FMI 3.0" in " ".join(PAGE.split())
    assert (len(full_names(FMU2)), len(full_names(FMU3))) == (365, 366)


def test_the_pages_model_exchange_command_does_what_it_says(tmp_path):
    command, count = re.search(r"For the h20 drop test: `(fraccontact export [^`]+)` \(it prints the (\d+) "
                               r"variables\)", " ".join(PAGE.split())).groups()
    done = subprocess.run([sys.executable, "-m", *command.split()], cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith(f"pp_me.fmu: {count} of the full FMU's 365 variables")
    assert read_model_description(str(tmp_path / "pp_me.fmu")).modelExchange is not None


def test_the_pages_specialized_build_section_follows_from_its_figures(monkeypatch):
    """The report's figures on the page give its ratio and its decision by
    docs/benchmarks.md's rule, and its edits still apply to the sources (so
    that scripts/report specialized measures it again)."""
    sys.path.insert(0, str(ROOT))
    monkeypatch.chdir(ROOT)  # a source-tree report works in the repository's root (ctest runs pytest elsewhere)
    from reports import specialized
    text = " ".join(PAGE.split(specialized.BEGIN)[1].split(specialized.END)[0].split())
    mine, general, ratio = re.search(r"executes ([\d,]+) instructions per run .*? against the general build's "
                                     r"([\d,]+): ratio ([\d.]+),", text).groups()
    mine, general = (float(x.replace(",", "")) for x in (mine, general))
    assert f"{mine / general:.3f}" == ratio
    fast, slow, clock_ratio, noise = re.search(r"([\d.]+) ms against ([\d.]+) ms of CPU per run, clock ratio "
                                               r"([\d.]+), spread ([\d.]+) %", text).groups()
    assert abs(float(fast) / float(slow) - float(clock_ratio)) <= 1.5e-3  # three printed digits each
    kept = float(clock_ratio) < 1 and specialized.beyond_noise(float(clock_ratio), float(noise) / 100)
    assert ("keep the general binary" in text) == (not kept)
    assert "off 1 by more than twice the larger spread of its row and by over 3 %" in \
        " ".join((ROOT / "docs" / "benchmarks.md").read_text().split())
    for name, old, new in specialized.SPECIALIZED:
        assert (ROOT / name).read_text().count(old) == 1, (name, old)


def test_the_pages_file_limit_is_the_glues():
    header = (ROOT / "fmu_src" / "glue" / "fixed_values.h").read_text()
    limit = re.search(r"#define FV_MAX_BYTES (\d+)", header).group(1)
    assert f"at most {limit} bytes" in PAGE and f"more than {limit} bytes" in PAGE


def test_the_pages_three_commands_do_what_it_says(tmp_path):
    """The shell block run as written (the build's SSP for build/), in a
    fresh folder; what the page says each prints; then its Python block
    prints the figures of its comment."""
    build = FMU2.parent
    block = page_blocks("sh")[0]
    lines = [line for line in block.splitlines() if line.strip()]
    assert len(lines) == 2
    done = []
    for line in lines:
        command = line.replace("build/", f"{build}/").replace("fraccontact ", f"{sys.executable} -m fraccontact ", 1)
        done.append(subprocess.run(command, shell=True, cwd=tmp_path, capture_output=True, text=True, timeout=300))
        assert done[-1].returncode == 0, done[-1].stderr
    fit = json.loads((tmp_path / "fit.json").read_text())
    assert {"k", "c", "F_peak", "eps"} <= fit.keys()
    said = re.search(r"says `(wrote pp_h20.fmu: 13 of the full FMU's 365 variables)`", " ".join(PAGE.split()))
    assert said.group(1) in done[0].stderr
    assert done[1].stdout.startswith("pp_contact.fmu: 14 of the full FMU's 365 variables")
    assert "the 14 variables of `pp_contact.fmu`" in PAGE
    assert (tmp_path / "pp_h20.fmu").is_file() and (tmp_path / "pp_drop.ssp").is_file()
    for python in page_blocks("python")[:2]:  # fmpy, then libcosim
        run = subprocess.run([sys.executable, "-c", python], cwd=tmp_path, capture_output=True, text=True,
                             timeout=300)
        assert run.returncode == 0, run.stderr
        assert run.stdout.strip() == python.split("# ")[-1].strip()


def test_an_ssp_of_an_exported_contact_runs_in_libcosim_and_fmpy_as_the_shipped_one(tmp_path):
    """drop_test.ssp with its contact exported at the values its bindings
    set: run_libcosim reports the scene, law and coupling the exported
    contact fixes (it exposes none of them); libcosim and fmpy give the
    shipped SSP's figures (the full FMU's) to the last bit, at two steps."""
    from fraccontact.ssp import run_fmpy, run_libcosim, with_exported
    ssp = FMU2.parent / "drop_test.ssp"
    contact = tmp_path / "contact.fmu"
    out = fraccontact.export(contact, scene="driven", coupling="jacobi", values=dict(law=2))
    assert not {"scene", "law", "coupling"} & set(out["variables"])
    mine = with_exported(ssp, {"contact": contact}, tmp_path / "exported.ssp")
    for H in (1e-4, 1e-5):
        a, b = run_libcosim(mine, H), run_libcosim(ssp, H)
        assert a["applied"] == b["applied"] == {"scene": 2, "law": 2, "coupling": 2}
        assert a == b and a["F_peak"] > 0
        a, b = run_fmpy(mine, H), run_fmpy(ssp, H)
        assert a.pop("rows").tobytes() == b.pop("rows").tobytes() and a == b


def test_the_headform_ssp_of_exported_contacts_gives_the_shipped_ssps_figures(tmp_path):
    """The page's Python block (the build's SSP for build/), then its
    command: fraccontact scene headform --ssp prints the shipped scene's
    figures; fmpy runs every recorded value of both SSPs bit for bit, and
    libcosim to the same last values; the page's refusal, as it words it."""
    from fmpy.ssp.simulation import simulate_ssp
    from fraccontact.scenes import systems
    from fraccontact.ssp import bound_parameters
    shipped = FMU2.parent / "headform.ssp"
    block = page_blocks("python")[2].replace('"build/', f'"{FMU2.parent}/')
    done = subprocess.run([sys.executable, "-c", block], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    mine = tmp_path / "headform_exported.ssp"
    command = page_blocks("sh")[1].split()
    assert command == ["fraccontact", "scene", "headform", "--ssp", "headform_exported.ssp"]

    def scene(*args):
        done = subprocess.run([sys.executable, "-m", "fraccontact", "scene", "headform", *args], cwd=tmp_path,
                              capture_output=True, text=True, timeout=300)
        return done.returncode, done.stdout, done.stderr
    exported, theirs = scene(*command[3:]), scene()
    assert exported[0] == 0 and exported[1] == theirs[1], exported[2]
    refused = scene(*command[3:], "--gap0", "0.05")
    said = re.search(r"`(hard\.gap0 = 0\.05 is set, but the exported FMU fixes it at 0\.065)`", " ".join(PAGE.split()))
    assert refused[0] == 2 and said.group(1) in refused[2], refused[2]

    def run(ssp):
        return simulate_ssp(str(ssp), stop_time=systems.T_END["headform"], step_size=systems.STEP["headform"],
                            parameter_set=bound_parameters(ssp))
    a, b = run(mine), run(shipped)
    assert a.dtype.names == b.dtype.names
    assert [n for n in a.dtype.names if a[n].tobytes() != b[n].tobytes()] == []
    assert b["skin.F"].max() > 0 and b["hard.F"].max() > 0
    # libcosim: it applies the bindings itself and hands the FMUs its own resource URIs
    mine, theirs = libcosim_last(mine, "headform"), libcosim_last(shipped, "headform")
    assert mine == theirs and theirs["hard.E_diss"] > 0


def libcosim_last(ssp, scene):
    """The last values of the scene's recorded variables, the SSP run by libcosim over the scene's time."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from fraccontact.scenes import systems
    log_output_level(CosimLogLevel.ERROR)
    ex = CosimExecution.from_ssp_file(str(ssp), step_size=round(systems.STEP[scene] * 1e9))
    observer = CosimObserver.create_last_value()
    ex.add_observer(observer)
    ex.simulate_until(target_time=round(systems.T_END[scene] * 1e9))
    out = {}
    for name in systems.RECORDED[scene]:
        component, variable = name.split(".")
        index = ex.slave_index_from_instance_name(component)
        reference = {v.name.decode(): v.reference for v in ex.slave_variables(index)}[variable]
        out[name] = observer.last_real_values(index, [reference])[0]
    return out


def test_an_ssp_binding_that_sets_a_fixed_variable_otherwise_is_refused(tmp_path):
    """drop_test.ssp binds law = 2 on its contact: a contact exported with
    law = 1 is refused, naming the binding and the fixed value; its SSD
    connects F_avg_next, which a Gauss-Seidel export lacks. Nothing written."""
    from fraccontact.ssp import with_exported
    ssp = FMU2.parent / "drop_test.ssp"
    g1 = tmp_path / "g1.fmu"
    fraccontact.export(g1, scene="driven", coupling="jacobi", values=dict(law=1))
    with pytest.raises(ValueError, match=r"contact.law = 2.0 is set, but the exported FMU fixes it at 1"):
        with_exported(ssp, {"contact": g1}, tmp_path / "x.ssp")
    gs = tmp_path / "gs.fmu"
    fraccontact.export(gs, scene="driven", coupling="gauss-seidel", values=dict(law=2))
    with pytest.raises(ValueError, match=r"the SSP connects contact.F_avg_next, which the exported FMU"):
        with_exported(ssp, {"contact": gs}, tmp_path / "x.ssp")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["g1.fmu", "gs.fmu"]


def test_fit_refuses_to_export_a_family_and_writes_nothing(tmp_path):
    """One drop test does not determine the springpot's three constants: no FMU of a family."""
    done = subprocess.run([sys.executable, "-m", "fraccontact", "fit", "--F-peak", "1004", "--eps", "0.59", "--height",
                           "0.020", "--m", "0.7437", "--damper", "2", "--export-fmu", str(tmp_path / "x.fmu")],
                          capture_output=True, text=True)
    assert done.returncode == 2 and "the fit found a family of solutions, not one" in done.stderr, done.stderr
    assert os.listdir(tmp_path) == []


# ---------------------------------------------------------------------------------------------------------------
# The FMI Cross-Check entry.


@pytest.mark.filterwarnings("ignore::DeprecationWarning")  # fmpy 0.3.32's import of scipy.ndimage.filters
def test_the_cross_check_entry_passes_fmpys_validator(tmp_path):
    """export --cross-check DIR for both FMI versions: the layout for both
    platforms, Booleans as 0/1 in the reference; fmpy's validator of vendor
    repositories finds no problem in the FMUs nor in a result of fmpy as the
    importer (run from the entry's _in.csv and _ref.opt, judged against
    _ref.csv), and finds the problem of a reference naming a variable the FMU
    has not."""
    from fmpy.cross_check.validate_vendor_repo import read_csv, validate_repo
    from fmpy.util import read_ref_opt_file
    from fraccontact.cross_check import csv_text, package_version
    for fmi in (2, 3):
        done = subprocess.run([sys.executable, "-m", "fraccontact", "export", str(tmp_path / f"h20_{fmi}.fmu"),
                               "--fmi", str(fmi), "--name", "fraccontact_h20", "--cross-check", str(tmp_path)],
                              capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
    version = package_version()
    entries = {p.relative_to(tmp_path).as_posix() for p in tmp_path.glob("fmus/*/cs/*/fraccontact/*/*")}
    # an entry for each platform the FMU has binaries for: Linux and Windows (MinGW), Linux alone in the
    # sanitizer build
    built = {v: {n.split("/")[1] for n in zipfile.ZipFile(fraccontact.fmu_path(name)).namelist()
                 if n.startswith("binaries/") and n.count("/") == 2}
             for v, name in (("2.0", "fraccontact"), ("3.0", "fraccontact-fmi3"))}
    assert "linux64" in built["2.0"] and "x86_64-linux" in built["3.0"]
    assert entries == {f"fmus/{v}/cs/{p}/fraccontact/{version}/fraccontact_h20" for v in built for p in built[v]}
    entry = tmp_path / f"fmus/2.0/cs/linux64/fraccontact/{version}/fraccontact_h20"
    assert sorted(p.name for p in entry.iterdir()) == ["ReadMe.md", "fraccontact_h20.fmu", "fraccontact_h20_in.csv",
                                                        "fraccontact_h20_ref.csv", "fraccontact_h20_ref.opt"]
    reference = read_csv(entry / "fraccontact_h20_ref.csv")
    assert set(np.unique(reference["contact"])) == {0.0, 1.0}
    opt = read_ref_opt_file(str(entry / "fraccontact_h20_ref.opt"))
    fmpy_version = __import__("fmpy").__version__
    result = tmp_path / f"results/2.0/cs/linux64/fmpy/{fmpy_version}/fraccontact/{version}/fraccontact_h20"
    result.mkdir(parents=True)
    inputs = read_csv(entry / "fraccontact_h20_in.csv")
    out = simulate_fmu(str(entry / "fraccontact_h20.fmu"), start_time=opt["StartTime"], stop_time=opt["StopTime"],
                       output_interval=opt["StepSize"], input=inputs, output=list(reference.dtype.names[1:]))
    (result / "fraccontact_h20_out.csv").write_text(csv_text(out.dtype.names, [out[n] for n in out.dtype.names]))
    (result / "passed").write_text("")
    fmus, results, problems = validate_repo(str(tmp_path))
    assert (fmus, results, problems) == (len(entries), 1, [])
    assert "python -m fmpy.cross_check.validate_vendor_repo DIR" in PAGE and "--cross-check DIR`" in PAGE
    bad = entry / "fraccontact_h20_ref.csv"
    bad.write_text(bad.read_text().replace('"eps"', '"no_such_variable"', 1))
    assert any("no_such_variable" in p for p in validate_repo(str(tmp_path))[2])
