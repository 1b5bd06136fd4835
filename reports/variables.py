"""The variables table of docs/variables.md, rendered from docs/parameters.tsv,
the one table of the model's parameters, inputs and outputs (name, kind,
type, unit, default, rule, value reference, where it appears, description).
tests/test_parameter_table.py checks the C structs, the library's table, the
solver's options, the package's names and both modelDescription.xml files
against it, and this page against its rendering."""

import pathlib

from fraccontact import atomic
from fraccontact.output import parse, parser

BEGIN, END = "<!-- variables:begin -->", "<!-- variables:end -->"
COLUMNS = ("name", "kind", "type", "unit", "default", "rule", "vr", "where", "description")


def read_table(path):
    """The rows of a parameters.tsv as dicts, in the file's order."""
    lines = pathlib.Path(path).read_text().splitlines()
    head = lines[0].split("\t")
    assert tuple(head) == COLUMNS, f"{path}: columns {head}, expected {COLUMNS}"
    rows = [dict(zip(head, line.split("\t"))) for line in lines[1:] if line.strip()]
    for i, row in enumerate(rows, 2):
        assert len(row) == len(COLUMNS), f"{path}:{i}: {len(row)} cells, expected {len(COLUMNS)}"
    return rows


def cell(text):
    return text.replace("|", "\\|")


def render(rows):
    """The markdown table between the page's markers."""
    lines = [BEGIN, "", "| name | kind | type | unit | default | rule | vr | where | description |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append("| " + " | ".join([f"`{r['name']}`"] + [cell(r[c]) for c in COLUMNS[1:]]) + " |")
    return "\n".join(lines + ["", END])


def rendered_page(page, rows):
    """page's text with its marked table replaced by rows' rendering."""
    start, end = page.find(BEGIN), page.find(END)
    if start < 0 or end < start:
        raise ValueError(f"the page has no {BEGIN} ... {END} section")
    return page[:start] + render(rows) + page[end + len(END):]


def main(argv=None, prog=None):
    args = parse(parser(prog, __doc__, out_help="the docs folder: parameters.tsv in, variables.md out (default: docs/)"),
                 argv)
    page = args.out / "variables.md"
    atomic.write_text(page, rendered_page(page.read_text(), read_table(args.out / "parameters.tsv")))
    print(f"wrote {page}")
