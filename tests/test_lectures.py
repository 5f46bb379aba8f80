"""Every notebook in lectures/ runs top to bottom (a failing notebook is a failed test),
is stored without outputs, and agrees with its text twin.

Each lecture is kept twice: the notebook (NN_topic.ipynb, what Jupyter opens) and the
same cells as MyST markdown (NN_topic.md, what a diff and a review read), paired by
jupytext (lectures/jupytext.toml). Edit either; `jupytext --sync lectures/NN_topic.ipynb`
(or Jupyter with jupytext installed, which saves both) brings the other in line.

Each notebook is executed with nbclient in a temporary copy of lectures/ (so nothing
is written next to the originals), with CONTACTFEM_PRESET=fast and CONTACTFEM_FIGURES
pointing to a temporary folder. The kernel is called "python3" but is defined here, in a
temporary JUPYTER_PATH, as *this* interpreter with the repository first on PYTHONPATH:
the test runs the code of this checkout, whatever kernel the machine has registered.
New notebooks are picked up automatically (glob, sorted).

A missing notebook dependency (nbformat, nbclient, ipykernel) skips these tests on a
student's machine, but FAILS them when CI=true: CI installs ".[all]", so a missing
package there is a broken install, not an optional extra.
"""

import json
import os
import shutil
import sys
from pathlib import Path

import pytest

ON_CI = os.environ.get("CI", "").lower() in ("true", "1", "yes")

REPO = Path(__file__).resolve().parents[1]
LECTURES = sorted((REPO / "lectures").glob("*.ipynb"))
TEXTS = sorted(p for p in (REPO / "lectures").glob("[0-9][0-9]_*.md"))  # the lectures' texts
CELL_TIMEOUT = 300  # seconds per cell
MAX_STORED_OUTPUT = 2000  # characters of stored output allowed per notebook ("small ones")


def require(module):
    """Import a notebook dependency: skip without it, except on CI (CI=true), where it fails."""
    if ON_CI:
        try:
            return __import__(module)
        except ImportError as err:
            pytest.fail(
                f"CI=true but the notebook dependency {module!r} is missing ({err}): install '.[all]'", pytrace=False
            )
    return pytest.importorskip(module)


def _stored_output_size(nb):
    return sum(
        len(json.dumps(c.get("outputs", []))) for c in nb["cells"] if c["cell_type"] == "code" if c.get("outputs")
    )


@pytest.fixture
def kernel_env(tmp_path, monkeypatch):
    spec = tmp_path / "jupyter" / "kernels" / "python3"
    spec.mkdir(parents=True)
    (spec / "kernel.json").write_text(
        json.dumps(
            {
                "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
                "display_name": "Python 3 (contactfem tests)",
                "language": "python",
            }
        )
    )
    monkeypatch.setenv("JUPYTER_PATH", str(tmp_path / "jupyter"))
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([str(REPO)] + [p for p in [os.environ.get("PYTHONPATH")] if p]))
    monkeypatch.setenv("CONTACTFEM_PRESET", "fast")
    monkeypatch.setenv("CONTACTFEM_FIGURES", str(tmp_path / "figures"))
    monkeypatch.setenv("MPLBACKEND", "module://matplotlib_inline.backend_inline")
    return tmp_path


def test_there_are_lectures():
    assert len(LECTURES) >= 4, f"expected the numbered course in {REPO / 'lectures'}, found {len(LECTURES)} notebooks"


@pytest.mark.parametrize("path", LECTURES, ids=[p.name for p in LECTURES])
def test_stored_without_outputs(path):
    nbformat = require("nbformat")
    nb = nbformat.read(path, as_version=4)
    nbformat.validate(nb)
    size = _stored_output_size(nb)
    assert size <= MAX_STORED_OUTPUT, f"{path.name} is stored with {size} characters of outputs: clear them"


def _cells(nb):
    return [(c.cell_type, c.source, dict(c.metadata)) for c in nb.cells]


@pytest.mark.parametrize("path", LECTURES, ids=[p.name for p in LECTURES])
def test_notebook_and_text_agree(path):
    """The notebook and its MyST twin hold the same cells: same kind, same source, same
    cell metadata (outputs and execution counts are the notebook's alone)."""
    nbformat = require("nbformat")
    jupytext = require("jupytext")
    text = path.with_suffix(".md")
    sync = f"jupytext --sync lectures/{path.name}"
    assert text.exists(), f"{path.name} has no text twin {text.name}: run `{sync}`"
    nb, md = _cells(nbformat.read(path, as_version=4)), _cells(jupytext.read(text))
    for i, (a, b) in enumerate(zip(nb, md)):
        if a != b:
            what = "kind" if a[0] != b[0] else "source" if a[1] != b[1] else "metadata"
            first = next(
                (
                    f"line {k + 1}: {x!r} in the notebook, {y!r} in the text"
                    for k, (x, y) in enumerate(zip(a[1].splitlines() + [""], b[1].splitlines() + [""]))
                    if x != y
                ),
                "",
            )
            pytest.fail(
                f"{path.name} and {text.name} differ in cell {i + 1} ({what}) {first}: edit one, then `{sync}`",
                pytrace=False,
            )
    assert len(nb) == len(md), f"{path.name} has {len(nb)} cells, {text.name} {len(md)}: edit one, then `{sync}`"


def test_every_text_has_its_notebook():
    orphans = [p.name for p in TEXTS if not p.with_suffix(".ipynb").exists()]
    assert not orphans, f"text lectures without a notebook: {orphans} (`jupytext --sync` on each makes it)"


@pytest.mark.slow
@pytest.mark.parametrize("path", LECTURES, ids=[p.name for p in LECTURES])
def test_lecture_runs(path, kernel_env):
    nbformat = require("nbformat")
    nbclient = require("nbclient")
    require("ipykernel")
    work = kernel_env / "lectures"
    shutil.copytree(REPO / "lectures", work)
    nb = nbformat.read(work / path.name, as_version=4)
    client = nbclient.NotebookClient(
        nb, timeout=CELL_TIMEOUT, kernel_name="python3", resources={"metadata": {"path": str(work)}}
    )
    try:
        client.execute()
    except nbclient.exceptions.CellExecutionError as err:
        pytest.fail(f"{path.name} failed:\n{str(err)[-4000:]}", pytrace=False)


def test_a_missing_dependency_fails_on_ci(monkeypatch):
    # the rule above, checked: on CI a missing module is a failure, elsewhere a skip
    monkeypatch.setattr(sys.modules[__name__], "ON_CI", True)
    with pytest.raises(pytest.fail.Exception, match="CI=true"):
        require("contactfem_no_such_module")
    monkeypatch.setattr(sys.modules[__name__], "ON_CI", False)
    with pytest.raises(pytest.skip.Exception):
        require("contactfem_no_such_module")
