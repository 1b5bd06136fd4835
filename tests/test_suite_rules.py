"""The suite keeps its own rules (issue 23, item 31): every pytest.approx
states both abs= and rel=, so that neither a default tolerance (approx's
rel=1e-6 with abs=1e-12) nor a forgotten one decides a comparison. Checked
on the source with the ast module, so a new test cannot bring the habit back."""

import ast
import pathlib

TESTS = pathlib.Path(__file__).resolve().parent


def is_approx(call):
    """pytest.approx(...) or approx(...) (imported from pytest)."""
    f = call.func
    return (isinstance(f, ast.Attribute) and f.attr == "approx" and isinstance(f.value, ast.Name)
            and f.value.id == "pytest") or (isinstance(f, ast.Name) and f.id == "approx")


def approx_without_both_tolerances(source, filename):
    """'file:line: missing abs=' for every approx call lacking abs= or rel=."""
    found = []
    for node in ast.walk(ast.parse(source, filename)):
        if isinstance(node, ast.Call) and is_approx(node):
            given = {k.arg for k in node.keywords}
            if None in given:  # approx(x, **tolerances): cannot be read here, so it must not be used
                found.append(f"{filename}:{node.lineno}: approx(**...) hides its tolerances")
                continue
            missing = [name for name in ("abs", "rel") if name not in given]
            if missing:
                found.append(f"{filename}:{node.lineno}: approx without {' and '.join(m + '=' for m in missing)}")
    return found


def test_the_check_finds_what_it_looks_for():
    """The checker itself: it must name the line of each offending form."""
    source = ("import pytest\nfrom pytest import approx\n"
              "a = pytest.approx(1.0, rel=1e-9, abs=0)\n"
              "b = pytest.approx(1.0, rel=1e-9)\n"
              "c = approx(1.0, abs=1e-3)\n"
              "d = pytest.approx(1.0)\n")
    assert approx_without_both_tolerances(source, "t.py") == [
        "t.py:4: approx without abs=", "t.py:5: approx without rel=", "t.py:6: approx without abs= and rel="]


def test_every_approx_states_abs_and_rel():
    found = []
    for path in sorted(TESTS.glob("*.py")):
        found += approx_without_both_tolerances(path.read_text(), f"tests/{path.name}")
    assert not found, "pytest.approx must state abs= and rel= (COMMON rules):\n" + "\n".join(found)
