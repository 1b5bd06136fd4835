"""Fixtures: the FMU under test (FRACCONTACT_FMU, else build/fraccontact.fmu)."""

import os
import pathlib
import shutil
import signal

import pytest
from fmpy import extract, read_model_description

from fmu_driver import Slave

ROOT = pathlib.Path(__file__).resolve().parent.parent
FMU = pathlib.Path(os.environ.get("FRACCONTACT_FMU", ROOT / "build" / "fraccontact.fmu"))


def pytest_configure(config):
    """A shell's background job ignores SIGINT, and its children inherit that:
    the suite run so would find no child stopping at the Ctrl-C its tests send.
    (Set before pytest-xdist starts its workers, which inherit it.)"""
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


@pytest.fixture(scope="session")
def fmu_path():
    if not FMU.exists():
        pytest.fail(f"{FMU} does not exist: build first (scripts/build)")
    return FMU


@pytest.fixture(scope="session")
def model_description(fmu_path):
    return read_model_description(str(fmu_path))


@pytest.fixture(scope="session")
def unzipped(fmu_path):
    folder = extract(str(fmu_path))
    yield folder
    shutil.rmtree(folder, ignore_errors=True)


@pytest.fixture
def slave(model_description, unzipped):
    """slave(start=True, **values) -> an instance with those values set
    (and initialized unless start=False); freed after the test."""
    made = []

    def make(start=True, **values):
        s = Slave(model_description, unzipped, start=start, **values)
        made.append(s)
        return s

    yield make
    for s in made:
        s.fmu.freeInstance()
