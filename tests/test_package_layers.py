"""The package apart from its tools: the wheel installs python/fraccontact
alone, which holds no report and imports none (the reports, under reports/,
run from the source tree and import the package), and the package's modules
import one another in layers: none imports from one that imports it back."""

import ast
import pathlib
import re
import tomllib

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "python" / "fraccontact"
REPORTS = ROOT / "reports"


def module_name(path):
    """fraccontact.fit.report for python/fraccontact/fit/report.py; a package by its folder's name."""
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imported(path):
    """The absolute names a module imports (at its top or inside a function):
    `from . import a, b` gives the package's a and b, `from .x import y` gives x."""
    name = module_name(path)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            yield from (a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0:
            yield node.module
        elif isinstance(node, ast.ImportFrom):
            base = ".".join(package.split(".")[:len(package.split(".")) - node.level + 1])
            if node.module:
                yield f"{base}.{node.module}"
            else:
                yield from (f"{base}.{a.name}" for a in node.names)


def unit(name):
    """The part of the package a module belongs to: a module of its top
    folder or a subpackage (fit, sweep, scenes); "" for the package's
    __init__ and the names it defines (fmu_path)."""
    first = name.split(".")[1] if name.count(".") else ""
    return first if (PACKAGE / first).is_dir() or (PACKAGE / f"{first}.py").exists() else ""


def unit_graph():
    """{unit: the other units it imports from}."""
    graph = {}
    for path in PACKAGE.rglob("*.py"):
        here = unit(module_name(path))
        for name in imported(path):
            if name.split(".")[0] == "fraccontact" and unit(name) != here:
                graph.setdefault(here, set()).add(unit(name))
    return graph


def cycle(graph):
    """A list of nodes a, b, ..., a, each importing the next, or None when the graph has no cycle."""
    done = set()  # nodes from which no cycle is reached

    def search(node, path):
        for after in sorted(graph.get(node, ())):
            if after in path:
                return path[path.index(after):] + [after]
            if after not in done and (found := search(after, path + [after])):
                return found
        done.add(node)
        return None
    for node in sorted(graph):
        if node not in done and (found := search(node, [node])):
            return found
    return None


@pytest.mark.parametrize("graph, has_cycle", [({"a": {"b"}, "b": {"c"}}, False), ({"a": {"b"}, "b": {"a"}}, True),
                                              ({"a": {"b"}, "b": {"c"}, "c": {"a"}}, True),
                                              ({"a": {"b", "c"}, "b": {"c"}}, False)])
def test_the_cycle_search_finds_a_cycle_where_there_is_one(graph, has_cycle):
    found = cycle(graph)
    assert (found is not None) == has_cycle
    if found:
        assert found[0] == found[-1] and all(b in graph[a] for a, b in zip(found, found[1:]))


def test_the_search_sees_the_packages_imports():
    """The graph the next test judges has the imports it should: fit's
    output helpers, and the lazy import of the omsimulator in ssp."""
    graph = unit_graph()
    assert "output" in graph["fit"] and "omsimulator" in graph["ssp"] and "" in graph["output"]


def test_no_part_of_the_package_imports_from_one_that_imports_it_back():
    assert cycle(unit_graph()) is None


def test_no_package_module_imports_the_reports():
    importers = [module_name(p) for p in PACKAGE.rglob("*.py")
                 if any(name.split(".")[0] == "reports" or unit(name) == "reports" for name in imported(p))]
    assert importers == []


def test_the_wheel_holds_the_package_and_no_report():
    """The wheel installs python/fraccontact (pyproject's wheel.packages) and
    the build's files CMake installs into it: none of them a report or the
    reports' folder."""
    packages = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["scikit-build"]["wheel"]["packages"]
    assert packages == ["python/fraccontact"]
    assert not (PACKAGE / "reports").exists()
    assert not REPORTS.resolve().is_relative_to(PACKAGE.resolve())
    installed = re.findall(r"install\((.*?)\)", (ROOT / "CMakeLists.txt").read_text(), re.S)
    assert installed and not any("reports" in rule for rule in installed)
    reports = {p.stem for p in REPORTS.glob("*.py")} - {"__init__", "__main__", "h20_drop"}
    assert reports and not reports & {p.stem for p in PACKAGE.rglob("*.py")}
