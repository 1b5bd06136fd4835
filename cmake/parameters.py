"""The files that model/parameters.def generates outside C: the
variables and model structure of both modelDescription.xml files and the
table of docs/variables.md. The parts of those files that no row of the
table decides (the GUID, the capabilities, the units, the prose) stay as
written; only the generated sections are replaced.

  parameters.py ROOT OUT        write the generated files into the folder OUT
  parameters.py ROOT OUT --check  ... and fail naming each file under ROOT that differs
  parameters.py ROOT ROOT       regenerate the files in the source tree ROOT

The build runs it with --check (CMakeLists.txt, target parameter_files)."""

import argparse
import html
import pathlib
import re
import sys

TABLE = pathlib.Path("model/parameters.def")
FMI2, FMI3, PAGE = pathlib.Path("modelDescription.xml"), pathlib.Path("fmi3/modelDescription.xml"), \
    pathlib.Path("docs/variables.md")
COLUMNS = ("name", "type", "unit", "default", "min", "max", "vr", "index", "variability", "words", "rule",
           "description")
KINDS = ("input", "parameter", "stop", "option", "output", "derivative", "state", "indicator")
# Model Exchange's kinds: der(name) of an output, a local state of MODES elements, an event indicator.
EXCHANGE_KINDS = ("derivative", "state", "indicator")
MODES = int(re.search(r"#define CONTACT_MAX_MODES (\d+)", pathlib.Path(__file__).parent.joinpath(
    "..", "model", "contact.h").read_text()).group(1))
DERIVATIVE_OFFSET = 1000  # a STATE row's der(name[i]) is this many value references on (fmu_model.h)
PLACES = ("model", "fmu", "library", "solver", "package")
# The initial unknowns that depend on a variable at the start: x = -gap0, v_striker = v - v2.
INITIAL_DEPENDENCIES = {"x": ("gap0",), "v_striker": ("v", "v2")}
# Model Exchange's derivatives that depend on a variable at the start: der(x) = v - v2, der(v_striker) = g.
EXCHANGE_DEPENDENCIES = {"der(x)": ("v", "v2"), "der(v_striker)": ("g",)}
# What each state's rate depends on in continuous-time and event mode (model/rates.c), with the
# FMI dependenciesKind of each: der(x) = v_striker in the drop test and the input rate v - v2 in the
# driven scene (factors 1, 0 and +-1, 0 that the fixed scene decides); der(v_striker) = g - F/m and the
# dashpot's x2' = F/c with the force F of x1 = x - x2; the springpot's x2' = (F/c_alpha - sum_j a_j
# phi_j)/eta; der(E_diss) = F x2'; der(phi[i]) = x2' - b_i phi_i (a_j, b_i, eta: the kernel of fixed
# parameters). A STATE row's name stands for all its elements, as known and as state.
RATE_DEPENDENCIES = {
    "x": {"v": "fixed", "v_striker": "fixed", "v2": "fixed"},
    "v_striker": {"x": "dependent", "x2": "dependent"},
    "x2": {"x": "dependent", "x2": "dependent", "phi": "fixed"},
    "E_diss": {"x": "dependent", "x2": "dependent", "phi": "dependent"},
    "phi": {"x": "dependent", "x2": "dependent", "phi": "fixed"},
}
# What each output depends on among the knowns of continuous-time and event mode, the inputs and
# the states (fmu_model.c's real_output on model/rates.c's contact_me_set_states): F = K x1^n and
# semi_integral, a multiple of F, of x1 = x - x2 (0 out of contact, where x1 is 0 too); the states
# x, x2, v_striker and E_diss are outputs of their own values (the driven scene's v_striker not: a
# factor 1 or 0 that the scene fixes). F_avg and F_avg_next change only in
# the co-simulation's steps, eps and contact at events, F_peak at events and completed integrator
# steps. The driven scene's v_striker is v - v2 in Model Exchange, but the one ModelStructure also
# makes co-simulation's promise of no direct feedthrough from the inputs (docs/model_exchange.md).
OUTPUT_DEPENDENCIES = {
    "F": {"x": "dependent", "x2": "dependent"},
    "x": {"x": "constant"},
    "x1": {"x": "dependent", "x2": "dependent"},
    "x2": {"x2": "constant"},
    "v_striker": {"v_striker": "fixed"},
    "E_diss": {"E_diss": "constant"},
    "semi_integral": {"x": "dependent", "x2": "dependent"},
}
ARGUMENT = re.compile(r'\s*((?:"[^"\\]*"\s*)+|[^,"]*?)\s*(,|$)')


def arguments(text):
    """The macro arguments of one row: C string literals (adjacent ones
    joined) as their text, anything else as written."""
    values, at = [], 0
    while at <= len(text):
        m = ARGUMENT.match(text, at)
        if not m:
            raise ValueError(f"cannot read the arguments {text!r} from position {at}")
        token = m.group(1)
        values.append("".join(re.findall(r'"([^"]*)"', token)) if token.startswith('"') else token)
        at = m.end() if m.group(2) else len(text) + 1
    return values


def read_table(path):
    """The rows of parameters.def as dicts, in its order, with kind and where."""
    text = re.sub(r"/\*.*?\*/", "", pathlib.Path(path).read_text(), flags=re.S)
    rows = []
    for line in text.splitlines():
        m = re.match(r"([A-Z_]+)\((.*)\)$", line.strip())
        if not m or line.startswith("#"):
            continue
        kind, *where = m.group(1).lower().split("_")
        values = arguments(m.group(2))
        if kind not in KINDS or not where or not set(where) <= set(PLACES) or len(values) != len(COLUMNS):
            raise ValueError(f"{path}: the row {line.strip()[:60]!r} is not KIND_WHERE(...) with {len(COLUMNS)} "
                             f"arguments ({', '.join(COLUMNS)})")
        rows.append(dict(zip(COLUMNS, values), kind=kind, where=where))
    return rows


def fmu_rows(rows):
    """The FMU's variables in the order of modelDescription.xml, but Model Exchange's."""
    return sorted((r for r in rows if "fmu" in r["where"] and r["kind"] not in EXCHANGE_KINDS),
                  key=lambda r: int(r["index"]))


def exchange_variables(rows):
    """Model Exchange's variables as dicts (name, vr, index, unit, description, start, and
    derivative: the name of the state whose derivative it is, or None; indicator), in index
    order: a DERIVATIVE row's der(name), a STATE row's name[1..MODES] and then der(name[i]),
    an INDICATOR row's name."""
    found = []
    for r in rows:
        if r["kind"] == "indicator":
            found.append(dict(name=r["name"], vr=r["vr"], index=r["index"], unit=r["unit"],
                              description=r["description"], start="", derivative=None, indicator=True))
        if r["kind"] == "derivative":
            found.append(dict(name=f"der({r['name']})", vr=r["vr"], index=r["index"], unit=r["unit"],
                              description=r["description"], start="", derivative=r["name"]))
        elif r["kind"] == "state":
            for i in range(MODES):
                found.append(dict(name=f"{r['name']}[{i + 1}]", vr=str(int(r["vr"]) + i),
                                  index=str(int(r["index"]) + i), unit=r["unit"], start=r["default"],
                                  description=r["description"] if i == 0 else
                                  f"mode {i + 1} of {r['name']} (see {r['name']}[1])", derivative=None))
            for i in range(MODES):
                found.append(dict(name=f"der({r['name']}[{i + 1}])", vr=str(int(r["vr"]) + DERIVATIVE_OFFSET + i),
                                  index=str(int(r["index"]) + MODES + i), unit=f"{r['unit']}/s",
                                  description=f"the rate of {r['name']}[{i + 1}]", start="",
                                  derivative=f"{r['name']}[{i + 1}]"))
    return sorted(found, key=lambda v: int(v["index"]))


def state_index(variables, fmu, name):
    """The FMI 2.0 index of the state `name`: an output's, or a STATE row's element."""
    by_name = {r["name"]: r["index"] for r in fmu}
    by_name.update({v["name"]: v["index"] for v in variables})
    return by_name[name]


def fmi2_exchange_variable(v, fmu, variables):
    if v.get("indicator"):
        real, initial = f'<Real unit="{v["unit"]}"/>', ""
    elif v["derivative"]:
        real = f'<Real unit="{v["unit"]}" derivative="{state_index(variables, fmu, v["derivative"])}"/>'
        initial = ""
    else:
        real = f'<Real unit="{v["unit"]}" start="{v["start"]}"/>'
        initial = ' initial="exact"'
    return (f'    <!-- {v["index"]} --><ScalarVariable name="{v["name"]}" valueReference="{v["vr"]}" '
            f'causality="local" variability="continuous"{initial}\n'
            f'      description="{html.escape(v["description"], quote=False)}">\n'
            f'      {real}</ScalarVariable>')


def attributes(row, names):
    return "".join(f' {name}="{row[key]}"' for name, key in names if row[key])


def fmi2_variable(row):
    type_ = row["type"]
    value = ("unit", "unit"), ("start", "default"), ("min", "min"), ("max", "max")
    if type_ != "Real":
        value = value[1:]
    return (f'    <!-- {row["index"]} --><ScalarVariable name="{row["name"]}" valueReference="{row["vr"]}" '
            f'causality="{row["kind"]}" variability="{row["variability"]}"\n'
            f'      description="{html.escape(row["description"], quote=False)}">\n'
            f'      <{type_}{attributes(row, value)}/></ScalarVariable>')


def initial_comment(by_name, key):
    """Which initial unknowns depend on what, by their FMI 2.0 indices or FMI 3.0 value references."""
    parts = [f"{name} = {formula} ({', '.join(by_name[d][key] for d in INITIAL_DEPENDENCIES[name])})"
             for name, formula in (("x", "-gap0"), ("v_striker", "v - v2"))]
    return f"at the start: {', '.join(parts)}; the rest starts at 0"


def dependencies(row, by_name, key):
    return " ".join(by_name[d][key] for d in INITIAL_DEPENDENCIES.get(row["name"], ()))


def exchange_dependencies(variable, by_name, key):
    return " ".join(by_name[d][key] for d in EXCHANGE_DEPENDENCIES.get(variable["name"], ()))


def known_dependencies(table, fmu, variables, key):
    """The dependencies and dependenciesKind attributes of the knowns `table` (name: kind, as in
    RATE_DEPENDENCIES) as FMI 2.0 indices or FMI 3.0 value references (key), in ascending order;
    dependencies="" alone for none."""
    known = {r["name"]: [r[key]] for r in fmu}
    for v in variables:
        if not v["derivative"] and not v.get("indicator"):
            known.setdefault(re.sub(r"\[\d+\]$", "", v["name"]), []).append(v[key])
    pairs = sorted((int(ref), kind) for name, kind in table.items() for ref in known[name])
    if not pairs:
        return ' dependencies=""'
    return (f' dependencies="{" ".join(str(ref) for ref, _ in pairs)}"'
            f' dependenciesKind="{" ".join(kind for _, kind in pairs)}"')


def rate_dependencies(variable, fmu, variables, key):
    """The dependencies of the derivative `variable`: its state's RATE_DEPENDENCIES."""
    return known_dependencies(RATE_DEPENDENCIES[re.sub(r"\[\d+\]$", "", variable["derivative"])], fmu, variables,
                              key)


def output_dependencies(row, fmu, variables, key):
    """The dependencies of the output `row`: its OUTPUT_DEPENDENCIES."""
    return known_dependencies(OUTPUT_DEPENDENCIES.get(row["name"], {}), fmu, variables, key)


def fmi2_section(rows):
    """From <ModelVariables> to </ModelStructure> of modelDescription.xml."""
    fmu = fmu_rows(rows)
    by_name = {r["name"]: r for r in fmu}
    outputs = [r for r in fmu if r["kind"] == "output"]
    exchange = exchange_variables(rows)
    derivatives = [v for v in exchange if v["derivative"]]
    lines = ["  <ModelVariables>"] + [fmi2_variable(r) for r in fmu]
    lines += [fmi2_exchange_variable(v, fmu, exchange) for v in exchange]
    lines += ["  </ModelVariables>", "", "  <ModelStructure>", "    <Outputs>",
              "      <!-- no direct feedthrough from the inputs; in Model Exchange some outputs depend on "
              "the states (docs/model_exchange.md) -->"]
    lines += [f'      <Unknown index="{r["index"]}"{output_dependencies(r, fmu, exchange, "index")}/>' for r in outputs]
    lines += ["    </Outputs>"]
    if derivatives:
        lines += ["    <Derivatives>", "      <!-- Model Exchange's states' rates (docs/model_exchange.md); at the "
                  "start der(x) = v - v2 (1, 36), der(v_striker) = g (11), the rest 0 -->"]
        lines += [f'      <Unknown index="{v["index"]}"{rate_dependencies(v, fmu, exchange, "index")}/>'
                  for v in derivatives] + ["    </Derivatives>"]
    lines += ["    <InitialUnknowns>", f"      <!-- {initial_comment(by_name, 'index')} -->"]
    lines += [f'      <Unknown index="{r["index"]}" dependencies="{dependencies(r, by_name, "index")}"/>'
              for r in outputs]
    lines += [f'      <Unknown index="{v["index"]}" dependencies="{exchange_dependencies(v, by_name, "index")}"/>'
              for v in derivatives]
    return "\n".join(lines + ["    </InitialUnknowns>", "  </ModelStructure>"])


FMI3_TYPES = {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean"}


def fmi3_variable(row):
    value = ("unit", "unit"), ("start", "default"), ("min", "min"), ("max", "max")
    if row["type"] != "Real":
        value = value[1:]
    return (f'    <{FMI3_TYPES[row["type"]]} name="{row["name"]}" valueReference="{row["vr"]}" '
            f'causality="{row["kind"]}" variability="{row["variability"]}"{attributes(row, value)}\n'
            f'      description="{html.escape(row["description"], quote=False)}"/>')


def fmi3_exchange_variable(v, fmu, variables):
    vr = {r["name"]: r["vr"] for r in fmu}
    vr.update({w["name"]: w["vr"] for w in variables})
    extra = f' derivative="{vr[v["derivative"]]}"' if v["derivative"] else ""
    if not v["derivative"] and not v.get("indicator"):
        extra = f' initial="exact" start="{v["start"]}"'
    return (f'    <Float64 name="{v["name"]}" valueReference="{v["vr"]}" causality="local" variability="continuous" '
            f'unit="{v["unit"]}"{extra}\n      description="{html.escape(v["description"], quote=False)}"/>')


def fmi3_section(rows):
    """From <ModelVariables> to </ModelStructure> of fmi3/modelDescription.xml."""
    fmu = fmu_rows(rows)
    by_name = {r["name"]: r for r in fmu}
    outputs = [r for r in fmu if r["kind"] == "output"]
    exchange = exchange_variables(rows)
    derivatives = [v for v in exchange if v["derivative"]]
    lines = ["  <ModelVariables>",
             '    <Float64 name="time" valueReference="0" causality="independent" variability="continuous" unit="s"',
             '      description="simulation time"/>']
    lines += [fmi3_variable(r) for r in fmu] + [fmi3_exchange_variable(v, fmu, exchange) for v in exchange]
    lines += ["  </ModelVariables>", "", "  <ModelStructure>",
              "    <!-- no direct feedthrough from the inputs; in Model Exchange some outputs",
              "         depend on the states (docs/model_exchange.md) -->"]
    lines += [f'    <Output valueReference="{r["vr"]}"{output_dependencies(r, fmu, exchange, "vr")}/>' for r in outputs]
    if derivatives:
        lines += ["    <!-- Model Exchange's states' rates (docs/model_exchange.md) -->"]
        lines += [f'    <ContinuousStateDerivative valueReference="{v["vr"]}"'
                  f'{rate_dependencies(v, fmu, exchange, "vr")}/>' for v in derivatives]
    lines += [f"    <!-- {initial_comment(by_name, 'vr')} -->"]
    lines += [f'    <InitialUnknown valueReference="{r["vr"]}" dependencies="{dependencies(r, by_name, "vr")}"/>'
              for r in outputs]
    if derivatives:
        lines += ["    <!-- at the start der(x) = v - v2 (1, 36), der(v_striker) = g (11), the rest 0 -->"]
    lines += [f'    <InitialUnknown valueReference="{v["vr"]}" '
              f'dependencies="{exchange_dependencies(v, by_name, "vr")}"/>' for v in derivatives]
    lines += [f'    <EventIndicator valueReference="{v["vr"]}"/>' for v in exchange if v.get("indicator")]
    return "\n".join(lines + ["  </ModelStructure>"])


def replaced(text, begin, end, section, what):
    """text with the lines from begin to end (both included) replaced by section."""
    start, stop = text.find(begin), text.find(end)
    if start < 0 or stop < start:
        raise ValueError(f"{what} has no {begin.strip()} ... {end.strip()} section")
    return text[:start] + section + text[stop + len(end):]


def cell(row, column):
    if column == "name":
        return f"`{row['name']}`"
    if column == "where":
        return " ".join(row["where"])
    return row[column].replace("|", "\\|")


PAGE_COLUMNS = ("name", "kind", "type", "unit", "default", "rule", "vr", "where", "description")


def page_section(rows):
    """The markdown table of docs/variables.md, between its markers."""
    lines = ["<!-- variables:begin -->", "", "| " + " | ".join(PAGE_COLUMNS) + " |",
             "|" + "---|" * len(PAGE_COLUMNS)]
    lines += ["| " + " | ".join(cell(r, c) for c in PAGE_COLUMNS) + " |" for r in rows]
    return "\n".join(lines + ["", "<!-- variables:end -->"])


def generated(root):
    """{relative path: text} of every file the table generates, from the files under root."""
    rows = read_table(root / TABLE)
    return {FMI2: replaced((root / FMI2).read_text(), "  <ModelVariables>", "  </ModelStructure>",
                           fmi2_section(rows), FMI2),
            FMI3: replaced((root / FMI3).read_text(), "  <ModelVariables>", "  </ModelStructure>",
                           fmi3_section(rows), FMI3),
            PAGE: replaced((root / PAGE).read_text(), "<!-- variables:begin -->", "<!-- variables:end -->",
                           page_section(rows), PAGE)}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("root", type=pathlib.Path, help="the source tree")
    p.add_argument("out", type=pathlib.Path, help="where the generated files go")
    p.add_argument("--check", action="store_true", help="fail when a file under ROOT differs from its generation")
    args = p.parse_args(argv)
    stale = []
    for path, text in generated(args.root).items():
        target = args.out / path
        target.parent.mkdir(parents=True, exist_ok=True)
        if not target.exists() or target.read_text() != text:
            target.write_text(text)
        if args.check and (args.root / path).read_text() != text:
            stale.append(path)
    for path in stale:
        print(f"{args.root / path} is not what {TABLE} generates ({args.out / path}): run "
              f"'cmake --build <build> --target update-parameter-files'", file=sys.stderr)
    return 1 if stale else 0


if __name__ == "__main__":
    sys.exit(main())
