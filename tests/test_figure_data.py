"""Every figure carries its data: NAME.json beside NAME.png (plots.data), and the committed
data is what the code computes today."""

import json

import numpy as np
import pytest

from contactfem.plots import data as D


def test_save_figure_writes_the_png_and_its_numbers(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 2])
    paths = D.save_figure(fig, tmp_path / "fig99_test.png", dict(v_final=np.float64(149.3), t=np.arange(3.0)),
                          dict(mu=0.3))
    assert paths == [str(tmp_path / "fig99_test.png"), str(tmp_path / "fig99_test.json")]
    d = json.loads((tmp_path / "fig99_test.json").read_text())
    assert d == dict(figure="fig99_test", code_version=D.code_version(), parameters=dict(mu=0.3),
                     v_final=149.3, t=[0.0, 1.0, 2.0])
    assert (tmp_path / "fig99_test.png").stat().st_size > 0
    with pytest.raises(ValueError, match="reserved key"):
        D.save_figure(None, tmp_path / "x.png", dict(parameters=1), {})


def test_code_version_is_the_version_and_a_hash_of_the_sources():
    from contactfem import __version__

    v = D.code_version()
    assert v.startswith(__version__ + "+src.") and len(D.source_hash()) == 10
    assert v == D.code_version()


def test_differences_find_a_changed_number_and_ignore_roundoff_and_version():
    a = dict(figure="f", code_version="0.1.0+src.aaaa", parameters=dict(mu=0.3), v_final=149.3,
             residuals=[171.88, 3.2, 3e-12], slip=[150.0, 1e-12], n_slip=2, label="sticks", x=None)
    same = json.loads(json.dumps(a))
    same.update(code_version="0.1.0+src.bbbb", residuals=[171.88, 3.2, 6e-12], slip=[150.0, 1e-7],
                v_final=149.3 * (1 + 1e-10))
    assert D.differences(a, same) == []
    assert D.differences(a, dict(a, v_final=149.2)) == ["v_final: 149.3 in the file, 149.2 from the run"]
    assert D.differences(a, dict(a, parameters=dict(mu=0.31))) == ["parameters.mu: 0.3 in the file, 0.31 from the run"]
    assert D.differences(a, dict(a, n_slip=3)) == ["n_slip: 2 in the file, 3 from the run"]
    assert D.differences(a, dict(a, residuals=[171.88, 3.2])) == ["residuals: 3 entries in the file, 2 from the run"]
    assert D.differences(a, dict(a, label="rebounds")) == ["label: 'sticks' in the file, 'rebounds' from the run"]
    assert D.differences(a, dict(a, slip=[150.0, 1e-4])) == ["slip[1]: 1e-12 in the file, 0.0001 from the run"]
    extra = dict(a, new=1)
    del extra["x"]
    assert D.differences(a, extra) == ["x: in the file, not from the run", "new: not in the file, from the run"]
    assert D.differences(a, dict(a, v_final=149.3 * (1 + 1e-7))) != []
