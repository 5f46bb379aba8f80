"""User-facing text speaks to users: no development history ("issue 3", "issue 6")
in BENCHMARKS.md, the lectures, `contactfem show`, the help texts or the docstrings that
`help()` shows."""

import re
from pathlib import Path

from contactfem.cli import build_parser, main
from contactfem.scenes import all_scenes

REPO = Path(__file__).resolve().parents[1]
HISTORY = re.compile(r"\bissues?\s*#?\d+", re.IGNORECASE)


def user_files():
    yield REPO / "BENCHMARKS.md"  # the top page's lint: tests/test_readme.py
    yield from sorted((REPO / "lectures").glob("*.md"))  # the course plan and the lectures' texts
    yield from sorted((REPO / "lectures").glob("*.ipynb"))
    yield from sorted((REPO / "contactfem").rglob("*.py"))


def test_no_issue_numbers_in_user_text():
    """One lint of every user-facing file (not one test item a file): all offenders at once."""
    hits = {
        str(p.relative_to(REPO)): [m.group(0) for m in HISTORY.finditer(p.read_text())]
        for p in user_files()
        if p.exists()
    }
    hits = {k: v for k, v in hits.items() if v}
    assert not hits, f"user text mentions development history {hits}: say what it means to a user instead"


def test_show_has_no_issue_numbers(capsys):
    for name in sorted(all_scenes()):
        assert main(["show", name]) == 0
        text = capsys.readouterr().out
        assert not HISTORY.search(text), (name, text)


def test_help_texts_have_no_issue_numbers():
    parser = build_parser()
    texts = [parser.format_help()]
    for action in parser._subparsers._group_actions:
        texts += [sub.format_help() for sub in action.choices.values()]
    for text in texts:
        assert not HISTORY.search(text), text
