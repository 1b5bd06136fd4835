"""model/parameters.def is the one table of the model's variables.
The C preprocessor expands it into the structs, the library's table and the
FMU's variables; cmake/parameters.py reads it on its own to render both
modelDescription.xml files and docs/variables.md. The two readings are
compared here through what the built library, solver and FMU report, and the
checked-in files against their generation."""

import importlib.util
import json
import os
import pathlib
import re
import shutil
import subprocess

import pytest

import fraccontact

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOLVE = os.environ.get("FRACCONTACT_SOLVE", str(ROOT / "build" / "fraccontact-solve"))
_spec = importlib.util.spec_from_file_location("parameters", ROOT / "cmake" / "parameters.py")
generator = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(generator)
TABLE = generator.read_table(ROOT / generator.TABLE)
GENERATED = (generator.FMI2, generator.FMI3, generator.PAGE)


def rows(where):
    """The rows that apply to where (model, fmu, ...), or of that kind (output, ...)."""
    return [r for r in TABLE if where in r["where"] or where == r["kind"]]


def test_the_checked_in_files_are_their_generation(tmp_path):
    assert generator.main([str(ROOT), str(tmp_path), "--check"]) == 0
    for path in GENERATED:
        assert (tmp_path / path).read_text() == (ROOT / path).read_text(), path


def test_a_stale_file_is_named(tmp_path, capsys):
    """A description changed in the table alone: every file that shows it is named."""
    for path in (generator.TABLE,) + GENERATED:
        (tmp_path / path).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(ROOT / path, tmp_path / path)
    table = tmp_path / generator.TABLE
    table.write_text(table.read_text().replace('"striker tip radius', '"the striker\'s tip radius'))
    assert generator.main([str(tmp_path), str(tmp_path / "out"), "--check"]) == 1
    named = capsys.readouterr().err
    assert all(str(tmp_path / path) in named for path in GENERATED), named
    assert 'name="R"' in (tmp_path / "out" / generator.FMI2).read_text()
    assert "the striker's tip radius" in (tmp_path / "out" / generator.FMI3).read_text()


def test_a_row_of_the_wrong_shape_is_refused(tmp_path):
    table = tmp_path / "parameters.def"
    table.write_text('PARAMETER_MODEL_FMU(R, Real, "m", 1)\n')
    with pytest.raises(ValueError, match="with 12 arguments"):
        generator.read_table(table)


def test_the_librarys_table():
    """fc_parameter_at, through the package: the library's rows in their
    order, with type, unit, default, words and description."""
    kinds = {"Real": "real", "Integer": "integer"}
    found = [(p["name"], p["kind"], p["unit"], p["default"], p["help"]) for p in fraccontact.parameters()]
    expected = [(r["name"], kinds[r["type"]], r["unit"], float(r["default"]), r["description"])
                for r in rows("library")]
    assert found == expected
    assert fraccontact.model.WORDS == {r["name"]: {w: i for i, w in enumerate(r["words"].split(), 1)}
                                       for r in rows("library") if r["words"]}


def test_the_fmus_variables(slave, model_description):
    """The built FMU's variables, by value reference and type, hold the
    table's start values (read through the C binding's variable list), and
    its modelDescription.xml declares them as the table does."""
    exchange = {v["name"]: v for v in generator.exchange_variables(TABLE)}
    declared = {v.name: v for v in model_description.modelVariables if v.name not in exchange}
    assert sorted(declared) == sorted(r["name"] for r in generator.fmu_rows(TABLE))
    s = slave(start=False)
    s.enter()
    get = {"Real": s.fmu.getReal, "Integer": s.fmu.getInteger, "Boolean": s.fmu.getBoolean}
    for r in generator.fmu_rows(TABLE):
        v = declared[r["name"]]
        assert (v.valueReference, v.type, v.causality, v.variability) == (
            int(r["vr"]), r["type"], r["kind"], r["variability"]), r["name"]
        if r["kind"] != "output":
            assert get[r["type"]]([int(r["vr"])]) == [float(r["default"])], r["name"]
    s.fmu.exitInitializationMode()
    for r in rows("output"):
        get[r["type"]]([int(r["vr"])])  # an FMI error if the binding gave the output another type
    # Model Exchange's derivatives and modes: declared as the table's rows
    # say, and read through the binding (at the start: the modes at rest,
    # the derivatives x' = v and the rest 0, out of contact the peak's
    # event indicator -1)
    start = {"der(x)": 0.626418, "event_x1_rate": -1.0}
    for v in model_description.modelVariables:
        if v.name in exchange:
            assert (v.valueReference, v.causality, v.variability) == (int(exchange[v.name]["vr"]), "local",
                                                                      "continuous"), v.name
            assert s.fmu.getReal([v.valueReference]) == [start.get(v.name, 0.0)], v.name


def test_the_solvers_options():
    """An option per library row and per solver row (--dt-max for dt_max),
    its help stating the table's unit and default."""
    listed = subprocess.run([SOLVE, "--list-options"], capture_output=True, text=True, timeout=60, check=True)
    options = {o["option"]: o["help"] for o in json.loads(listed.stdout)}
    for r in rows("library") + rows("solver"):
        help_ = options["--" + r["name"].replace("_", "-")]
        assert f"[{r['unit']}]" in help_, help_
        if r["default"]:
            assert float(re.search(r"\(default ([^)]+)\)", help_).group(1)) == float(r["default"]), help_


def test_the_packages_names():
    """fraccontact.impact takes every library and package row by name, and
    names exactly those when it refuses another."""
    for r in rows("library") + rows("package"):
        value = float(r["default"]) if r["default"] else 0.02
        fraccontact.impact(**{r["name"]: int(value) if r["type"] == "Integer" else value})
    with pytest.raises(TypeError, match="no_such_name") as refused:
        fraccontact.impact(no_such_name=1.0)
    known = re.search(r"the parameters are (.*)", str(refused.value)).group(1).replace(" and ", ", ").split(", ")
    assert sorted(known) == sorted(r["name"] for r in rows("library") + rows("package"))
