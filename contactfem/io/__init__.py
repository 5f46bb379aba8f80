"""Results a student wants to look at after (or during) a run.

runs.py      save_run(results, path) / load_run(path): a scene's results (dicts of
             numbers, strings and numpy arrays) to .json or .npz and back, without
             re-running; compare_runs(mine, ref), the largest relative difference of two
             results; Recorder, snapshots of every k-th record of a march;
             save_record(record, path) / load_record(path): one record of a march with
             its SystemState, to resume the run from (solver.march.resume)
paraview.py  export_series(...), export_continuum(...), export_polyline(...): time
             series as VTU files + a .pvd collection for ParaView (needs meshio)
animate.py   animate_outlines(frames, "motion.gif"): body outlines over time with
             matplotlib's PillowWriter (GIF) or FFMpegWriter (MP4)
outputs.py   Outputs: a run's output files checked before the run, written to temporaries
             and renamed into place together (none or all); check_output_path,
             check_output_dir
progress.py  ProgressBar: a progress bar on stderr (called with each record's t);
             chain(...) to call several at once; progress_bar, the factory for
             integrate(..., progress=), solver.march.watch and run_scene(..., progress=)
"""

from ..lazy import attach

# each name from its module, loaded on first use (PEP 562): checking an output path
# (outputs.py) loads neither scikit-fem nor matplotlib
_WHERE = {
    "animate_outlines": "animate",
    "boundary_loop": "animate",
    "export_continuum": "paraview",
    "export_polyline": "paraview",
    "export_series": "paraview",
    "Outputs": "outputs",
    "check_output_path": "outputs",
    "check_output_dir": "outputs",
    "ProgressBar": "progress",
    "chain": "progress",
    "progress_bar": "progress",
    "Recorder": "runs",
    "as_arrays": "runs",
    "load_run": "runs",
    "save_run": "runs",
    "compare_runs": "runs",
    "save_record": "runs",
    "load_record": "runs",
}

__all__ = [
    "save_run",
    "load_run",
    "save_record",
    "load_record",
    "compare_runs",
    "as_arrays",
    "Outputs",
    "check_output_path",
    "check_output_dir",
    "Recorder",
    "boundary_loop",
    "export_series",
    "export_continuum",
    "export_polyline",
    "animate_outlines",
    "ProgressBar",
    "chain",
    "progress_bar",
]


__getattr__, __dir__ = attach(__name__, _WHERE, globals())
