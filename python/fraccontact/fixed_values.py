"""An exported FMU's fixed values (fraccontact export): the resources file
its binary reads at instantiation (fmu_src/glue/fixed_values.h), read back."""

import xml.etree.ElementTree as ET
import zipfile

FIXED_VALUES = "resources/fixed_values.txt"  # fmu_src/glue/fixed_values.h's file
OMIT = "omit"  # its line "omit NAME": an output the exported FMU does not offer


def fixed_of(fmu):
    """{name: value text} of an exported FMU's fixed values, and the names its modelDescription.xml has."""
    with zipfile.ZipFile(fmu) as z:
        if FIXED_VALUES not in z.namelist():
            raise ValueError(f"{fmu} is no exported FMU: it has no {FIXED_VALUES} (fraccontact export writes one)")
        lines = z.read(FIXED_VALUES).decode().splitlines()
        names = {e.get("name") for e in ET.fromstring(z.read("modelDescription.xml")).find("ModelVariables")}
    words = (line.partition("#")[0].split() for line in lines)
    return {w[0]: w[1] for w in words if len(w) == 2 and w[0] != OMIT}, names
