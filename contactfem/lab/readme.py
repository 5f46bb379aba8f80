"""The README's numbers, from the data the runs left in the repository.

Every number the README states from a run sits in a block between ``<!-- NAME:start -->`` and
``<!-- NAME:end -->``, and ``BLOCKS[NAME](repo)`` builds what the block holds from the committed data:
the JSON beside the figures (figures/NAME.json), the benchmarks' bench.json, the code's own tables.
The prose around the blocks is written by hand.

    readme(repo)            the README with every block filled
    first_difference(repo)  the name of the first block the README holds otherwise, or None
    write(repo)             README.md rewritten with its blocks filled; whether it changed

``contactfem readme`` writes it, ``contactfem readme --check`` names the first block that differs.
"""

import json
import re
import textwrap
from pathlib import Path

from ..plots import rounding, summary
from .bench.coverage import readme_lines
from .bench.error_bars import error_bars_sentence

MARK = re.compile(r"<!-- ([\w-]+):start -->(.*?)<!-- \1:end -->", re.S)
WIDTH = 110


def paragraph(text, indent=""):
    """One paragraph wrapped at WIDTH; lines after the first indented by ``indent``."""
    return textwrap.fill(
        " ".join(text.split()),
        WIDTH,
        subsequent_indent=indent,
        break_long_words=False,
        break_on_hyphens=False,
    )


def prose(texts):
    """Paragraphs and lists: each text wrapped; a text that starts with "- " is a list item, and the items
    of one list follow each other without a blank line."""
    out = []
    for t in texts:
        item = t.startswith("- ")
        if out and not (item and out[-1].startswith("- ")):
            out.append("")
        out.append(paragraph(t, "  " if item else ""))
    return "\n".join(out)


def lines(*texts):
    """A block of whole lines: the texts one a line, between the markers' own lines."""
    return "\n" + "\n".join(texts) + "\n"


def _json(repo, name):
    return json.loads((Path(repo) / name).read_text())


# -- the blocks ------------------------------------------------------------------------------------


def summary_block(repo):
    """The table of the paper's examples, ours beside the paper's, from the figures' JSON."""
    rows = summary.summary_table("paper", summary.committed(Path(repo) / "figures"))
    return lines(*(row.replace("](", "](figures/") for row in rows))


def rounding_block(repo):
    """The table of the numbers rounding moves, from the figures' rounding sections."""
    return lines(*rounding.table_lines(Path(repo) / "figures"))


def coverage_block(repo):
    """The coverage study's account and what the error bars cost, from bench.json."""
    bench = _json(repo, "bench.json")
    return lines(prose(readme_lines(bench["coverage"]) + [error_bars_sentence(bench["error_bars"])]))


BLOCKS = {
    "summary": summary_block,
    "rounding": rounding_block,
    "coverage": coverage_block,
}


def checkout():
    """The checkout this package lives in (the folder of its README.md)."""
    repo = Path(__file__).resolve().parents[2]
    if not (repo / "README.md").is_file():
        raise ValueError(f"{repo} has no README.md: contactfem readme works in a checkout of the repository")
    return repo


# -- filling them ----------------------------------------------------------------------------------


def blocks(text):
    """The README's blocks in order: (name, what it holds)."""
    return [(m.group(1), m.group(2)) for m in MARK.finditer(text)]


def _check_names(text):
    names = [name for name, _ in blocks(text)]
    unknown = sorted(set(names) - set(BLOCKS))
    if unknown:
        raise ValueError(f"README.md has blocks no function builds: {', '.join(unknown)}")
    missing = [name for name in BLOCKS if names.count(name) != 1]
    if missing:
        raise ValueError(f"README.md must hold each block once: {', '.join(missing)}")


def filled(text, repo):
    """``text`` with every block between its markers replaced by what ``BLOCKS`` builds."""
    _check_names(text)
    built = {name: fn(repo) for name, fn in BLOCKS.items()}
    return MARK.sub(lambda m: f"<!-- {m.group(1)}:start -->{built[m.group(1)]}<!-- {m.group(1)}:end -->", text)


def readme(repo):
    """The README of ``repo`` with every block filled from the repository's data."""
    return filled((Path(repo) / "README.md").read_text(), repo)


def first_difference(repo, text=None):
    """The name of the first block that ``text`` (default: the README) holds otherwise than the data
    give it, or None when every block is what its function builds."""
    text = (Path(repo) / "README.md").read_text() if text is None else text
    _check_names(text)
    for name, held in blocks(text):
        if held != BLOCKS[name](repo):
            return name
    return None


def write(repo):
    """README.md with its blocks filled, written in place; whether it changed."""
    path = Path(repo) / "README.md"
    old = path.read_text()
    new = filled(old, repo)
    if new != old:
        path.write_text(new)
    return new != old
