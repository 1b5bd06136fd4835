"""The contact of one scene as its own FMU: only the variables the scene sets
or reads, the rest fixed at given values (docs/export.md).

  fraccontact export pp.fmu --scene drop --k 3.3e8 --c 6080
  fraccontact export pp.fmu --fit fit.json --material "PP, h20 drop test" --keep c
  fraccontact export panel.fmu --scene driven --bodies 2 --coupling jacobi --fmi 3 --damper springpot
  fraccontact export pp_me.fmu --coupling model-exchange --law hertz

The exported FMU is the shipped FMU (the same Linux and Windows binaries: no
compiler is needed) with its modelDescription.xml filtered and a file of
fixed values in its resources, which the binary reads at instantiation and
sets through the same setters and checks as an importer's values: it gives
the full FMU's results at the same values to the last bit. What it exposes:
the inputs the scene sets (v and m; with --bodies 2 the second body's; in the
driven scene the accelerations of the bodies' other forces), every output
but the other coupling's averaged force, and the variables named by --keep,
whose start values are the values given (--coupling model-exchange: an FMU of
Model Exchange alone, with its states, derivatives and event indicators, and
neither averaged force). Every other parameter and input is
fixed. Values: --NAME VALUE for any parameter or input of the FMU (the
names of docs/variables.md, '-' for '_'), or a fit's JSON output (fraccontact
fit --json > fit.json; --fit fit.json), which given values override. A bad
value is refused as the FMU would refuse it, before anything is written
(exit status 2)."""

import argparse
import io
import json
import math
import numbers
import os
import pathlib
import sys
import uuid
import warnings
import xml.etree.ElementTree as ET
import zipfile

from . import model
from .atomic import replacing
from .fixed_values import FIXED_VALUES, OMIT
from .options import OneLineParser
from .shipped import fmu_path

FMU_FILES = {2: "fraccontact", 3: "fraccontact-fmi3"}
SCENES = model.WORDS["scene"]  # drop, driven
COUPLINGS = {"gauss-seidel": 1, "jacobi": 2}  # the coupling parameter's codes
MODEL_EXCHANGE = "model-exchange"  # the host's solver integrates the contact: the coupling parameter has no effect
BODIES = (1, 2)
# docs/two_bodies.md: the second body's inputs, and the accelerations of the
# bodies' other forces, which only the driven scene's proxy striker reads.
SECOND_BODY = ("v2", "m2", "a2")
OTHER_FORCES = ("a", "a2")
# What each coupling's master reads as the contact's force over a step (Model Exchange: neither).
COUPLING_FORCE = {1: "F_avg", 2: "F_avg_next"}
# The ModelStructure's entries of Model Exchange (FMI 2.0's sections, FMI 3.0's elements): the states'
# derivatives, whose states they name, and the event indicators.
MODEL_EXCHANGE_STRUCTURE = ("Derivatives", "ContinuousStateDerivative", "EventIndicator")
# The proxy striker's inputs of the driven scene, which Model Exchange has not (the host moves the bodies).
PROXY = ("m",)
SCENE_OPTIONS = ("scene", "coupling")  # the FMU's parameters that --scene and --coupling set
# A fit's JSON keys (fraccontact fit --json) that are values of the FMU, by
# the FMU's name; E_s follows from k, which wins over it.
FIT_VALUES = {"k": "k", "c": "c", "c_alpha": "c_alpha", "alpha": "damper_order", "law": "law", "damper": "damper",
              "m": "m", "v": "v"}
TOKEN = {2: "guid", 3: "instantiationToken"}  # modelDescription.xml's attribute tying it to the binary
TYPES = {"Real": "Real", "Float64": "Real", "Integer": "Integer", "Int32": "Integer", "Boolean": "Boolean"}


# ---------------------------------------------------------------------------------------------------------------
# The full FMU's variables.


class Variable:
    """A variable of a modelDescription.xml: its element, and the element
    holding its type and start (FMI 2.0's child, FMI 3.0's element itself)."""

    def __init__(self, element, fmi):
        self.element = element
        self.typed = element if fmi == 3 else next(c for c in element if c.tag in TYPES)
        self.name = element.get("name")
        self.causality = element.get("causality", "local")
        self.type = TYPES.get(self.typed.tag)
        self.vr = element.get("valueReference")

    @property
    def settable(self):
        return self.causality in ("parameter", "input")


def description_of(path):
    """The FMI version and the parsed modelDescription.xml of the FMU file path."""
    with zipfile.ZipFile(path) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    return int(root.get("fmiVersion").partition(".")[0]), root


def variables_of(root, fmi):
    holder = root.find("ModelVariables")
    return [Variable(e, fmi) for e in holder if fmi == 3 or e.tag == "ScalarVariable"]


def full_fmu(fmi):
    """The shipped FMU of that FMI version (fmu_path; $FRACCONTACT_FMU3 names another build's FMI 3.0 FMU)."""
    return fmu_path(FMU_FILES[fmi])


# ---------------------------------------------------------------------------------------------------------------
# The scene: what it exposes, and the values.


def exposed_names(variables, scene, bodies, coupling, keep):
    """The names the exported FMU keeps: the scene's inputs, its outputs, the kept ones. coupling: the
    coupling parameter's code, None for Model Exchange (which has no proxy striker and no step's average)."""
    hidden = set()
    if bodies == 1:
        hidden.update(SECOND_BODY)
    if scene == SCENES["drop"] or coupling is None:
        hidden.update(OTHER_FORCES)
    if scene == SCENES["driven"] and coupling is None:
        hidden.update(PROXY)
    hidden.update(force for code, force in COUPLING_FORCE.items() if code != coupling)
    names = {v.name for v in variables}
    missing = sorted((hidden | set(COUPLING_FORCE.values())) - names)
    if missing:
        raise RuntimeError(f"the full FMU lacks the variables {', '.join(missing)} that export knows")
    return {v.name for v in variables if (v.causality in ("input", "output", "independent") and v.name not in hidden)
            or v.name in keep}


def value_of(variable, given):
    """A value as the FMU takes it: a float, an int (an enumeration's word as its code) or a bool; ValueError
    naming the variable, the value and the rule."""
    words = model.WORDS.get(variable.name, {})
    if variable.type == "Real":
        if isinstance(given, bool) or not isinstance(given, (numbers.Real, str)):
            raise ValueError(f"{variable.name} = {given!r} is invalid: it must be a real number")
        try:
            return float(given)
        except ValueError:
            raise ValueError(f"{variable.name} = {given!r} is invalid: it must be a real number") from None
    if variable.type == "Integer":
        if isinstance(given, str) and given in words:
            return words[given]
        if not isinstance(given, bool):
            try:
                number = float(given)
            except (TypeError, ValueError, OverflowError):
                number = None
            if number is not None and math.isfinite(number) and number == int(number) \
                    and model.C_INT.min <= number <= model.C_INT.max:
                return int(number)
        choices = f" or one of {', '.join(words)}" if words else ""
        raise ValueError(f"{variable.name} = {given!r} is invalid: it must be a whole number that fits a C int"
                         f"{choices}")
    if given in (True, False, 0, 1, "true", "false", "0", "1"):
        return given in (True, 1, "true", "1")
    raise ValueError(f"{variable.name} = {given!r} is invalid: it must be a Boolean (true or false)")


def checked_values(variables, values):
    """{name: value} as the FMU takes them, every name a parameter or input of the FMU; the library's rules
    for the parameters it shares (ValueError as it words it)."""
    by_name = {v.name: v for v in variables}
    out = {}
    for name, given in values.items():
        v = by_name.get(name)
        if v is None or not v.settable:
            settable = ", ".join(v.name for v in variables if v.settable)
            what = f"{name} is an output" if v is not None else f"the FMU has no variable {name}"
            raise ValueError(f"{what}: values are given to its parameters and inputs ({settable})")
        out[name] = value_of(v, given)
    unused = model.warning(**{n: x for n, x in out.items() if n in model.NAMES})  # ValueError where refused
    if unused:
        warnings.warn(unused, model.ParameterWarning, stacklevel=3)
    return out


def fit_values(fit, source):
    """The FMU's values in a fit (fraccontact fit --json's object, or the path of a file holding it)."""
    named = "the fit" if isinstance(fit, dict) else f"fit = {str(fit)!r}"
    if not isinstance(fit, dict):
        try:
            fit = json.loads(pathlib.Path(fit).read_text())
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
            raise ValueError(f"{named}: not a fit's JSON output ({e})") from None
    if isinstance(fit, dict) and fit.get("family"):
        raise ValueError(f"{named}: the fit found a family of solutions, not one: fix the springpot's order "
                         "(fraccontact fit ... --damper-order ALPHA)")
    if not isinstance(fit, dict) or "k" not in fit:
        raise ValueError(f"{named}: not a fit's JSON output (it has no k): write it with fraccontact fit ... --json")
    return {FIT_VALUES[key]: fit[key] for key in FIT_VALUES if fit.get(key) is not None}, fit


def word(name, values):
    """The word of an enumerated parameter's value (its default where not given)."""
    code = values.get(name, model.defaults()[name])
    return next(w for w, c in model.WORDS[name].items() if c == code)


def described(values, scene, bodies, coupling, material):
    """The description's first part: the material, the scene, the law, the damper, k and the damper's
    constants."""
    default = model.defaults()
    names = ("k", "c") if word("damper", values) == "dashpot" else ("k", "c_alpha", "damper_order")
    constants = ", ".join(f"{n} = {values.get(n, default[n]):.6g}" for n in names)
    return [f"fraccontact contact{' of ' + material if material else ''}, exported for the {scene} scene with "
            f"{bodies} bod{'y' if bodies == 1 else 'ies'} and the {coupling} coupling: law {word('law', values)}, "
            f"{word('damper', values)}, {constants}"]


def fit_summary(fit, source):
    """The fit's figures for the description: its source, the model's F_peak and eps, the residuals."""
    figures = [f"{key} = {fit[key]:.6g}" for key in ("F_peak", "eps", "rms_residual") if fit.get(key) is not None]
    figures += [f"sigma_{key} = {fit['sigma_' + key]:.3g}" for key in ("k", "c", "c_alpha", "alpha")
                if fit.get("sigma_" + key) is not None]
    return (f"fitted to {source}" if source else "fitted") + (f"; the model at the fit: {', '.join(figures)}"
                                                              if figures else "")


# ---------------------------------------------------------------------------------------------------------------
# The exported FMU's files.


def spelled(variable, value):
    """A value as modelDescription.xml and the file of fixed values write it (repr: a Real read back to the bit)."""
    if variable.type == "Boolean":
        return "true" if value else "false"
    if variable.type == "Real" and not math.isfinite(value):
        return {"nan": "NaN", "inf": "INF", "-inf": "-INF"}[repr(value)]  # XML's spelling, which strtod reads
    return repr(value)


def fixed_values_text(variables, exposed, values, title):
    """The resources file: every hidden parameter and input at its value (given or the full FMU's start), and
    every exposed one given a value, its start in the exported FMU; in the order of modelDescription.xml; then
    a line "omit NAME" for each output left out (without F_avg_next the binary keeps no prediction)."""
    lines = [f"# {line}" for line in title] + ["# name value (fmu_src/glue/fixed_values.c reads it at "
                                                "instantiation)"]
    for v in variables:
        if not v.settable or (v.name in exposed and v.name not in values):
            continue
        value = values[v.name] if v.name in values else value_of(v, v.typed.get("start"))
        lines.append(f"{v.name} {spelled(v, value)}{'  # its start: tunable' if v.name in exposed else ''}")
    lines += [f"{OMIT} {v.name}" for v in variables if v.causality == "output" and v.name not in exposed]
    return "\n".join(lines + ["end", ""])


def exported_token(full, *content):
    """The exported FMU's own GUID or instantiation token, the same for the same export: a modelDescription.xml
    of other variables is another FMU's (importers such as libcosim keep one description per GUID)."""
    return "{" + str(uuid.uuid5(uuid.UUID(full.strip("{}")), repr(content))) + "}"


def model_exchange_names(root, fmi):
    """The variables Model Exchange needs besides the scene's: those of the ModelStructure's
    MODEL_EXCHANGE_STRUCTURE, and the states whose derivatives they are."""
    variables = variables_of(root, fmi)
    by_number = {(str(i) if fmi == 2 else v.vr): v for i, v in enumerate(variables, 1)}
    key = "index" if fmi == 2 else "valueReference"
    structure = root.find("ModelStructure")
    entries = [e for e in structure.iter() if e.tag in MODEL_EXCHANGE_STRUCTURE and e.get(key) is not None]
    entries += [e for section in structure if section.tag in MODEL_EXCHANGE_STRUCTURE for e in section]
    named = [by_number[e.get(key)] for e in entries]
    return {v.name for v in named} | {by_number[v.typed.get("derivative")].name for v in named
                                      if v.typed.get("derivative") is not None}


def renumbered(text, numbers):
    """A space-separated list of references, those in numbers mapped, the others dropped."""
    return " ".join(numbers[n] for n in text.split() if n in numbers)


def output_knowns(root, fmi):
    """What an output may depend on in the kept variables (renumbered): the inputs and the states, those a
    derivative names; a co-simulation export has no states (its x, x2, ... are outputs only)."""
    states = {typed.get("derivative") for typed in root.iter() if typed.get("derivative") is not None}
    return states | {str(i) if fmi == 2 else v.vr for i, v in enumerate(variables_of(root, fmi), 1)
                     if v.causality == "input"}


def filter_structure(root, numbers, fmi):
    """ModelStructure and derivative references of the variables kept, renumbered (FMI 2.0: 1-based
    indices into ModelVariables; FMI 3.0: value references, which stay)."""
    key = "index" if fmi == 2 else "valueReference"
    for typed in root.iter():
        if typed.get("derivative") is not None:
            reference = renumbered(typed.get("derivative"), numbers)
            if reference:
                typed.set("derivative", reference)
            else:
                del typed.attrib["derivative"]
    structure = root.find("ModelStructure")
    knowns = output_knowns(root, fmi)
    for holder in [structure] + list(structure):
        for unknown in list(holder):
            if unknown.get(key) is None:
                continue
            if unknown.get(key) not in numbers:
                holder.remove(unknown)
                continue
            unknown.set(key, numbers[unknown.get(key)])
            kinds = unknown.get("dependenciesKind")
            if unknown.get("dependencies") is not None:
                deps = unknown.get("dependencies").split()
                output = holder.tag == "Outputs" or unknown.tag == "Output"
                kept = [i for i, d in enumerate(deps) if d in numbers and (not output or numbers[d] in knowns)]
                unknown.set("dependencies", " ".join(numbers[deps[i]] for i in kept))
                if kinds is not None and kept:
                    unknown.set("dependenciesKind", " ".join(kinds.split()[i] for i in kept))
                elif kinds is not None:
                    del unknown.attrib["dependenciesKind"]
        if holder is not structure and len(holder) == 0 and fmi == 2:
            structure.remove(holder)


def filtered_description(root, fmi, exposed, values, name, text, stop_time, token, interface):
    """modelDescription.xml of the exported FMU: the exposed variables, their given values as starts,
    the one interface ("CoSimulation" or "ModelExchange"), with its name, description, default experiment and
    its own GUID or instantiation token."""
    variables = variables_of(root, fmi)
    holder = root.find("ModelVariables")
    numbers = {}
    for index, v in enumerate(variables, 1):
        if v.name not in exposed:
            holder.remove(v.element)
            continue
        numbers[str(index) if fmi == 2 else v.vr] = str(len(numbers) + 1) if fmi == 2 else v.vr
        if v.name in values:
            v.typed.set("start", spelled(v, values[v.name]))
    filter_structure(root, numbers, fmi)
    for other in root.findall("ModelExchange") + root.findall("CoSimulation"):
        if other.tag != interface:
            root.remove(other)
    root.set("modelName", name)
    root.set(TOKEN[fmi], token)
    root.set("generationTool", "fraccontact export (docs/export.md)")
    root.set("description", text)
    experiment = root.find("DefaultExperiment")
    if experiment is not None and stop_time is not None:
        experiment.set("stopTime", repr(stop_time))
    ET.indent(root, space="  ")
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True) + b"\n"


def fmu_bytes(source, description, fixed_text):
    """The exported FMU as zip bytes: every file of the full one, its modelDescription.xml replaced, the
    fixed values added."""
    out = io.BytesIO()
    with zipfile.ZipFile(source) as full, zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as z:
        for info in full.infolist():
            if info.filename in ("modelDescription.xml", FIXED_VALUES):
                continue
            z.writestr(info, full.read(info.filename))
        z.writestr("modelDescription.xml", description)
        z.writestr(FIXED_VALUES, fixed_text)
    return out.getvalue()


def instantiation_error(data, fmi, model_exchange):
    """The exported FMU instantiated where fmpy and a binary for this platform are at hand (for Model
    Exchange also initialized, where the FMU applies its rules of Model Exchange): None, or the FMU's message
    refusing its fixed values."""
    import tempfile
    try:
        from fmpy import extract, platform, platform_tuple, read_model_description
    except ImportError:
        return None
    with tempfile.TemporaryDirectory() as folder:
        path = pathlib.Path(folder, "exported.fmu")
        path.write_bytes(data)
        with zipfile.ZipFile(path) as z:
            if not any(n.startswith(f"binaries/{platform if fmi == 2 else platform_tuple}/") for n in z.namelist()):
                return None
        md = read_model_description(str(path))
        unzipped = extract(str(path), unzipdir=os.path.join(folder, "unzipped"))
        messages = []
        try:
            instance = (model_exchange_instance if model_exchange else instantiated)(md, unzipped, fmi, messages)
        except Exception:
            return messages[-1] if messages else "the exported FMU cannot be instantiated"
        try:
            if model_exchange:
                instance.enterInitializationMode()
                instance.exitInitializationMode()
        except Exception:
            return messages[-1] if messages else "the exported FMU cannot be initialized"
        finally:
            instance.freeInstance()
        return None


def instantiated(md, unzipped, fmi, messages):
    """An instance of the unpacked FMU whose error messages land in messages."""
    if fmi == 2:
        from .fmu import Slave

        class Probe(Slave):
            def _logger(self, env, name, status, category, message):
                super()._logger(env, name, status, category, message)
                if status >= 3:
                    messages.append(message.decode())
        return Probe(md, unzipped, start=False, instance_name="export").fmu
    from fmpy.fmi3 import FMU3Slave
    return fmi3_instance(FMU3Slave, md.coSimulation, md, unzipped, messages)


def fmi3_instance(kind, interface, md, unzipped, messages):
    """An FMI 3.0 instance (kind: fmpy's FMU3Slave or FMU3Model) of the unpacked FMU's
    interface whose error messages land in messages."""
    def log(env, status, category, message):
        if status >= 3:
            messages.append(message.decode())
    fmu = kind(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=interface.modelIdentifier,
               instanceName="export")
    fmu.instantiate(logMessage=log)
    return fmu


def model_exchange_instance(md, unzipped, fmi, messages):
    """A Model Exchange instance of the unpacked FMU whose error messages land in messages."""
    if fmi == 3:
        from fmpy.fmi3 import FMU3Model
        return fmi3_instance(FMU3Model, md.modelExchange, md, unzipped, messages)
    from ctypes import byref
    from fmpy import calloc, free
    from fmpy.fmi2 import (FMU2Model, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                           fmi2CallbackFunctions, fmi2CallbackLoggerTYPE)
    from fmpy.logging import addLoggerProxy

    def log(env, name, status, category, message):
        if status >= 3:
            messages.append(message.decode())
    callbacks = fmi2CallbackFunctions()
    callbacks.logger = fmi2CallbackLoggerTYPE(log)
    callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    addLoggerProxy(byref(callbacks))
    fmu = FMU2Model(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.modelExchange.modelIdentifier,
                    instanceName="export")
    fmu.instantiate(callbacks=callbacks)  # fmu keeps callbacks alive
    fmu.setupExperiment(startTime=0.0)
    return fmu


# ---------------------------------------------------------------------------------------------------------------
# The function and the command.


def export(path, scene="drop", bodies=1, coupling="gauss-seidel", fmi=2, values=None, keep=(), fit=None,
           source=None, name=None, material=None, stop_time=None):
    """Writes the FMU of one scene to path and returns what it holds: {"variables": the exposed names,
    "fixed": the fixed values' file text, "full_variables": the full FMU's count}.

    scene: drop or driven; bodies: 1 or 2 (the second body's m2 > 0 free); coupling: gauss-seidel or jacobi
    (what the master feeds: F_avg after the step, F_avg_next before it), or model-exchange (an FMU of Model
    Exchange alone: law 2, the dashpot or the springpot's compressed memory); fmi: 2 or 3; values: {name: value}
    of the FMU's parameters and inputs; keep: names that stay tunable; fit: a fit's JSON output (its object
    or a file's path), whose values the given ones override; source: the fit's data, for the description
    (default the fit's path); name: the modelName; material: words for the description;
    stop_time: the default experiment's. ValueError for a bad argument, naming it, its value and the rule."""
    for option, value, allowed in (("scene", scene, SCENES), ("coupling", coupling, (*COUPLINGS, MODEL_EXCHANGE)),
                                   ("bodies", bodies, BODIES), ("fmi", fmi, FMU_FILES)):
        if value not in allowed or isinstance(value, bool):
            raise ValueError(f"{option} = {value!r} is invalid: it must be one of "
                             f"{', '.join(str(a) for a in allowed)}")
    path = pathlib.Path(path)
    if not path.parent.is_dir():
        raise ValueError(f"path = {str(path)!r} is invalid: its folder {str(path.parent)!r} does not exist")
    source = source if source is not None else fit if not isinstance(fit, dict) else None
    given, fitted = fit_values(fit, source) if fit is not None else ({}, None)
    full = full_fmu(fmi)
    _, root = description_of(full)
    variables = variables_of(root, fmi)
    given.update(values or {})
    given.update(scene=SCENES[scene])
    model_exchange = coupling == MODEL_EXCHANGE
    if model_exchange and scene == "driven":
        given.setdefault("m", 0.0)  # the rate prescribed: the host moves the bodies
    elif not model_exchange:
        given.update(coupling=COUPLINGS[coupling])
    unknown = [k for k in keep if k not in {v.name for v in variables if v.settable}]
    if unknown:
        raise ValueError(f"keep = {unknown[0]!r} is invalid: it must name a parameter or input of the FMU (its "
                         "outputs are all exposed)")
    if stop_time is not None and not (isinstance(stop_time, numbers.Real) and 0 < stop_time < math.inf):
        raise ValueError(f"stop_time = {stop_time!r} is invalid: it must be a positive, finite time [s]")
    checked = checked_values(variables, given)
    if bodies == 1 and checked.get("m2", 0) != 0:
        raise ValueError(f"m2 = {checked['m2']!r} is invalid with bodies = 1: a second body of mass m2 > 0 is "
                         "bodies = 2")
    exposed = exposed_names(variables, SCENES[scene], bodies, COUPLINGS.get(coupling), set(keep))
    if model_exchange:
        exposed |= model_exchange_names(root, fmi)
    what = described(checked, scene, bodies, coupling, material)
    name = name or f"fraccontact_{word('damper', checked)}_{scene}"
    if fitted is not None:
        what.append(fit_summary(fitted, source))
    fixed = fixed_values_text(variables, exposed, checked, what)
    token = exported_token(root.get(TOKEN[fmi]), fixed, sorted(exposed), name, what, stop_time)
    description = filtered_description(root, fmi, exposed, checked, name, "; ".join(what), stop_time, token,
                                       "ModelExchange" if model_exchange else "CoSimulation")
    fixed = fixed.replace("\nend\n", f"\nguid {token}\nend\n")
    data = fmu_bytes(full, description, fixed)
    refused = instantiation_error(data, fmi, model_exchange)
    if refused:
        raise ValueError(f"the exported FMU refuses its values at "
                         f"{'initialization in Model Exchange' if model_exchange else 'instantiation'}: {refused}")
    with replacing(path, "wb") as f:
        f.write(data)
    return {"path": str(path), "variables": sorted(exposed), "full_variables": len(variables), "fixed": fixed}


def value_options(parser, variables):
    """--NAME for every parameter and input of the full FMU but those the scene's options set."""
    group = parser.add_argument_group("values (the FMU's parameters and inputs, docs/variables.md)")
    for v in variables:
        if v.settable and v.name not in SCENE_OPTIONS:
            group.add_argument("--" + v.name.replace("_", "-"), dest="value_" + v.name, metavar="VALUE",
                               help=f"{v.type} (full FMU's start {v.typed.get('start')})")


def build_parser(prog=None):
    p = OneLineParser(prog=prog, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("path", type=pathlib.Path, help="the FMU to write (.fmu)")
    p.add_argument("--scene", choices=tuple(SCENES), default="drop", help="the scene (default drop)")
    p.add_argument("--bodies", type=int, choices=BODIES, default=1,
                   help="1: the specimen held (m2 = 0), 2: a free second body (v2, m2 exposed); default 1")
    p.add_argument("--coupling", choices=tuple(COUPLINGS) + (MODEL_EXCHANGE,), default="gauss-seidel",
                   help="what the master feeds (default gauss-seidel: F_avg after the step; jacobi: F_avg_next); "
                        "model-exchange: an FMU of Model Exchange, which the host's solver integrates (law 2)")
    p.add_argument("--fmi", type=int, choices=tuple(FMU_FILES), default=2, help="FMI version (default 2)")
    p.add_argument("--fit", type=pathlib.Path, metavar="JSON", help="a fit's JSON output (fraccontact fit --json)")
    p.add_argument("--keep", nargs="+", default=[], metavar="NAME", help="variables that stay tunable")
    p.add_argument("--name", help="the FMU's modelName (default fraccontact_<damper>_<scene>)")
    p.add_argument("--material", help="the material and test, for the FMU's description")
    p.add_argument("--stop-time", type=float, help="the default experiment's stop time [s]")
    p.add_argument("--cross-check", type=pathlib.Path, metavar="DIR",
                   help="also write the FMU's FMI Cross-Check entry under DIR (fmus/<FMI version>/cs/<platform>/...)")
    p.add_argument("--ssp", nargs=3, metavar=("SSP", "COMPONENT", "OUT"),
                   help="also write the SSP OUT: SSP with its component COMPONENT made the exported FMU")
    fmi, root = description_of(full_fmu(2))
    value_options(p, variables_of(root, fmi))
    return p


def main(argv=None, prog=None):
    parser = build_parser(prog)
    args = parser.parse_args(argv)
    values = {key[len("value_"):]: text for key, text in vars(args).items()
              if key.startswith("value_") and text is not None}
    if args.cross_check is not None and not args.cross_check.is_dir():
        parser.error(f"--cross-check {args.cross_check}: no such folder")
    from .cross_check import check_name, entry
    try:
        if args.cross_check is not None and args.name is not None:
            check_name(args.name)
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always", model.ParameterWarning)
            out = export(args.path, scene=args.scene, bodies=args.bodies, coupling=args.coupling, fmi=args.fmi,
                         values=values, keep=args.keep, fit=args.fit, name=args.name, material=args.material,
                         stop_time=args.stop_time)
        for w in said:
            print(f"{parser.prog}: warning: {w.message}", file=sys.stderr)
    except ValueError as e:
        print(f"{parser.prog}: {e}", file=sys.stderr)
        return 2
    print(f"{out['path']}: {len(out['variables'])} of the full FMU's {out['full_variables']} variables: "
          f"{', '.join(out['variables'])}")
    if args.ssp:
        from .ssp import with_exported
        ssp, component, target = args.ssp
        try:
            with_exported(ssp, {component: out["path"]}, target)
        except (OSError, KeyError, zipfile.BadZipFile, ET.ParseError) as e:
            print(f"{parser.prog}: --ssp {ssp}: not an SSP ({e})", file=sys.stderr)
            return 2
        except ValueError as e:
            print(f"{parser.prog}: --ssp {ssp}: {e}", file=sys.stderr)
            return 2
        print(f"{target}: {ssp} with {component} = {out['path']}")
    if args.cross_check:
        for folder in entry(out["path"], args.cross_check):
            print(f"{folder}: the Cross-Check entry")
    return 0
