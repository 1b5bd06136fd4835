"""docs/parameters.tsv is the one table of the model's parameters, inputs and
outputs (issue 24, item 4). Every place that lists them is checked against
it here, and each failure names what is missing or different: the model's
struct contact_params (fmu_src/model/contact.h), the library's fc_params
(solver/fraccontact.h) and its table (fraccontact.parameters(), read from
the C library), the solver's options (fraccontact-solve --list-options and
--help), the package's keywords and Run fields, the FMU binding's variables
(fmu_src/binding/fmu_model.[ch]) and both modelDescription.xml files; and
docs/variables.md shows the table as rendered from it."""

import json
import os
import pathlib
import re
import subprocess
import xml.etree.ElementTree as ET

import pytest

import fraccontact
from reports import variables

ROOT = pathlib.Path(__file__).resolve().parent.parent
TABLE = variables.read_table(ROOT / "docs" / "parameters.tsv")
SOLVE = os.environ.get("FRACCONTACT_SOLVE", str(ROOT / "build" / "fraccontact-solve"))
C_TYPES = {"double": "Real", "int": "Integer"}


def rows(where):
    return {r["name"]: r for r in TABLE if where in r["where"].split()}


def compare(found, expected, what):
    """found and expected as {name: value}: the names missing on either side and the values that differ."""
    problems = [f"{what}: {n} missing (the table has it)" for n in expected if n not in found]
    problems += [f"{what}: {n} is not in docs/parameters.tsv" for n in found if n not in expected]
    problems += [f"{what}: {n} is {found[n]!r}, the table says {expected[n]!r}"
                 for n in expected if n in found and found[n] != expected[n]]
    return problems


def struct_fields(header, struct):
    """{field: C type} of a typedef struct { ... } struct; in a C header."""
    text = re.sub(r"/\*.*?\*/", "", (ROOT / header).read_text(), flags=re.S)
    body = re.search(r"typedef struct \{([^{}]*)\}\s*" + struct + ";", text).group(1)
    fields = {}
    for decl in body.split(";"):
        m = re.match(r"\s*(double|int|int64_t)\s+(.*)", decl, flags=re.S)
        if m:
            for name in m.group(2).split(","):
                fields[name.strip()] = m.group(1)
    return fields


def number(text):
    return float(text) if text else None


def test_the_table_is_well_formed():
    names = [r["name"] for r in TABLE]
    assert len(names) == len(set(names)), "a name twice"
    for r in TABLE:
        assert r["kind"] in ("input", "parameter", "output", "stop", "option"), r
        assert r["type"] in ("Real", "Integer", "Boolean"), r
        assert r["description"], f"{r['name']}: no description"
        assert r["where"].split() and set(r["where"].split()) <= {"model", "fmu", "library", "solver", "package"}, r
        if r["kind"] != "output" and r["name"] != "height":
            assert r["default"] and r["rule"], f"{r['name']}: a parameter needs its default and its rule"


def test_the_models_struct():
    """contact_params: a field per model parameter, of the table's type."""
    found = {n: C_TYPES[t] for n, t in struct_fields("fmu_src/model/contact.h", "contact_params").items()}
    problems = compare(found, {n: r["type"] for n, r in rows("model").items()}, "contact_params")
    assert not problems, "\n".join(problems)


def test_the_librarys_struct():
    """fc_params: the library's parameters and stops, of the table's type."""
    found = {n: C_TYPES[t] for n, t in struct_fields("solver/fraccontact.h", "fc_params").items()}
    problems = compare(found, {n: r["type"] for n, r in rows("library").items()}, "fc_params")
    assert not problems, "\n".join(problems)


def test_the_librarys_table():
    """fc_parameter_at, through the package: name, kind, unit and default."""
    kinds = {"real": "Real", "integer": "Integer"}
    found = {p["name"]: (kinds[p["kind"]], p["unit"], float(p["default"])) for p in fraccontact.parameters()}
    expected = {n: (r["type"], r["unit"], float(r["default"])) for n, r in rows("library").items()}
    problems = compare(found, expected, "the library's table")
    assert not problems, "\n".join(problems)


def solver_options():
    run = subprocess.run([SOLVE, "--list-options"], capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stderr
    return {o["option"]: o for o in json.loads(run.stdout)}


# The solver's own options: how it runs and writes, not the model.
PROGRAM_OPTIONS = {"--output-interval", "--csv", "--json", "--reference", "--rtol", "--repeat", "--quiet"}


def test_the_solvers_options():
    """An option per library parameter and per solver option of the table
    (--dt-max for dt_max), its help stating the table's unit and default."""
    options = {o: v for o, v in solver_options().items() if o not in PROGRAM_OPTIONS}
    expected = {"--" + n.replace("_", "-"): r for n, r in {**rows("library"), **rows("solver")}.items()}
    problems = compare({o: o for o in options}, {o: o for o in expected}, "fraccontact-solve's options")
    for option, r in expected.items():
        if option not in options:
            continue
        help_ = options[option]["help"]
        if f"[{r['unit']}]" not in help_:
            problems.append(f"fraccontact-solve {option}: its help does not give the unit [{r['unit']}]: {help_!r}")
        default = re.search(r"\(default ([^)]+)\)", help_)
        if r["default"] and (not default or float(default.group(1)) != float(r["default"])):
            problems.append(f"fraccontact-solve {option}: default {default and default.group(1)}, the table says "
                            f"{r['default']}")
    assert not problems, "\n".join(problems)


def test_the_packages_names():
    """fraccontact.impact takes every library parameter and the package's
    options by name (a name it does not know raises TypeError listing the
    names it knows: the table's), and a Run's figures are the FMU outputs' names."""
    for name, r in {**rows("library"), **rows("package")}.items():
        value = float(r["default"]) if r["default"] else 0.02
        fraccontact.impact(**{name: int(value) if r["type"] == "Integer" else value})
    with pytest.raises(TypeError, match="no_such_name") as refused:
        fraccontact.impact(no_such_name=1.0)
    known = re.search(r"the parameters are (.*)", str(refused.value)).group(1).replace(" and ", ", ").split(", ")
    problems = compare(dict.fromkeys(known), dict.fromkeys({**rows("library"), **rows("package")}), "impact()'s names")
    assert not problems, "\n".join(problems)
    outputs = rows("fmu")
    run = fraccontact.impact()
    # per impact: the FMU's outputs at the separation; x2_end, t_onset,
    # v_onset, t_contact are the impact's own figures (docs/model.md §9).
    figures = {"t_onset", "v_onset", "t_contact", "x2_end"}
    unknown = [k for k in ("F_peak", "eps", "E_diss") if k not in outputs]
    # end: the FMU's outputs where the run stopped (t the time; v the striker's
    # velocity, which the FMU calls v_striker).
    unknown += [k for k in run.end.keys() if k not in outputs and k not in figures | {"t", "v"}]
    assert not unknown, f"Run fields that are no FMU output of the table: {unknown}"


def binding_variables():
    """{name: (vr, type, causality)} of fmu_model.c's variable table."""
    vrs = {m.group(1): m.group(2) for m in re.finditer(r"VR_(\w+) = (\d+)", (ROOT / "fmu_src/binding/fmu_model.h").read_text())}
    types = {"VAR_REAL": "Real", "VAR_INTEGER": "Integer", "VAR_BOOLEAN": "Boolean"}
    found = {}
    for m in re.finditer(r'\{VR_(\w+), "(\w+)", (VAR_\w+), VAR_(\w+),', (ROOT / "fmu_src/binding/fmu_model.c").read_text()):
        assert m.group(1) == m.group(2), m.group(0)
        found[m.group(2)] = (vrs[m.group(1)], types[m.group(3)], m.group(4).lower())
    return found


def test_the_fmu_binding():
    expected = {n: (r["vr"], r["type"], r["kind"]) for n, r in rows("fmu").items()}
    problems = compare(binding_variables(), expected, "fmu_src/binding/fmu_model.c")
    assert not problems, "\n".join(problems)


def fmi2_variables():
    root = ET.parse(ROOT / "modelDescription.xml").getroot()
    found = {}
    for v in root.findall("ModelVariables/ScalarVariable"):
        t = v[0]
        found[v.get("name")] = dict(vr=v.get("valueReference"), kind=v.get("causality"), type=t.tag,
                                    unit=t.get("unit", "1" if t.tag == "Integer" else ""), default=number(t.get("start")),
                                    description=v.get("description"), min=t.get("min"), max=t.get("max"))
    return found


def fmi3_variables():
    root = ET.parse(ROOT / "fmi3" / "modelDescription.xml").getroot()
    types = {"Float64": "Real", "Int32": "Integer", "Boolean": "Boolean"}
    found = {}
    for v in root.find("ModelVariables"):
        if v.get("causality") == "independent":
            continue
        found[v.get("name")] = dict(vr=v.get("valueReference"), kind=v.get("causality"), type=types[v.tag],
                                    unit=v.get("unit", "1" if v.tag == "Int32" else ""), default=number(v.get("start")),
                                    description=v.get("description"), min=v.get("min"), max=v.get("max"))
    return found


@pytest.mark.parametrize("which", ["modelDescription.xml", "fmi3/modelDescription.xml"])
def test_the_model_descriptions(which):
    """Name, value reference, causality, type, unit, start value and
    description as the table has them; min and max are numbers the rule states."""
    found = fmi2_variables() if which == "modelDescription.xml" else fmi3_variables()
    expected = {n: dict(vr=r["vr"], kind=r["kind"], type=r["type"], unit=r["unit"], default=number(r["default"]),
                        description=r["description"]) for n, r in rows("fmu").items()}
    problems = []
    for name, row in expected.items():
        if name not in found:
            problems.append(f"{which}: {name} missing (the table has it)")
            continue
        for key, value in row.items():
            if found[name][key] != value:
                problems.append(f"{which}: {name}'s {key} is {found[name][key]!r}, the table says {value!r}")
        stated = {float(x) for x in re.findall(r"-?\d+(?:\.\d+)?(?:e-?\d+)?", rows("fmu")[name]["rule"])}
        for bound in ("min", "max"):
            if found[name][bound] is not None and float(found[name][bound]) not in stated:
                problems.append(f"{which}: {name}'s {bound} {found[name][bound]} is not in the table's rule "
                                f"{rows('fmu')[name]['rule']!r}")
    problems += [f"{which}: {n} is not in docs/parameters.tsv" for n in found if n not in expected]
    assert not problems, "\n".join(problems)


def test_the_variables_page_is_the_tables_rendering():
    """docs/variables.md's table is what `scripts/report variables` renders from the table."""
    page = (ROOT / "docs" / "variables.md").read_text()
    assert page == variables.rendered_page(page, TABLE), "docs/variables.md is stale: run scripts/report variables"


def test_a_difference_is_named():
    """The comparison itself: a changed unit and a missing name are reported by name."""
    problems = compare({"k": "N/m", "c": "N.s/m"}, {"k": "N/m1.5", "m": "kg", "c": "N.s/m"}, "x")
    assert problems == ["x: m missing (the table has it)", "x: k is 'N/m', the table says 'N/m1.5'"]
