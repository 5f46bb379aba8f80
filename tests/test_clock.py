"""A run's clock (contactfem/clock.py): the time spent loading modules is summed while a clock
runs (an import statement once, with the imports it triggers), and left out of a run's
wall_time_s in every entry point; the command line adds import_time_s. The clock is a fake
one here (time.perf_counter replaced by a counter the imported modules advance): no test
depends on the machine's speed."""

import builtins
import json
import sys
import types

import pytest

from contactfem import clock
from contactfem.problem import scene as base

STATE = types.ModuleType("clock_test_state")  # the fake time, advanced by the modules below
STATE.t = 0.0

MODULES = {
    "slow_outer": "import clock_test_state as s\ns.t += 1.0\nimport slow_inner\n",
    "slow_inner": "import clock_test_state as s\ns.t += 2.0\n",
    "slow_broken": "import clock_test_state as s\ns.t += 0.5\nraise ImportError('no')\n",
    "slow_other": "import clock_test_state as s\ns.t += 4.0\n",
}


@pytest.fixture
def fake_time(tmp_path, monkeypatch):
    for name, text in MODULES.items():
        (tmp_path / f"{name}.py").write_text(text)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setitem(sys.modules, "clock_test_state", STATE)
    monkeypatch.setattr(STATE, "t", 0.0)
    monkeypatch.setattr("time.perf_counter", lambda: STATE.t)
    yield STATE
    for name in MODULES:
        sys.modules.pop(name, None)


def test_an_import_is_timed_once_with_what_it_imports(fake_time):
    before = builtins.__import__
    with clock.imports_timed() as imported:
        import slow_outer  # noqa: F401

        assert imported[0] == 3.0  # 1 of its own + 2 of slow_inner, once
        import slow_outer  # noqa: F401,F811             (loaded: nothing)

        with pytest.raises(ImportError):
            import slow_broken  # noqa: F401            (a failed import is import time too)
        fake_time.t += 10.0  # time that is not an import
    assert imported[0] == 3.5
    assert builtins.__import__ is before  # the clock leaves nothing behind


def test_nested_clocks_each_see_the_imports_inside_them(fake_time):
    with clock.imports_timed() as outer:
        import slow_inner  # noqa: F401

        with clock.imports_timed() as inner:
            import slow_other  # noqa: F401
    assert (outer[0], inner[0]) == (6.0, 4.0)


def test_clocks_that_read_the_same_stop_in_any_order(fake_time):
    """Each clock stops its own accumulator, also when another one holds the same value."""
    first = clock.imports_timed()
    second = clock.imports_timed()
    a, b = first.__enter__(), second.__enter__()
    second.__exit__(None, None, None)  # both read 0: the second one stops
    import slow_inner  # noqa: F401

    first.__exit__(None, None, None)
    assert (a[0], b[0]) == (2.0, 0.0)


def test_wall_time_of_a_run_leaves_out_its_imports(fake_time, monkeypatch):
    """run_scene: a run that loads a module on first use (4 s of fake time) and computes for
    1 s reports wall_time_s = 1 s, whichever entry point calls it."""
    from contactfem import scenes

    def build(params, *, normal=None, friction=None, system_options=None):
        import slow_other  # noqa: F401

        return base.Model(systems=())

    def simulate(model, params, progress):
        fake_time.t += 1.0
        return []

    scene = base.Scene(
        name="timed",
        title="t",
        params=(base.Param("x", 1.0),),
        build=build,
        measure=lambda model, params, records: {"x": params["x"]},
        simulate=simulate,
    )
    monkeypatch.setattr(scenes, "get_scene", lambda name: scene)
    res = scenes.run_scene("timed")
    assert res["wall_time_s"] == 1.0 and "import_time_s" not in res


def test_the_command_line_reports_both(tmp_path):
    """From the command line: wall_time_s, and the process's import_time_s beside it."""
    from contactfem.cli import main

    out = tmp_path / "r.json"
    assert main(["run", "sloping_impact", "--set", "n_steps=3", "--json", str(out)]) == 0
    res = json.loads(out.read_text())
    assert res["wall_time_s"] > 0 and res["import_time_s"] >= 0


def test_a_ctrl_c_inside_an_import_is_raised_when_the_module_is_loaded(tmp_path, monkeypatch):
    """The command line's SIGINT handler holds a Ctrl-C met while a module is loaded under
    the clock until its body returns (a C extension interrupted in its own import prints a
    traceback); the module's body runs to its end, then KeyboardInterrupt (the import
    statement raises it, as an interrupted import does); a second Ctrl-C while one is held
    is raised at once. Python's import itself is not replaced."""
    import signal

    from contactfem import cli

    monkeypatch.setitem(sys.modules, "clock_test_state", STATE)
    monkeypatch.setattr(STATE, "done", [], raising=False)
    (tmp_path / "interrupted_once.py").write_text(
        "import os, signal\nimport clock_test_state as s\nos.kill(os.getpid(), signal.SIGINT)\ns.done.append(1)\n"
    )
    (tmp_path / "interrupted_twice.py").write_text(
        "import os, signal\nimport clock_test_state as s\nos.kill(os.getpid(), signal.SIGINT)\n"
        "os.kill(os.getpid(), signal.SIGINT)\ns.done.append(2)\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    old = signal.signal(signal.SIGINT, cli._on_sigint)
    importer = builtins.__import__
    try:
        with clock.imports_timed():
            assert builtins.__import__ is importer
            with pytest.raises(KeyboardInterrupt):
                import interrupted_once  # noqa: F401
            assert STATE.done == [1]  # its body ran to its end
            with pytest.raises(KeyboardInterrupt):
                import interrupted_twice  # noqa: F401
            assert STATE.done == [1]  # the second Ctrl-C stopped it at once
    finally:
        signal.signal(signal.SIGINT, old)
        cli._INTERRUPTED.clear()  # (it tells the command line an interrupt came)
        for name in ("interrupted_once", "interrupted_twice"):
            sys.modules.pop(name, None)
    assert not clock._pending[0]
