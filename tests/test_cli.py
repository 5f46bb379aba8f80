"""The command line: list/show/run, and bad input as one clear line with exit code 2."""

import json
import subprocess
import sys

import pytest

from contactfem.cli import main
from contactfem.scenes import all_scenes


def cli(*args):
    return subprocess.run([sys.executable, "-m", "contactfem", *args], capture_output=True, text=True)


def test_list_names_every_scene():
    out = cli("list")
    assert out.returncode == 0
    for name in all_scenes():
        assert name in out.stdout


@pytest.mark.parametrize("name", sorted(all_scenes()))
def test_show_gives_defaults_units_ranges(name, capsys):
    assert main(["show", name]) == 0
    text = capsys.readouterr().out
    for p in all_scenes()[name].params:
        assert p.name in text


@pytest.mark.parametrize("args,needle", [
    (["show", "no_such_scene"], "unknown scene 'no_such_scene'"),
    (["run", "no_such_scene"], "unknown scene 'no_such_scene'"),
    (["run", "block", "--set", "no_such=1"], "unknown parameter 'no_such'"),
    (["run", "block", "--set", "c_T=-5"], "parameter c_T = -5 is out of range"),
    (["run", "block", "--set", "mu=abc"], "parameter mu must be a number"),
    (["run", "block", "--set", "law=magic"], "parameter law = 'magic' is not allowed"),
    (["run", "block", "--set", "nonsense"], "--set expects NAME=VALUE"),
])
def test_bad_input_is_one_line_exit_2(args, needle):
    out = cli(*args)
    assert out.returncode == 2, out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], out.stderr
    assert "Traceback" not in out.stderr


def test_run_writes_json_with_the_contract_keys(tmp_path):
    path = tmp_path / "block.json"
    assert main(["run", "block", "--json", str(path)]) == 0
    res = json.loads(path.read_text())
    for key in ("wall_time_s", "newton_iterations_total", "parameters"):
        assert key in res
    assert res["parameters"]["c_T"] > 0


def test_bench_only_keeps_the_other_studies_of_an_earlier_run(tmp_path, monkeypatch):
    """`bench --only NAME` merges into DIR/bench.json: the earlier studies stay."""
    import contactfem.lab.bench as bench

    (tmp_path / "bench.json").write_text(json.dumps({"machine": {"cpu": "x"}, "tangents": {"kept": 1}}))
    monkeypatch.setattr(bench, "run_bench", lambda quick, only, progress: {"speed": {"new": 2}})
    written = []
    monkeypatch.setattr(bench, "write_outputs", lambda res, out: written.append(res) or [])
    from contactfem.cli import main
    assert main(["bench", "--only", "speed", "--out", str(tmp_path)]) == 0
    assert written[0]["tangents"] == {"kept": 1} and written[0]["speed"] == {"new": 2}


def test_a_closed_pipe_is_not_an_error():
    """`contactfem equations | head -1`: the reader leaves early; no error line, exit 0."""
    import subprocess
    import sys
    p = subprocess.run(f"{sys.executable} -m contactfem equations | head -1", shell=True,
                       capture_output=True, text=True)
    assert p.stdout.count("\n") == 1 and p.stderr == ""


def test_a_failed_site_build_shows_sphinx_then_one_line(monkeypatch, capsys):
    import contactfem.lab.site as site

    def broken(out=None, instructor=False):
        raise RuntimeError("the site build failed (Sphinx exit code 1):\nlectures/03.ipynb:12: WARNING: undefined label")

    monkeypatch.setattr(site, "build", broken)
    with pytest.raises(SystemExit) as exit_:
        main(["site", "--out", "/tmp/nowhere"])
    assert exit_.value.code == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err[0] == "lectures/03.ipynb:12: WARNING: undefined label"
    assert err[-1] == "contactfem: error: the site build failed (Sphinx exit code 1) (Sphinx's messages above)"
    assert not any("Traceback" in line for line in err)
