"""README.md is what its generator makes of the committed data (contactfem/lab/readme.py): every number
it states from a run sits in a generated block. The one test file that reads it."""

from pathlib import Path

import pytest

from contactfem.cli import main
from contactfem.lab import readme as R

REPO = Path(__file__).resolve().parents[1]
TEXT = (REPO / "README.md").read_text()


def test_the_readme_is_the_generators_output():
    assert R.readme(REPO) == TEXT, (
        f"README.md's block {R.first_difference(REPO)!r} is not what the committed data give: run `contactfem readme`"
    )


def test_every_block_is_in_the_readme_once():
    names = [name for name, _ in R.blocks(TEXT)]
    assert sorted(names) == sorted(R.BLOCKS)


@pytest.mark.parametrize("name", sorted(R.BLOCKS))
def test_a_changed_number_is_found_and_named(name):
    """A README whose block ``name`` has one digit changed differs from the generator's output, and the
    check names that block."""
    held = dict(R.blocks(TEXT))[name]
    digit = next((i for i, c in enumerate(held) if c.isdigit()), None)
    if digit is None:
        pytest.skip(f"block {name} holds no digit")
    altered = held[:digit] + str((int(held[digit]) + 1) % 10) + held[digit + 1 :]
    start = f"<!-- {name}:start -->"
    text = TEXT.replace(start + held, start + altered)
    assert text != TEXT
    assert R.first_difference(REPO, text) == name
    assert R.filled(text, REPO) == TEXT  # filling it again restores it


def test_unknown_and_missing_blocks_are_refused():
    with pytest.raises(ValueError, match="no function builds: nosuch"):
        R.first_difference(REPO, TEXT + "<!-- nosuch:start -->1<!-- nosuch:end -->")
    name = sorted(R.BLOCKS)[0]
    without = TEXT.replace(f"<!-- {name}:start -->", "").replace(f"<!-- {name}:end -->", "")
    with pytest.raises(ValueError, match=f"each block once: {name}"):
        R.first_difference(REPO, without)


def test_the_command_checks_and_writes(tmp_path, monkeypatch, capsys):
    """`contactfem readme --check` exits 0 on the committed README; on an altered one it exits 1 naming the
    block and writes nothing; `contactfem readme` writes it back."""
    assert main(["readme", "--check"]) == 0
    held = dict(R.blocks(TEXT))["summary"]
    altered = TEXT.replace(held, held.replace("| ", "|  ", 1))
    fake = tmp_path / "README.md"
    fake.write_text(altered)
    for entry in REPO.iterdir():  # the repository's data beside the altered copy
        if entry.name != "README.md":
            (tmp_path / entry.name).symlink_to(entry)
    monkeypatch.setattr(R, "checkout", lambda: tmp_path)
    capsys.readouterr()
    assert main(["readme", "--check"]) == 1
    assert "'summary'" in capsys.readouterr().err
    assert fake.read_text() == altered
    assert main(["readme"]) == 0
    assert fake.read_text() == TEXT


def test_no_issue_numbers():
    """User text speaks to users: no development history ("issue 3") in the README."""
    import re

    assert not re.search(r"\bissues?\s*#?\d+", TEXT, re.IGNORECASE)
