"""The FMUs the package ships, found by name."""

import os
import pathlib

_HERE = pathlib.Path(__file__).resolve().parent
_FMU_VARIABLES = {"fraccontact": "FRACCONTACT_FMU", "fraccontact-fmi3": "FRACCONTACT_FMU3", "striker": "STRIKER_FMU"}


def fmu_path(name="fraccontact"):
    """The path of an FMU the package ships: fraccontact (the contact
    element), fraccontact-fmi3 (its FMI 3.0 FMU) or striker (the rigid
    striker of the co-simulation studies). $FRACCONTACT_FMU,
    $FRACCONTACT_FMU3 / $STRIKER_FMU name another build's."""
    if name not in _FMU_VARIABLES:
        raise ValueError(f"no FMU {name!r}: fraccontact, fraccontact-fmi3 or striker")
    path = pathlib.Path(os.environ.get(_FMU_VARIABLES[name]) or _HERE / f"{name}.fmu")
    if not path.exists():
        raise FileNotFoundError(f"{path} does not exist: install the package (pip install .) or build it")
    return path
