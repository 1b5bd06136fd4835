"""Every reference in the repository points inside it: a path a comment, a
docstring, a --help text or a page names (docs/x.md, scripts/x, python/...,
tests/..., solver/..., model/..., fmu_src/..., a .py file given with its directory) is
a file or folder the repository has; a "docs/model.md §n" is one of the
sections docs/model.md has; and nothing refers to the specification given
beside the clone (its folder or its two files, by the names OUTSIDE below
matches). A file renamed or split without its references fails here with
the file:line that still names it."""

import fnmatch
import pathlib
import re
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
SUFFIXES = (".c", ".h", ".py", ".md", ".xml", ".cmake", ".ssd", ".ssv", ".toml")
# Folders of the repository a path may start with (build/ holds what the
# build makes, not sources, and is not checked).
TOP = ("docs", "scripts", "python", "reports", "tests", "solver", "model", "fmu_src", "ssp", "striker", "fmi3", "cmake")
PATH = re.compile(r"(?<![\w./~$-])((?:%s)/[\w./*\[\]${}-]*)" % "|".join(TOP))
# A .py file named with a folder but not from the top (fraccontact/cosim.py,
# reports/stability.py): some file of the repository must end so.
PY_PATH = re.compile(r"(?<![\w./~$-])((?:\w+/)+\w+\.py)\b")
SECTION = re.compile(r"docs/model\.md(?:'s)? (§\d+(?:(?:-|–|, | and )§\d+)*)")
OUTSIDE = re.compile(r"\.\./shared|\bMODEL\.md|\bDESIGN\.md")
THIS = pathlib.Path(__file__).resolve()


def tracked():
    out = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    return out.split()


FILES = tracked()
FOLDERS = {str(p) for f in FILES for p in pathlib.PurePosixPath(f).parents if str(p) != "."}


def scanned():
    """The text files whose comments and strings may name a path."""
    for name in FILES:
        path = ROOT / name
        if (name.endswith(SUFFIXES) or name == "CMakeLists.txt" or name.startswith("scripts/")) \
                and path.resolve() != THIS and path.is_file():
            yield name, path.read_text(errors="replace").splitlines()


def exists(token):
    """A tracked file or folder, or a glob (tests/test_*.c, contact.[ch]) that matches one."""
    # CMake's tests/test_${name}.c, an f-string's tests/{name}: any name there
    token = re.sub(r"\$?\{[^}]*\}", "*", token.rstrip(".").rstrip("/"))
    if token.count("]") > token.count("["):  # a markdown link's [docs/x.md](...)
        token = token[:token.rindex("]")]
    if any(c in token for c in "*["):
        return bool(fnmatch.filter(FILES, token)) or any(fnmatch.fnmatch(f, token) for f in FOLDERS)
    return token in FILES or token in FOLDERS


def model_sections():
    text = (ROOT / "docs" / "model.md").read_text()
    return {int(n) for n in re.findall(r"^## (\d+)\. ", text, flags=re.M)}


def test_no_reference_leaves_the_repository():
    found = [f"{name}:{i}: {line.strip()[:120]}" for name, lines in scanned()
             for i, line in enumerate(lines, 1) if OUTSIDE.search(line)]
    assert not found, "refers to the specification outside the repository (cite docs/model.md §n):\n" + "\n".join(found)


def test_every_path_named_exists():
    missing = []
    for name, lines in scanned():
        for i, line in enumerate(lines, 1):
            for token in PATH.findall(line):
                if not exists(token):
                    missing.append(f"{name}:{i}: {token.rstrip('.')}")
            for token in PY_PATH.findall(line):
                if not token.startswith(TOP) and not any(f == token or f.endswith("/" + token) for f in FILES):
                    missing.append(f"{name}:{i}: {token}")
    assert not missing, "names a file the repository does not have:\n" + "\n".join(missing)


def test_every_model_section_cited_exists():
    sections = model_sections()
    assert sections == set(range(1, max(sections) + 1)), f"docs/model.md's sections are not 1..n: {sorted(sections)}"
    wrong = []
    for name, lines in scanned():
        for i, line in enumerate(lines, 1):
            for cited in SECTION.findall(line):
                for n in map(int, re.findall(r"§(\d+)", cited)):
                    if n not in sections:
                        wrong.append(f"{name}:{i}: docs/model.md §{n}")
    assert not wrong, f"docs/model.md has sections 1 to {max(sections)}:\n" + "\n".join(wrong)


@pytest.mark.parametrize("line, bad", [("see scripts/stability.py", True), ("see docs/nothing.md", True),
                                       ("tests/test_*.c", False), ("model/g1.[ch]", False),
                                       ("reports/gone.py", True), ("fraccontact/cosim.py", False),
                                       ("[docs/model.md](model.md)", False), ("[docs/gone.md](gone.md)", True)])
def test_the_scan_finds_what_it_should(line, bad):
    """The scanner itself, on lines written for it: it must be able to fail."""
    tokens = PATH.findall(line)
    missing = [t for t in tokens if not exists(t)]
    missing += [t for t in PY_PATH.findall(line)
                if not t.startswith(TOP) and not any(f == t or f.endswith("/" + t) for f in FILES)]
    assert bool(missing) == bad, (line, tokens, missing)


LINK = re.compile(r"\]\(([^)\s#]+)(?:#[^)]*)?\)")


def test_every_markdown_link_resolves():
    """A page's relative link ([x](model.md), [y](../README.md)) reaches a file of the repository."""
    broken = []
    for name, lines in scanned():
        if name.endswith(".md"):
            for i, line in enumerate(lines, 1):
                for target in LINK.findall(line):
                    if "://" not in target and not exists(str(pathlib.PurePosixPath(name).parent / target)
                                                            .replace("docs/../", "")):
                        broken.append(f"{name}:{i}: {target}")
    assert not broken, "links to a file the repository does not have:\n" + "\n".join(broken)
