"""The drop test as an SSP file (build/drop_test.ssp, made by CMake from ssp/):
the striker and the contact FMU wired for the predictive coupling (F_avg_next),
run by two independent SSP importers, fmpy and libcosim (libcosimpy), and by
OMSimulator where it is installed (fraccontact.omsimulator). And any SSP with
components made exported FMUs (with_exported; fraccontact export --ssp,
docs/export.md).

Both step every FMU from the values of the last communication point (Jacobi),
so the results are those of fraccontact.cosim's Jacobi order, predictive
coupling. Used by the cosim_study report and tests/test_ssp.py.
"""

import io
import math
import os
import pathlib
import xml.etree.ElementTree as ET
import zipfile

import numpy as np

from .shipped import fmu_path
from .atomic import replacing
from .cosim import M, V0
from .fixed_values import FIXED_VALUES, fixed_of

T_END = 3e-3  # the SSD's DefaultExperiment: the impact and the rebound


def ssp_path():
    """The scene: $DROP_TEST_SSP, else drop_test.ssp next to the contact FMU
    (the build folder, or the installed package, which ships both)."""
    path = pathlib.Path(os.environ.get("DROP_TEST_SSP") or fmu_path().parent / "drop_test.ssp")
    if not path.exists():
        raise FileNotFoundError(f"{path} does not exist: build it (scripts/build makes build/drop_test.ssp; pip install . puts it in the package)")
    return path


def bound_parameters(ssp):
    """The parameter bindings of every component of the SSP ssp (a path) as
    one fmpy parameter set, for simulate_ssp(ssp, ..., parameter_set=...):
    fmpy applies no binding itself, only a set it is given, and matches its
    names by the component's path ("contact.scene", "head.v0"), where a
    binding names the component's own variables ("scene")."""
    from fmpy.ssp.ssd import ParameterSet, Parameter, find_components, read_ssd
    merged = ParameterSet(name="bindings")
    for component in find_components(read_ssd(str(ssp)).system):
        for binding in component.parameterBindings:
            for values in binding.parameterValues:
                for p in values.parameters:
                    merged.parameters.append(Parameter(name=f"{component.name}.{p.name}", type=p.type,
                                                       value=p.value, unit=p.unit))
    return merged


def summary(F_peak, E_diss, v_end):
    """What fraccontact.cosim reports of a run: eps from the striker's final
    velocity, the energy error against the impact energy."""
    return dict(F_peak=F_peak, eps=-v_end / V0, E_diss=E_diss,
                energy_error=(0.5 * M * v_end ** 2 + E_diss) / (0.5 * M * V0 ** 2) - 1)


def run_fmpy(ssp, H, t_end=T_END):
    """The scene in fmpy's SSP master. It starts every connector at 0, so the
    contact's first step sees v = 0 and the impact begins one step late; the
    run is the Jacobi run shifted by H, its results the same once the
    rebound is over."""
    from fmpy.ssp.simulation import simulate_ssp
    rows = simulate_ssp(str(ssp), stop_time=t_end, step_size=H, parameter_set=bound_parameters(ssp))
    last = rows[-1]
    return dict(summary(last["contact.F_peak"], last["contact.E_diss"], last["striker.v"]), rows=rows)


def run_libcosim(ssp, H, t_end=T_END):
    """The scene in libcosim's SSP loader (it applies the parameter bindings
    itself), with its fixed-step algorithm at step H instead of the SSD's."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    log_output_level(CosimLogLevel.ERROR)
    ex = CosimExecution.from_ssp_file(str(ssp), step_size=round(H * 1e9))  # libcosim counts nanoseconds
    observer = CosimObserver.create_last_value()
    ex.add_observer(observer)
    ex.simulate_until(target_time=round(t_end * 1e9))
    contact, striker = (ex.slave_index_from_instance_name(n) for n in ("contact", "striker"))
    vr = {name: {v.name.decode(): v.reference for v in ex.slave_variables(index)}
          for name, index in (("contact", contact), ("striker", striker))}
    F_peak, E_diss = observer.last_real_values(contact, [vr["contact"]["F_peak"], vr["contact"]["E_diss"]])
    v_end = observer.last_real_values(striker, [vr["striker"]["v"]])[0]
    # libcosim only warns when a binding fails to apply: report what the contact runs with, as it reads
    # them, or as an exported contact's file fixes them (its binary sets them)
    names = ("scene", "law", "coupling")
    read = [n for n in names if n in vr["contact"]]
    applied = dict(zip(read, observer.last_integer_values(contact, [vr["contact"][n] for n in read]))) if read else {}
    fixed = fixed_values(ssp, "contact") if len(read) < len(names) else {}
    applied.update({n: int(fixed[n]) for n in names if n not in applied})
    return dict(summary(F_peak, E_diss, v_end), applied=applied)


def grid(H, t_end):
    """A fixed-step master's communication points 0, H, ..., N H with N H the last <= t_end."""
    n = int(math.floor(t_end / H * (1 + 1e-12)))
    return np.arange(n + 1) * H


def run_omsimulator(ssp, H, t_end=T_END):
    """The scene in OMSimulator's fixed-step master (it applies the parameter
    bindings itself) at step H instead of the SSD's."""
    from .omsimulator import simulate
    trace = simulate(ssp, H, grid(H, t_end), {}, ("contact.F_peak", "contact.E_diss", "striker.v"))
    return summary(trace["contact.F_peak"][-1], trace["contact.E_diss"][-1], trace["striker.v"][-1])


def registered_namespaces(data):
    """The XML's namespace prefixes, registered so that ElementTree writes them back as they were."""
    for _, (prefix, uri) in ET.iterparse(io.BytesIO(data), events=("start-ns",)):
        ET.register_namespace(prefix, uri)


def local(tag):
    return tag.rpartition("}")[2]


def bound_value(parameter):
    """An SSV parameter's value as a number."""
    typed = next(iter(parameter))
    text = typed.get("value")
    return (text == "true") if local(typed.tag) == "Boolean" else float(text)


def exposed(component, name, value, fixed, names):
    """Whether the exported FMU of component exposes name: else it must fix it at value (else ValueError)."""
    if name in names:
        return True
    if name not in fixed:
        raise ValueError(f"{component}.{name} is set, which the exported FMU has not")
    kept = fixed[name]
    if value != (kept == "true" if kept in ("true", "false") else float(kept)):
        raise ValueError(f"{component}.{name} = {value!r} is set, but the exported FMU fixes it at {kept}")
    return False


def filter_bindings(parameter_set, component, fixed, names):
    """Leaves out of an SSV parameter set the values the FMU fixes, each equal to its fixed value (else
    ValueError); the number of values left."""
    holder = next(e for e in parameter_set.iter() if local(e.tag) == "Parameters")
    for parameter in list(holder):
        if not exposed(component, parameter.get("name"), bound_value(parameter), fixed, names):
            holder.remove(parameter)
    return len(holder)


def component_fmus(ssp, components):
    """{component: its FMU's bytes as a file} of the SSP's components named."""
    with zipfile.ZipFile(ssp) as z:
        ssd = ET.fromstring(z.read("SystemStructure.ssd"))
        sources = {e.get("name"): e.get("source") for e in ssd.iter() if local(e.tag) == "Component"}
        return {component: io.BytesIO(z.read(sources[component])) for component in components}


def fixed_values(ssp, component):
    """{name: value text} that the SSP's component fixes: an exported FMU's fixed values, none for a full FMU."""
    fmu = component_fmus(ssp, [component])[component]
    return fixed_of(fmu)[0] if FIXED_VALUES in zipfile.ZipFile(fmu).namelist() else {}


def exposed_values(ssp, values):
    """{component: {name: value}} of values that the SSP's FMUs expose: a value its exported FMUs fix is left
    out, each equal to the fixed one (else ValueError). What a master sets on the SSP of a scene."""
    fmus = component_fmus(ssp, values)
    out = {}
    for component, given in values.items():
        if FIXED_VALUES not in zipfile.ZipFile(fmus[component]).namelist():
            out[component] = dict(given)
            continue
        fixed, names = fixed_of(fmus[component])
        out[component] = {n: x for n, x in given.items() if exposed(component, n, x, fixed, names)}
    return out


def replace_component(ssd, files, component, fmu):
    """The component's source made the exported FMU, its connectors checked against it, the bindings it fixes
    left out."""
    element = next((e for e in ssd.iter() if local(e.tag) == "Component" and e.get("name") == component), None)
    if element is None:
        names = [e.get("name") for e in ssd.iter() if local(e.tag) == "Component"]
        raise ValueError(f"component = {component!r} is invalid: the SSP's components are {', '.join(names)}")
    fixed, names = fixed_of(fmu)
    missing = [c.get("name") for c in element.iter() if local(c.tag) == "Connector" and c.get("name") not in names]
    if missing:
        raise ValueError(f"the SSP connects {component}.{missing[0]}, which the exported FMU {fmu} does not expose "
                         "(export it for this scene: --scene, --bodies, --coupling, --keep)")
    element.set("source", f"resources/{component}.fmu")
    files[f"resources/{component}.fmu"] = pathlib.Path(fmu).read_bytes()
    for bindings in [e for e in element if local(e.tag) == "ParameterBindings"]:
        for binding in list(bindings):
            if binding.get("source"):
                data = files[binding.get("source")]
                registered_namespaces(data)
                parameter_set = ET.fromstring(data)
            else:
                parameter_set = binding
            left = filter_bindings(parameter_set, component, fixed, names)
            if not left:
                bindings.remove(binding)
            elif binding.get("source"):
                binding.set("source", f"resources/{component}_bindings.ssv")
                files[binding.get("source")] = ET.tostring(parameter_set, encoding="UTF-8", xml_declaration=True)
        if len(bindings) == 0:
            element.remove(bindings)


def with_exported(ssp, contacts, out):
    """Writes the SSP out: the SSP ssp with the FMU of each component named in contacts ({component: the
    path of an exported FMU}) replaced by it, the values its parameter bindings set that the FMU fixes left
    out (each must equal the fixed one), the files no component uses any longer dropped."""
    with zipfile.ZipFile(ssp) as z:
        files = {n: z.read(n) for n in z.namelist() if not n.endswith("/")}
    registered_namespaces(files["SystemStructure.ssd"])
    ssd = ET.fromstring(files["SystemStructure.ssd"])
    for component, fmu in contacts.items():
        replace_component(ssd, files, component, fmu)
    used = {e.get("source") for e in ssd.iter() if e.get("source")}
    files = {n: data for n, data in files.items() if not n.startswith("resources/") or n in used}
    files["SystemStructure.ssd"] = ET.tostring(ssd, encoding="UTF-8", xml_declaration=True)
    with replacing(out, "wb") as f, zipfile.ZipFile(f, "w", zipfile.ZIP_DEFLATED) as z:
        for name, data in files.items():
            z.writestr(name, data)
    return pathlib.Path(out)
