"""Every figure and table image that shows a fitted reading says so: FITTED and the fitted
values, taken from the run's JSON (``fitted``), in its title or a label. The figures are drawn
here (fast preset, into a temporary folder) and their text is read before saving."""

from pathlib import Path

import matplotlib
import pytest

matplotlib.use("Agg")

from contactfem.plots import block, cached_run, fitted_words, sloping_impact  # noqa: E402


def _texts(fig):
    out = [fig._suptitle.get_text()] if fig._suptitle else []
    for ax in fig.axes:
        out.append(ax.get_title())
        legend = ax.get_legend()
        if legend:
            out += [t.get_text() for t in legend.get_texts()]
    return " ".join(out)


@pytest.fixture
def drawn(monkeypatch, tmp_path):
    """Run a figure function, keeping the text of every figure it saves."""
    seen = {}

    def capture(module):
        real = module.save_figure

        def save(fig, path_png, data, parameters):
            seen[Path(path_png).stem] = _texts(fig)
            return real(fig, tmp_path / Path(path_png).name, data, parameters)

        monkeypatch.setattr(module, "save_figure", save)

    capture(block)
    capture(sloping_impact)
    return seen


@pytest.mark.slow
@pytest.mark.parametrize(
    "draw,stem,scene,over,to",
    [
        (block.fig07, "fig07_block_conical_stresses", "block", dict(law="conical"), "Table 1"),
        (block.fig08, "fig08_block_parabolic_stresses", "block", dict(law="parabolic"), "Table 1"),
        (block.table1, "table1_block_newton_residuals", "block", dict(law="conical"), "Table 1"),
        (
            sloping_impact.fig10,
            "fig10_sloping_impact_frictionless",
            "sloping_impact",
            dict(variant="frictionless"),
            "Table 2",
        ),
        (
            sloping_impact.fig11a,
            "fig11a_sloping_impact_frictional",
            "sloping_impact",
            dict(variant="frictional"),
            "Table 2",
        ),
        (sloping_impact.table2, "table2_sloping_impact", "sloping_impact", dict(variant="frictional"), "this table"),
    ],
)
def test_fitted_reading_is_labelled(drawn, tmp_path, draw, stem, scene, over, to):
    fitted = cached_run(scene, "fast", **over)["fitted"]
    assert fitted, f"{scene}: the run reports no fitted values"
    draw("fast", outdir=str(tmp_path))
    text = " ".join(drawn[stem].split())
    assert "FITTED" in text
    for key, value in fitted.items():
        assert f"{key} = " in text, f"{stem} does not name the fitted {key}"
    assert " ".join(fitted_words(dict(fitted=fitted), to).split()) in text


@pytest.mark.slow
def test_no_fitted_label_without_fitted_values(drawn, tmp_path):
    # the viscoplastic ring keeps the paper's separate element (one point): nothing fitted
    r = cached_run("sloping_impact", "fast", variant="viscoplastic")
    assert r["fitted"] == {}
    sloping_impact.fig11b("fast", outdir=str(tmp_path))
    assert "FITTED" not in drawn["fig11b_sloping_impact_viscoplastic"]
    assert fitted_words(r, "Table 2") == ""
