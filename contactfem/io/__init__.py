"""Results a student wants to look at after (or during) a run.

    runs.py      save_run(results, path) / load_run(path): a scene's results (dicts of
                 numbers, strings and numpy arrays) to .json or .npz and back, without
                 re-running; Recorder, snapshots of every k-th record of a march
    paraview.py  export_series(...), export_continuum(...), export_polyline(...): time
                 series as VTU files + a .pvd collection for ParaView (needs meshio)
    animate.py   animate_outlines(frames, "motion.gif"): body outlines over time with
                 matplotlib's PillowWriter (GIF) or FFMpegWriter (MP4)
    outputs.py   Outputs: a run's output files checked before the run, written to temporaries
                 and renamed into place together (none or all); check_output_path
    progress.py  ProgressBar: a progress bar on stderr (called with each record's t);
                 chain(...) to call several at once; progress_bar, the factory for
                 integrate(..., progress=), solver.march.watch and run_scene(..., progress=)
"""

from .animate import animate_outlines, boundary_loop
from .paraview import export_continuum, export_polyline, export_series
from .outputs import Outputs, check_output_path
from .progress import ProgressBar, chain, progress_bar
from .runs import Recorder, as_arrays, load_run, save_run

__all__ = ["save_run", "load_run", "as_arrays", "Outputs", "check_output_path", "Recorder", "boundary_loop",
           "export_series", "export_continuum", "export_polyline", "animate_outlines", "ProgressBar", "chain",
           "progress_bar"]
