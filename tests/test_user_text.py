"""User-facing text speaks to users: no development history ("issue 3", "issue 6")
in the README, the lectures, `contactfem show`, the help texts or the docstrings that
`help()` shows."""

import re
from pathlib import Path

import pytest

from contactfem.cli import build_parser, main
from contactfem.scenes import all_scenes

REPO = Path(__file__).resolve().parents[1]
HISTORY = re.compile(r"\bissues?\s*#?\d+", re.IGNORECASE)


def user_files():
    yield from (REPO / f for f in ("README.md", "BENCHMARKS.md", "lectures/README.md"))
    yield from sorted((REPO / "lectures").glob("*.ipynb"))
    yield from sorted((REPO / "contactfem").rglob("*.py"))


@pytest.mark.parametrize("path", list(user_files()), ids=lambda p: str(p.relative_to(REPO)))
def test_no_issue_numbers_in_user_text(path):
    if not path.exists():
        pytest.skip(f"{path.name} not in this checkout")
    hits = [m.group(0) for m in HISTORY.finditer(path.read_text())]
    assert not hits, f"{path.relative_to(REPO)} mentions {hits}: say what it means to a user instead"


@pytest.mark.parametrize("name", sorted(all_scenes()))
def test_show_has_no_issue_numbers(name, capsys):
    assert main(["show", name]) == 0
    text = capsys.readouterr().out
    assert not HISTORY.search(text), text


def test_help_texts_have_no_issue_numbers():
    parser = build_parser()
    texts = [parser.format_help()]
    for action in parser._subparsers._group_actions:
        texts += [sub.format_help() for sub in action.choices.values()]
    for text in texts:
        assert not HISTORY.search(text), text
