"""The command line: list/show/run, and bad input as one clear line with exit code 2."""

import importlib
import json
import re
import subprocess
import sys

import pytest

from contactfem import scenes
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


@pytest.mark.parametrize(
    "args,needle",
    [
        (["show", "no_such_scene"], "unknown scene 'no_such_scene'"),
        (["run", "no_such_scene"], "unknown scene 'no_such_scene'"),
        (["run", "block", "--set", "no_such=1"], "unknown parameter 'no_such'"),
        (["run", "blok"], "unknown scene 'blok' (did you mean 'block'?)"),
        (["run", "block", "--set", "c_n=1"], "unknown parameter 'c_n' for scene block (did you mean 'c_N'?)"),
        (["run", "block", "--friction", "coulomb", "--set", "law.m=1"], "law.m for Coulomb (did you mean 'mu'?)"),
        (["run", "block", "--set", "c_T=-5"], "parameter c_T = -5 is out of range"),
        (["run", "block", "--set", "mu=abc"], "parameter mu must be a number"),
        (["run", "block", "--set", "law=magic"], "parameter law = 'magic' is not allowed"),
        (["run", "block", "--set", "nonsense"], "--set expects NAME=VALUE"),
    ],
)
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


def test_a_file_that_was_there_is_never_replaced_silently(tmp_path, capsys):
    """An output onto a file that exists: the run writes it and says so in one line naming it; a new file, or a
    sweep resumed from its table, is not remarked on."""
    mine = tmp_path / "mine.json"
    mine.write_text("my data")
    assert main(["run", "block", "--no-error-bars", "--json", str(mine)]) == 0
    err = capsys.readouterr().err
    assert f"--json {mine}: the file that was there is replaced" in err and "parameters" in json.loads(mine.read_text())
    fresh = tmp_path / "fresh.json"
    assert main(["run", "block", "--no-error-bars", "--json", str(fresh)]) == 0
    assert "replaced" not in capsys.readouterr().err
    table = tmp_path / "grades.csv"
    table.write_text("name,grade\nalice,A\n")
    sweep = ["sweep", "block", "--no-error-bars", "--set", "p_y=100", "--out", str(table)]
    assert main(sweep) == 0
    assert f"--out {table}: the file that was there is replaced" in capsys.readouterr().err
    assert main([*sweep, "--resume"]) == 0
    assert "replaced" not in capsys.readouterr().err


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
    # the earlier study keeps the machine (and load) it ran on, whatever machine the new run records
    assert written[0]["tangents_machine"] == {"cpu": "x"}


def test_a_bench_figure_names_the_machine_its_own_study_ran_on(tmp_path, monkeypatch):
    """Two studies run at different loads: each figure's parameters carry its study's machine."""
    from contactfem.lab.bench import figures as F

    bench = {
        "quick": False,
        "machine": {"load_average": [1.0]},
        "adaptive": {},
        "adaptive_machine": {"load_average": [7.0]},
    }
    (tmp_path / "bench.json").write_text(json.dumps(bench))
    monkeypatch.setenv("CONTACTFEM_BENCH", str(tmp_path / "bench.json"))
    assert F._section("adaptive", "paper")[1]["machine"] == {"load_average": [7.0]}


def test_a_closed_pipe_is_not_an_error():
    """`contactfem equations | head -1`: the reader leaves early; no error line, exit 0."""
    import subprocess
    import sys

    p = subprocess.run(
        f"{sys.executable} -m contactfem equations | head -1", shell=True, capture_output=True, text=True
    )
    assert p.stdout.count("\n") == 1 and p.stderr == ""


def test_a_failed_site_build_shows_sphinx_then_one_line(monkeypatch, capsys):
    import contactfem.lab.site as site

    def broken(out=None, instructor=False, **kwargs):
        raise RuntimeError(
            "the site build failed (Sphinx exit code 1):\nlectures/03.ipynb:12: WARNING: undefined label"
        )

    monkeypatch.setattr(site, "build", broken)
    with pytest.raises(SystemExit) as exit_:
        main(["site", "--out", "/tmp/nowhere"])
    assert exit_.value.code == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err[0] == "lectures/03.ipynb:12: WARNING: undefined label"
    assert err[-1] == "contactfem: error: the site build failed (Sphinx exit code 1) (Sphinx's messages above)"
    assert not any("Traceback" in line for line in err)


# ---- every command checks its outputs before any work -----------------------------------


def _no_work(*args, **kwargs):
    raise AssertionError("the work started before the output was checked")


@pytest.mark.parametrize(
    "argv,target,pattern",
    [
        (["site", "--out", "{file}"], ("contactfem.lab.site", "build"), r"--out .*: is a file, give a folder"),
        (["figures", "--outdir", "{file}"], ("contactfem.plots", "make_all"), r"--outdir .*: is a file, give a folder"),
        (["figures", "--outdir", "{file}/sub"], ("contactfem.plots", "make_all"), r"--outdir .*/sub: .* is a file"),
        (
            ["reconstruct", "block", "--quick", "--json", "{file}/x.json"],
            ("contactfem.lab.reconstruct", "main"),
            r"--json .*/x.json: .*a_file is a file, not a folder",
        ),
        (
            ["reconstruct", "block", "--quick", "--json", ""],
            ("contactfem.lab.reconstruct", "main"),
            r"--json: empty file name",
        ),
        (["figures", "--outdir", ""], ("contactfem.plots", "make_all"), r"--outdir: empty folder name"),
        (["site", "--out", ""], ("contactfem.lab.site", "build"), r"--out: empty folder name"),
        (
            ["reconstruct", "block", "--quick", "--json", "{dir}/r.txt"],
            ("contactfem.lab.reconstruct", "main"),
            r"--json .*r.txt: the file name must end in .json",
        ),
        (
            ["bench", "--quick", "--out", "{file}/sub"],
            ("contactfem.lab.bench", "run_bench"),
            r"--out .*/sub: .* is a file",
        ),
        (
            ["sweep", "block", "--set", "mu=0.3", "--out", "{file}/sub/s.csv"],
            ("contactfem.lab.sweep", "sweep"),
            r"--out .*/sub/s.csv: .*a_file is a file, not a folder",
        ),
        (
            ["sweep", "block", "--set", "mu=0.3", "--out", ""],
            ("contactfem.lab.sweep", "sweep"),
            r"--out: empty file name",
        ),
    ],
)
def test_every_command_checks_its_outputs_before_any_work(argv, target, pattern, tmp_path, monkeypatch, capsys):
    import importlib

    f = tmp_path / "a_file"
    f.write_text("")
    monkeypatch.setattr(importlib.import_module(target[0]), target[1], _no_work)
    argv = [a.format(file=f, dir=tmp_path) for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and re.search(pattern, err[0]), err


def test_one_rule_for_missing_folders(tmp_path, monkeypatch, capsys):
    """Every command's outputs make the missing folders of their path when written (the command
    line's promises): run --json as figures --outdir and site --out do; a run that writes nothing
    (refused, or failed) leaves no folder behind."""
    target = tmp_path / "a" / "b" / "r.json"
    assert main(["run", "block", "--preset", "canonical", "--json", str(target)]) == 0
    assert json.loads(target.read_text())["parameters"]["width"] == 4.0
    gone = tmp_path / "c" / "d" / "r.json"
    monkeypatch.setattr(scenes, "run_scene", lambda *a, **k: (_ for _ in ()).throw(FloatingPointError("boom")))
    assert main(["run", "block", "--json", str(gone)]) == 1
    assert not (tmp_path / "c").exists()
    made = []
    monkeypatch.setattr(
        importlib.import_module("contactfem.plots"), "make_all", lambda preset, outdir, only: made.append(outdir) or []
    )
    assert main(["figures", "--outdir", str(tmp_path / "e" / "f")]) == 0 and made == [str(tmp_path / "e" / "f")]
    capsys.readouterr()


def test_an_empty_output_name_is_refused(capsys):
    """`--json ""` is bad input naming --json (it used to write nothing and exit 0)."""
    for argv in (["run", "block", "--json", ""], ["run", "block", "--save", ""]):
        assert main(argv) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and f"{argv[-2]}: empty file name" in err[0], err


def test_help_names_every_command():
    text = cli("--help").stdout
    for name in ("list", "show", "run", "figures", "equations", "sweep", "site", "reconstruct", "bench"):
        assert re.search(rf"^    {name} +\S", text, re.M), name
    assert "reconstruct" in text.split("positional arguments")[0]  # the description names it too


def test_show_says_which_preset_its_columns_are(capsys):
    assert main(["show", "rolling_ring"]) == 0
    text = capsys.readouterr().out
    head = text.splitlines()[1].split()
    assert head[:4] == ["parameter", "fast", "(run)", "paper"]
    row = next(ln for ln in text.splitlines() if ln.startswith("dt "))
    assert row.split()[1:3] == ["0.02", "0.01"]  # the fast preset's, then where paper differs
    assert "what `contactfem run` uses unless --preset is given" in text
    assert "c_T " in text and "builds the friction law" in text
