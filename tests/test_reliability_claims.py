"""Figures of docs/reliability.md that every build measures again, not only
its report (scripts/report reliability): each test finds its sentence, reads
the figures as written there, and measures them on this build. A figure
that drifts, or a sentence reworded without its test, fails here."""

import json
import os
import pathlib
import re
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
PAGE = " ".join((ROOT / "docs" / "reliability.md").read_text().split())
SOAK = os.environ.get("FRACCONTACT_SOAK", str(ROOT / "build" / "fraccontact-soak"))


def claim(pattern):
    m = re.search(pattern, PAGE)
    assert m, f"docs/reliability.md no longer says {pattern!r}: update the sentence's test with it"
    return m.groups()


@pytest.mark.skipif(os.environ.get("FRACCONTACT_SANITIZED") == "1",
                    reason="AddressSanitizer's redzones and shadow memory are resident memory too")
def test_the_memory_per_instance_is_what_an_instance_holds():
    """The resident memory per FMU instance, as fraccontact-soak measures it
    with that many instances alive, rounded to the page's digits; and the
    page's account of it: the contact model twice (its size and its modes
    read from the build), with less than a page of memory besides."""
    count, kib, model, modes = claim(r"\*\*([\d,]+) instances alive at once\*\*.*? \(([\d.]+) KiB per instance: "
                                     r"an instance holds the contact model twice, its state and its prediction of "
                                     r"the next communication step, ([\d,]+) B each, most of it the compressed "
                                     r"memory's arrays for (\d+) modes, whatever the damper\)")
    done = subprocess.run([SOAK, "instances", count.replace(",", "")], capture_output=True, text=True, check=True)
    measured = json.loads(done.stdout)
    assert (measured["bytes_contact_model"], measured["max_modes"]) == (int(model.replace(",", "")), int(modes))
    decimals = len(kib.partition(".")[2])
    assert f"{measured['kib_per_instance']:.{decimals}f}" == kib, f"measured {measured['kib_per_instance']} KiB"
    per_instance = measured["kib_per_instance"] * 1024
    assert 2 * measured["bytes_contact_model"] <= per_instance < 2 * measured["bytes_contact_model"] + 4096
