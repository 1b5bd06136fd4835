"""A scene's SSP as one container FMU, built by fmu-manipulation-toolbox
(PyPI) and run by fmpy.

The toolbox reads the SSP's SSD (components, connections) but not its
parameter bindings, nor does it expose anything an SSD does not connect to
the system's boundary: the components' values (the SSV files') become the
container's start values, and the recorded variables its outputs. By
default its container steps every embedded FMU from the values of the last
internal step (a Jacobi master), with the internal step H. In its
sequential mode it steps them one after the other, each with the outputs the
ones before it have just computed (Gauss-Seidel): the contacts then step
first, from the bodies' state at the step's start, with coupling = 1, and
the bodies take the force of that step, F_avg, in place of the SSD's
F_avg_next (docs/coupling.md).
"""

import contextlib
import io
import logging
import pathlib
import shutil
import tempfile

from fmpy import simulate_fmu
from fmpy.ssp.ssd import find_components, read_ssd

from .systems import FMUS


def instance_names(ssp):
    """{SSD component: the toolbox's name of its FMU}: the FMU's file in the
    SSP's extract folder, numbered from its second instance on."""
    from fmu_manipulation_toolbox.assembly import instance_name
    used, names = [], {}
    for component in find_components(read_ssd(str(ssp)).system):
        name = instance_name(f"{ssp.stem}.dir/{pathlib.Path(component.source).name}", used)
        used.append(name)
        names[component.name] = name
    return names


def gauss_seidel(node, names, start):
    """Makes the container's node sequential, contacts first, fed coupling =
    1 and F_avg: start's contacts are changed in place."""
    contacts = [names[c] for c in start if FMUS[c] == "fraccontact"]
    node.sequential = True
    node.fmu_names_list.sort(key=lambda name: name not in contacts)
    for link in node.links:
        if link.from_port.port_name == "F_avg_next":
            link.from_port.port_name = "F_avg"
    for component, values in start.items():
        if FMUS[component] == "fraccontact":
            values["coupling"] = 1


def build(ssp, H, start, outputs, folder, sequential=False):
    """The container FMU of ssp in folder (its path): internal step H [s],
    start values start ({component: {variable: value}}), outputs the
    recorded "component.variable" names; sequential: Gauss-Seidel."""
    from fmu_manipulation_toolbox.assembly import Assembly
    # It reports the inputs the SSD leaves unconnected (the masses, the rigid barrier's v2) as errors: they
    # are set by the start values.
    logging.getLogger("fmu_manipulation_toolbox").setLevel(logging.CRITICAL)
    folder = pathlib.Path(folder)
    shutil.copy(ssp, folder / ssp.name)
    names = instance_names(ssp)
    assembly = Assembly(ssp.name, fmu_directory=folder, default_step_size=H)
    if sequential:
        start = {component: dict(values) for component, values in start.items()}
        gauss_seidel(assembly.root, names, start)
    for component, values in start.items():
        for variable, value in values.items():
            assembly.root.add_start_value(names[component], variable, str(value))
    for output in outputs:
        component, variable = output.split(".")
        assembly.root.add_output(names[component], variable, output)
    assembly.make_fmu()
    return folder / f"{ssp.stem}.fmu"


def simulate(ssp, H, t_end, start, outputs, sequential=False):
    """{output: values at 0, H, ..., t_end} of the container run by fmpy at
    communication step H; sequential: in Gauss-Seidel order."""
    with tempfile.TemporaryDirectory() as folder:
        fmu = build(pathlib.Path(ssp), H, start, outputs, folder, sequential)
        # fmpy prints the container's log on stdout, which is the command's. On every run the
        # container logs its version, its mode and "Solver configure....", the last with status
        # Error though nothing failed (toolbox 2.0's container_configure sends it unconditionally):
        # the log is kept for a run that fails, whose error it ends. (A logger of our own would
        # outlive the call in fmpy's proxy.)
        log = io.StringIO()
        try:
            with contextlib.redirect_stdout(log):
                rows = simulate_fmu(str(fmu), stop_time=t_end, step_size=H, output_interval=H, output=list(outputs))
        except Exception as e:
            raise RuntimeError(f"the container FMU failed: {e}\nits log:\n{log.getvalue()}") from e
    return {name: rows[name].astype(float) for name in outputs}
