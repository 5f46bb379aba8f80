"""The run as a value: what a run remembers from step to step is the SystemState the records
carry, never the bodies, contacts or loads. So marching the same model twice gives the same
records bit for bit, and a run resumed from any of its records goes on exactly as it went."""

import numpy as np
import pytest

from contactfem.io import load_record, save_record
from contactfem.scenes import get_scene
from contactfem.problem.scene import simulate
from contactfem.solver.march import resume

# every scene (the cork: two stages, shortened)
CASES = [
    ("bar_impact", {}),
    ("bar_impact", {"contact_integration": "energy_consistent"}),
    ("block", {}),
    ("cork", {"t_end": 0.0004, "n_press": 2}),
    ("block", {"law": "parabolic"}),
    ("block", {"enforcement": "augmented"}),
    ("block", {"enforcement": "lagrange"}),
    ("funnel", {}),
    ("hertz", {}),
    ("hertz", {"enforcement": "augmented"}),
    ("patch", {}),
    ("patch", {"enforcement": "lagrange"}),
    ("rolling_ring", {}),
    ("rolling_ring", {"kind": "continuum"}),
    ("sloping_impact", {}),
    ("sloping_impact", {"variant": "frictional"}),
    ("sloping_impact", {"variant": "viscoplastic"}),
    ("sloping_impact", {"contact_integration": "energy_consistent"}),
]


def same(r, q):
    """Two records equal bit for bit (Record ==: state of motion, energies, Newton's residuals, the
    SystemState), and so are the contact states both hold (a record read back holds none)."""
    assert r == q, f"record {r.k} differs from record {q.k}"
    for cs, ds in zip(r.contacts, q.contacts):
        for name in ("g_N", "t_N", "t_T"):
            if hasattr(cs, name):
                assert np.array_equal(getattr(cs, name), getattr(ds, name))


def model_of(name, over):
    scene = get_scene(name)
    params = scene.resolve("fast", over)
    return scene, params, scene.build(params)


@pytest.mark.slow
@pytest.mark.parametrize(
    "name,over", CASES, ids=[f"{n}{'-' + '-'.join(map(str, o.values())) if o else ''}" for n, o in CASES]
)
def test_marching_the_same_model_twice_gives_the_same_records(name, over):
    scene, params, model = model_of(name, over)
    first, second = simulate(model, params), simulate(model, params)
    assert len(first) == len(second) > 1
    for r, q in zip(first, second):
        same(r, q)


@pytest.mark.slow
@pytest.mark.parametrize(
    "name,over", [("sloping_impact", {"variant": "frictional"}), ("block", {"n_steps": 4}), ("rolling_ring", {})]
)
def test_a_run_resumed_from_its_kth_record_goes_on_as_it_went(name, over):
    scene, params, model = model_of(name, over)
    records = simulate(model, params)
    st = model.stage
    k = len(records) // 2
    rest = list(resume(st.stepper, st.schedule, records[k], label=st.label))
    assert len(rest) == len(records) - k - 1
    for r, q in zip(rest, records[k + 1 :]):
        same(r, q)


@pytest.mark.slow
@pytest.mark.parametrize(
    "name,over,suffix",
    [
        ("sloping_impact", {"variant": "viscoplastic"}, ".json"),
        ("bar_impact", {"enforcement": "augmented"}, ".npz"),
        ("sloping_impact", {"variant": "frictional"}, ".npz"),
        ("sloping_impact", {"accuracy": 1e-2, "n_steps": 5}, ".json"),
        ("bar_impact", {"accuracy": 1e-2}, ".npz"),
    ],
)
def test_a_run_restarted_from_its_saved_kth_record_goes_on_as_it_went(name, over, suffix, tmp_path):
    """The record saved to a file and read back (its SystemState: plastic strains, multipliers,
    contact histories, the slope a run at a tolerance carries; its step's local error, which
    sizes the next step) resumes the run exactly: the same records from k on, bit for bit."""
    scene, params, model = model_of(name, over)
    records = simulate(model, params)
    st = model.stage
    k = len(records) // 2
    loaded = load_record(save_record(records[k], tmp_path / f"record{suffix}"))
    same(loaded, records[k])
    rest = list(resume(st.stepper, st.schedule, loaded, label=st.label))
    assert len(rest) == len(records) - k - 1 > 0
    for r, q in zip(rest, records[k + 1 :]):
        same(r, q)


def test_records_compare_by_value():
    """Records of two marches of one model are equal (==, and one entry of a set), though they are
    other objects holding other arrays; a record whose u differs in one bit, or whose SystemState
    does, is not equal; a record read back from its file equals the one saved."""
    from dataclasses import replace

    from contactfem.io import load_record, save_record

    scene, params, model = model_of("block", {"n_steps": 2})
    first, second = simulate(model, params), simulate(model, params)
    assert first[2] is not second[2] and first[2].u is not second[2].u
    assert first == second and len({first[2], second[2]}) == 1
    u = first[2].u.copy()
    u[3] = np.nextafter(u[3], np.inf)
    assert replace(first[2], u=u) != first[2]
    assert replace(first[2], state=first[1].state) != first[2]
    assert first[1] != first[2]


def test_a_record_saved_and_read_back_is_equal_to_it(tmp_path):
    scene, params, model = model_of("sloping_impact", {"variant": "frictional", "n_steps": 3})
    record = simulate(model, params)[2]
    assert load_record(save_record(record, tmp_path / "r.npz")) == record


def test_resuming_a_record_on_a_model_of_another_size_names_both_sizes():
    scene, params, model = model_of("block", {"n_steps": 1})
    record = simulate(model, params)[1]
    _, _, other = model_of("block", {"n_steps": 1, "nx": 12})
    with pytest.raises(ValueError, match=rf"^record 1 holds {len(record.u)} unknowns, the model {other.system.ndof}:"):
        next(resume(other.stage.stepper, other.stage.schedule, record))


@pytest.mark.slow
@pytest.mark.parametrize("suffix", [None, ".npz"])
def test_the_cork_resumed_from_a_record_of_its_pop_goes_on_as_it_went(suffix, tmp_path):
    """The pop, the stage built from the press fit's last record, resumed from its kth record (read
    back from a file too: the gas's state, the contacts' histories): the same records from k on."""
    scene, params, model = model_of("cork", {"t_end": 0.0006, "n_press": 2})
    records = simulate(model, params)
    fit, pop = [r for r in records if r.stage == 0], [r for r in records if r.stage == 1]
    st = model.stages[1](fit[-1])
    k = len(pop) // 2
    start = pop[k] if suffix is None else load_record(save_record(pop[k], tmp_path / f"record{suffix}"))
    rest = list(resume(st.stepper, st.schedule, start, label=st.label))
    assert len(rest) == len(pop) - k - 1 > 0
    for r, q in zip(rest, pop[k + 1 :]):
        same(r, q)


def test_a_record_that_is_not_one_is_refused(tmp_path):
    from contactfem.io import save_run

    path = save_run({"x": 1.0}, tmp_path / "run.json")
    with pytest.raises(ValueError, match="not a saved record"):
        load_record(path)


def test_the_block_of_lecture_04_twice():
    """Table 1 of the block: the same residuals at a second march of the same model."""
    scene, params, model = model_of("block", {"law": "coulomb"})
    res = [r.residuals for r in simulate(model, params)[1:]]
    again = [r.residuals for r in simulate(model, params)[1:]]
    assert res == again and len(res[0]) > 2


def test_a_contact_keeps_nothing_of_a_run():
    scene, params, model = model_of("sloping_impact", {"variant": "frictional"})
    before = {c.name: dict(vars(c)) for c in model.system.contacts}
    simulate(model, params)
    for c in model.system.contacts:
        after = vars(c)
        changed = [k for k in after if after[k] is not before[c.name].get(k)]
        assert not changed, f"contact {c.name!r} changed {changed} during a run"


# -- the lectures' march cells ---------------------------------------------------------------

LECTURE_DIR = __import__("pathlib").Path(__file__).resolve().parents[1] / "lectures"


def _march_twice(name, monkeypatch):
    """Run the lecture's code cells in order up to the first one that marches (its records
    captured through contactfem.solver.march), then run that cell again in the same namespace,
    on the same model objects, as a student re-running it would: the two runs' records."""
    jupytext = pytest.importorskip("jupytext")
    import sys

    import contactfem.solver as solver

    march_module = sys.modules["contactfem.solver.march"]

    runs, real = [], march_module.march

    def recording(*args, **kwargs):
        runs.append(records := [])
        for rec in real(*args, **kwargs):
            records.append(rec)
            yield rec

    monkeypatch.setattr(solver, "march", recording)
    monkeypatch.setattr(march_module, "march", recording)
    monkeypatch.setenv("CONTACTFEM_PRESET", "fast")
    monkeypatch.chdir(LECTURE_DIR)
    cells = [c.source for c in jupytext.read(LECTURE_DIR / f"{name}.md").cells if c.cell_type == "code"]
    namespace = {"__name__": "__lecture__"}
    for source in cells:
        exec(compile(source, name, "exec"), namespace)
        if runs:
            first = list(runs)
            runs.clear()
            exec(compile(source, name, "exec"), namespace)
            return first, list(runs)
    pytest.fail(f"{name}: no cell marches")


@pytest.mark.slow
@pytest.mark.parametrize(
    "name", ["04_block", "05_rolling_ring", "06_sloping_impact", "07_funnel", "10_write_your_own_law"]
)
def test_a_lectures_march_cell_run_twice_gives_the_same_records(name, monkeypatch, tmp_path):
    monkeypatch.setenv("CONTACTFEM_FIGURES", str(tmp_path))
    first, second = _march_twice(name, monkeypatch)
    assert len(first) == len(second) >= 1
    for a, b in zip(first, second):
        assert len(a) == len(b) > 1
        for r, q in zip(a, b):
            same(r, q)


@pytest.mark.slow
def test_the_example_resumes_a_run(tmp_path, monkeypatch):
    """The example of a resumed run (examples/resume.py, shown on the front page), run as written (in a
    scratch folder): the rest of the run from its saved record 10 is the run's records 11 on."""
    import runpy
    from pathlib import Path

    monkeypatch.chdir(tmp_path)
    namespace = runpy.run_path(str(Path(__file__).resolve().parents[1] / "examples" / "resume.py"))
    rest, records = namespace["rest"], namespace["records"]
    assert len(rest) == len(records) - 11 > 0
    for r, q in zip(rest, records[11:]):
        same(r, q)


@pytest.mark.slow
def test_the_cork_twice_gives_the_same_records():
    """Both stages of the cork (press fit, then the pop built from its last record) run twice on the
    same model: the same records, each marked with its stage; the model is not changed by a run (the
    pop's neck at rest is a new master)."""
    scene, params, model = model_of("cork", {"t_end": 0.0004, "n_press": 2})
    motion = model.parts["neck"].motion
    first, second = simulate(model, params), simulate(model, params)
    assert model.parts["neck"].motion is motion is not None
    assert [r.stage for r in first] == [0] * 3 + [1] * (len(first) - 3)  # n_press = 2: k = 0, 1, 2
    assert len(first) == len(second) > 4
    for r, q in zip(first, second):
        same(r, q)


def test_start_leaves_the_system_as_it_is():
    """``System.start`` gives a SystemState and changes nothing of the System: its assembly plan is
    the cache it was built with, a run before it included."""
    scene, params, model = model_of("block", {})
    system, st = model.system, model.stage
    simulate(model, params)
    before = dict(vars(system))
    system.start(st.u0, st.t0)
    after = vars(system)
    assert after.keys() == before.keys()
    assert not [k for k in after if after[k] is not before[k]]
