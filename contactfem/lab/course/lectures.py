"""Where the course's lectures are: the notebooks in the checkout's lectures/ folder."""

from pathlib import Path

REPO = Path(__file__).resolve().parents[3]


def lecture_sources(repo=None):
    """The lecture notebooks of the checkout, in course order."""
    folder = Path(repo or REPO) / "lectures"
    if not folder.is_dir():
        raise ValueError(f"contactfem course needs a checkout of the repository: no lectures/ in {folder.parent}")
    return sorted(folder.glob("[0-9][0-9]_*.ipynb"))
