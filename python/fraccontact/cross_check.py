"""The FMI Cross-Check's entry of an exported FMU (fraccontact export
--cross-check DIR, docs/export.md): the layout the community's compliance
process publishes, fmus/<FMI version>/cs/<platform>/<tool>/<version>/<model>/,
with the FMU, its reference result, its inputs, the options of the run and a
ReadMe, which fmpy's validator of vendor repositories checks."""

import pathlib
import re
import zipfile

import numpy as np

from .atomic import replacing

# The platforms of the Cross-Check's layout, by FMI version, as the FMUs' binaries/ folders name them.
CROSS_CHECK_PLATFORMS = {2: ("linux64", "win64"), 3: ("x86_64-linux", "x86_64-windows")}


def package_version():
    """The package's version: the installed distribution's, else the source tree's pyproject.toml."""
    import importlib.metadata
    try:
        return importlib.metadata.version("fraccontact")
    except importlib.metadata.PackageNotFoundError:  # tomllib is Python 3.11's; the package runs on 3.9
        text = (pathlib.Path(__file__).parents[2] / "pyproject.toml").read_text()
        return re.search(r'^version = "([^"]+)"', text, re.M).group(1)


def csv_text(names, columns):
    """A CSV the Cross-Check reads: a header of names, numbers written to the bit, Booleans as 0 and 1."""
    rows = [",".join(f'"{n}"' for n in names)]
    for values in zip(*columns):
        rows.append(",".join(str(int(x)) if isinstance(x, (bool, np.bool_)) else repr(float(x)) for x in values))
    return "\n".join(rows) + "\n"


def check_name(name):
    if not (name.replace("_", "").isalnum() and name.isascii()):
        raise ValueError(f"name = {name!r} is invalid for the Cross-Check: it names a folder and a file, so it "
                         "must be letters, digits and '_'")


def entry(fmu, folder):
    """Writes the FMI Cross-Check entry of the FMU under folder, for each platform it has binaries for:
    fmus/<FMI version>/cs/<platform>/fraccontact/<version>/<model>/ with <model>.fmu, <model>_ref.csv
    (fmpy's run of it from its default experiment), <model>_in.csv (its inputs, held at their start
    values), <model>_ref.opt and ReadMe.md. The folders written."""
    from fmpy import read_model_description, simulate_fmu
    md = read_model_description(str(fmu))
    model = md.modelName
    check_name(model)
    experiment = md.defaultExperiment
    start, stop, step = (float(experiment.startTime or 0), float(experiment.stopTime), float(experiment.stepSize))
    outputs = [v for v in md.modelVariables if v.causality == "output"]
    inputs = [v for v in md.modelVariables if v.causality == "input"]
    result = simulate_fmu(str(fmu), start_time=start, stop_time=stop, output_interval=step,
                          output=[v.name for v in outputs], fmi_type="CoSimulation")
    reference = csv_text(["time"] + [v.name for v in outputs], [result["time"]] + [result[v.name] for v in outputs])
    held = csv_text(["time"] + [v.name for v in inputs], [[start, stop]] + [[float(v.start)] * 2 for v in inputs])
    options = f"StepSize,{step!r}\nStartTime,{start!r}\nStopTime,{stop!r}\nRelTol,0.0001\n"
    readme = (f"# {model}\n\n{md.description}\n\nWritten by `fraccontact export --cross-check` "
              f"(fraccontact {package_version()}, docs/export.md): the reference is fmpy's run of this FMU on "
              f"x86_64 Linux from {start:g} s to {stop:g} s, a communication step of {step:g} s, its inputs held "
              "at their start values.\n")
    with zipfile.ZipFile(fmu) as z:
        binaries = {n.split("/")[1] for n in z.namelist() if n.startswith("binaries/") and n.count("/") >= 2}
    fmi = md.fmiVersion
    written = []
    for platform in CROSS_CHECK_PLATFORMS[int(fmi[0])]:
        if platform not in binaries:
            continue
        place = pathlib.Path(folder, "fmus", fmi, "cs", platform, "fraccontact", package_version(), model)
        place.mkdir(parents=True, exist_ok=True)
        with replacing(place / f"{model}.fmu", "wb") as f:
            f.write(pathlib.Path(fmu).read_bytes())
        for name, text in ((f"{model}_ref.csv", reference), (f"{model}_in.csv", held),
                           (f"{model}_ref.opt", options), ("ReadMe.md", readme)):
            with replacing(place / name) as f:
                f.write(text)
        written.append(place)
    return written
