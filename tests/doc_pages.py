"""The pages users copy from: the README and the guides of docs/ written by
hand (the generated reports are checked by their own tests). The README's
tests (test_readme.py, test_claims.py) read the text through here, so a
block or a sentence moved from one page to another is still run and
measured."""

import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parent.parent
GUIDES = ("README.md", "coupling.md", "fmi3.md", "ssp.md", "python.md", "solver.md", "fitting.md", "sweeps.md",
          "scenes.md", "numerics.md", "springpot.md", "variables.md", "model_exchange.md")
PAGES = {"README.md": ROOT / "README.md", **{f"docs/{name}": ROOT / "docs" / name for name in GUIDES}}


def text(page):
    return PAGES[page].read_text()


def fenced_blocks(body):
    """(section heading, language, body) of every fenced code block of a page's text."""
    blocks, heading, lines, inside = [], "", [], None
    for line in body.splitlines():
        if inside is None and line.startswith("## "):
            heading = line[3:].strip()
        elif line.startswith("```"):
            if inside is None:
                inside, lines = line[3:].strip(), []
            else:
                blocks.append((heading, inside, "\n".join(lines) + "\n"))
                inside = None
        elif inside is not None:
            lines.append(line)
    return blocks


def all_blocks():
    """(page, heading, language, body) of every page's fenced blocks."""
    return [(page, *block) for page in PAGES for block in fenced_blocks(text(page))]


def section(heading):
    """The text under '## heading' (to the next '## '), lines kept, on whichever page holds it."""
    found = [text(page).split(f"\n## {heading}", 1)[1].split("\n## ", 1)[0] for page in PAGES
             if f"\n## {heading}" in text(page)]
    assert len(found) == 1, f"'## {heading}' is on {len(found)} pages, expected one"
    return found[0]


def prose():
    """Every page's text, each sentence on one line (whitespace as one space)."""
    return " ".join(" ".join(text(page).split()) for page in PAGES)


def inline_code(body):
    """The `code spans` outside fenced blocks (where prose quotes a command)."""
    outside = re.sub(r"^```.*?^```", "", body, flags=re.S | re.M)
    return re.findall(r"`([^`\n]+)`", outside)
