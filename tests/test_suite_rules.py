"""The suite keeps its own rules: every pytest.approx states both abs= and
rel=, so that neither a default tolerance (approx's rel=1e-6 with abs=1e-12)
nor a forgotten one decides a comparison (checked on the source with the
ast module, so a new test cannot bring the habit back); a test file is
named for the code it tests, not for the issue that asked for it; and no
source file carries an issue number, which rots (the history keeps them):
a comment says what the code checks or does."""

import ast
import pathlib
import re
import subprocess

TESTS = pathlib.Path(__file__).resolve().parent
ROOT = TESTS.parent
# The sources: C and headers, Python, CMake, the SSP files, the XML and TOML
# descriptions; shell scripts by their #! line.
SOURCE_SUFFIXES = (".c", ".h", ".py", ".cmake", ".ssd", ".ssv", ".xml", ".toml")
# An issue's number as the sources wrote it: the word, singular or plural,
# in any case, then a space, a hyphen or nothing, a # or not, the digits.
ISSUE_NUMBER = re.compile(r"\bissues?[ -]?#?\d+", re.IGNORECASE)


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


def issue_numbers(lines, filename):
    """'file:line: text' for every line that carries an issue's number."""
    return [f"{filename}:{i}: {line.strip()[:100]}" for i, line in enumerate(lines, 1) if ISSUE_NUMBER.search(line)]


def is_script(path):
    with path.open("rb") as f:
        return f.read(2) == b"#!"


def sources():
    """The tracked source files: (name, lines)."""
    names = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True).stdout.split()
    for name in names:
        path = ROOT / name
        if path.is_file() and (name.endswith(SOURCE_SUFFIXES) or pathlib.PurePosixPath(name).name == "CMakeLists.txt"
                               or is_script(path)):
            yield name, path.read_text(errors="replace").splitlines()


def test_the_issue_number_check_finds_what_it_looks_for():
    """The checker itself, on lines written here in pieces (so that this
    file carries no issue number): each form found, words alike left."""
    lines = ["# " + "issue" + " 23, item 4", "Is" + "sue #14 asked", "(" + "issues" + " 10 and 12)",
             "the " + "issue" + "-12 benchmarks", "a tissue 3 mm thick", "the issue's own call", "issue_ok = 2"]
    assert issue_numbers(lines, "t.py") == ["t.py:1: " + lines[0], "t.py:2: " + lines[1], "t.py:3: " + lines[2],
                                            "t.py:4: " + lines[3]]


def test_no_source_carries_an_issue_number():
    found = [hit for name, lines in sources() for hit in issue_numbers(lines, name)]
    assert not found, "say what the code checks or does instead of the issue's number:\n" + "\n".join(found)


def test_no_test_file_is_named_for_a_defects_issue():
    """A test lives in the file named for the code it tests (test_solver.py,
    test_sweep_options.py, ...), not in one named for the defects an issue
    listed."""
    assert sorted(p.name for p in TESTS.glob("*_defects.py")) == []


def test_no_python_file_uses_a_name_it_never_defines():
    """pyflakes over the package, the reports, the tests and the build's
    scripts: a name used but never defined or imported (a helper left behind
    when a module moved) fails only when its line runs, and the reports are
    not run by CI."""
    from pyflakes import api, reporter

    class Undefined(reporter.Reporter):
        def __init__(self):
            self.found = []

        def flake(self, message):
            if "undefined name" in str(message):
                self.found.append(str(message))

        def unexpectedError(self, filename, msg):
            self.found.append(f"{filename}: {msg}")

        def syntaxError(self, filename, msg, lineno, offset, text):
            self.found.append(f"{filename}:{lineno}: {msg}")

    found = Undefined()
    api.checkRecursive([str(ROOT / d) for d in ("python", "reports", "tests", "cmake")], found)
    assert found.found == []
