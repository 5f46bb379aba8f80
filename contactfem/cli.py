"""Command line: `contactfem list | show SCENE | run SCENE [--preset fast|paper]
[--set NAME=VALUE ...] [--json FILE] | figures | sweep | bench | equations`.

Bad input (unknown scene, unknown or out-of-range parameter) prints one line on
stderr and exits with code 2, without a traceback. A failed Newton solve exits
with code 1 and prints the residual history."""

import argparse
import json
import sys

from . import scenes
from .solver.newton import NewtonError


def parse_sets(items):
    out = {}
    for item in items or []:
        if "=" not in item:
            raise ValueError(f"--set expects NAME=VALUE, got {item!r}")
        k, v = item.split("=", 1)
        out[k.strip()] = v.strip()
    return out


def cmd_list(args):
    for name, sc in scenes.all_scenes().items():
        print(f"{name:16s} {sc.title}")


def cmd_show(args):
    sc = scenes.get_scene(args.scene)
    print(f"{sc.name}: {sc.title}")
    print(f"{'parameter':14s} {'default':>12s} {'fast':>10s} {'paper':>10s}  {'unit':10s} allowed")
    for p in sc.params:
        fast = sc.presets.get("fast", {}).get(p.name, "")
        paper = sc.presets.get("paper", {}).get(p.name, "")
        print(f"{p.name:14s} {str(p.default):>12s} {str(fast):>10s} {str(paper):>10s}  {p.unit:10s} {p.range_text()}"
              + (f"  -- {p.doc}" if p.doc else ""))
    for name, values in sc.presets.items():
        if name not in ("fast", "paper"):
            print(f"preset {name}: " + ", ".join(f"{k}={v}" for k, v in values.items()))
    if sc.notes:
        print(sc.notes)
    if sc.reports:
        print("reports: " + ", ".join(sc.reports))


def cmd_run(args):
    progress = None
    if args.progress:
        from .io import progress_bar as progress
    overrides, laws = laws_from_args(args)
    res = scenes.run_scene(args.scene, args.preset, overrides, progress=progress, **laws)
    text = json.dumps(res, indent=1)
    if args.json:
        with open(args.json, "w") as fh:
            fh.write(text)
    if args.save:
        from .io import save_run

        save_run(res, args.save)
    if args.gif:
        write_animation(res, args.gif)
    summary = {k: v for k, v in res.items() if not isinstance(v, (list, dict))}
    for k, v in summary.items():
        print(f"{k}: {v}")


def laws_from_args(args):
    """Scene overrides and the --friction / --normal law objects (fields from --set law.NAME=...)."""
    from .laws.lawfile import laws_from_options, split_sets

    overrides, law_sets = split_sets(parse_sets(args.set))
    if not (args.friction or args.normal or any(law_sets.values())):
        return overrides, {}
    params = scenes.get_scene(args.scene).resolve(args.preset, overrides)
    return overrides, laws_from_options(args.friction, args.normal, law_sets, params)


def cmd_figures(args):
    from .plots import make_all

    for path in make_all(args.preset, args.outdir, args.only):
        print(path)


def cmd_sweep(args):
    from .studies.sweep import parse_grid, sweep, write_table

    if args.jobs < 1:
        raise ValueError(f"parameter jobs = {args.jobs} is out of range: allowed [1, inf)")
    rows = sweep(args.scene, parse_grid(parse_sets(args.set)), args.preset, args.jobs, args.scheduler)
    write_table(rows, args.out)
    print(f"{len(rows)} runs -> {args.out}")


def cmd_equations(args):
    from .equations import markdown_table

    print(markdown_table())


def cmd_reconstruct(args):
    from .studies.reconstruct import main as reconstruct

    reconstruct(args.scene, quick=args.quick, top=args.top, json_path=args.json, cache=not args.no_cache)


BENCH_STUDIES = ("tangents", "work_precision", "cost", "targets")    # contactfem.studies.bench.STUDIES


def cmd_bench(args):
    """`contactfem bench [--quick] [--out DIR] [--only NAME ...]`: bench.json and BENCHMARKS.md."""
    from pathlib import Path

    from .studies.bench import run_bench, write_outputs

    res = run_bench(quick=args.quick, only=args.only,
                    progress=lambda m: print(m, file=sys.stderr, flush=True))
    old = Path(args.out) / "bench.json"
    if args.only and old.exists():                  # keep the other studies of an earlier run
        res = dict(json.loads(old.read_text()), **res)
    for path in write_outputs(res, args.out):
        print(path)


def write_animation(res, path):
    """Animate the outlines a scene recorded (rings, the cork) into a GIF or MP4."""
    from .io import animate_outlines

    if not res.get("outlines"):
        raise ValueError(f"--gif: scene {res['scene']} records no outlines to animate")
    import numpy as np

    frames = [[np.asarray(f)] if np.asarray(f).ndim == 2 else [np.asarray(p) for p in f] for f in res["outlines"]]
    animate_outlines(frames, path, times=res.get("outline_t"), closed=True,
                     obstacles=res.get("obstacles", ()), title=res["scene"])
    print(f"animation -> {path}")


def build_parser():
    ap = argparse.ArgumentParser(prog="contactfem", description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="command", required=True)
    sub.add_parser("list", help="the scenes").set_defaults(func=cmd_list)
    sp = sub.add_parser("show", help="a scene's parameters with defaults, units and allowed ranges")
    sp.add_argument("scene")
    sp.set_defaults(func=cmd_show)
    rp = sub.add_parser("run", help="run a scene")
    rp.add_argument("scene")
    rp.add_argument("--preset", default="fast",
                    help="fast (default), paper, or a named variant of the scene (listed by show)")
    rp.add_argument("--set", action="append", metavar="NAME=VALUE",
                    help="override a parameter, or a field of a law file's law as law.NAME=VALUE (repeatable)")
    rp.add_argument("--friction", metavar="FILE.py:CLASS", help="use the friction law CLASS defined in FILE.py")
    rp.add_argument("--normal", metavar="FILE.py:CLASS", help="use the normal law CLASS defined in FILE.py")
    rp.add_argument("--json", metavar="FILE", help="write all results to FILE as JSON")
    rp.add_argument("--gif", metavar="FILE", help="animate the recorded outlines (.gif, or .mp4 with ffmpeg)")
    rp.add_argument("--progress", action="store_true", help="show a progress bar on stderr during the time loop")
    rp.add_argument("--save", metavar="FILE", help="save the run (.json or .npz) for contactfem.io.load_run")
    rp.set_defaults(func=cmd_run)
    fp = sub.add_parser("figures", help="regenerate every figure and table of the paper into figures/")
    fp.add_argument("--preset", default="fast", choices=["fast", "paper"])
    fp.add_argument("--outdir", default=None, help="default: the repo's figures/ folder")
    fp.add_argument("--only", default=None, help="only figures whose file name contains this text")
    fp.set_defaults(func=cmd_figures)
    sub.add_parser("equations", help="the equation index: paper equation -> implementing function"
                   ).set_defaults(func=cmd_equations)
    sw = sub.add_parser("sweep", help="run a scene over a grid of parameter values, in parallel")
    sw.add_argument("scene")
    sw.add_argument("--preset", default="fast", choices=["fast", "paper"])
    sw.add_argument("--set", action="append", metavar="NAME=V1,V2,...", help="values of a parameter (repeatable)")
    sw.add_argument("--jobs", type=int, default=1, help="local worker processes (joblib)")
    sw.add_argument("--scheduler", default=None, help="Dask scheduler address: run on that cluster instead")
    sw.add_argument("--out", default="sweep.csv", help="table of results (.csv or .json)")
    sw.set_defaults(func=cmd_sweep)
    rc = sub.add_parser("reconstruct", help="the scan's lost values as an inverse problem: run every reading "
                        "the scan allows, score it against what the paper prints, print the ranked table")
    rc.add_argument("scene", help="block | sloping_impact")
    rc.add_argument("--quick", action="store_true", help="a small profile of the search (seconds)")
    rc.add_argument("--top", type=int, default=25, help="rows of the ranked table to print")
    rc.add_argument("--json", metavar="FILE", help="write every reading and its scores to FILE")
    rc.add_argument("--no-cache", action="store_true", help="recompute every reading (default: reuse the "
                    "results of earlier runs of the same code, in $CONTACTFEM_CACHE or ~/.cache/contactfem)")
    rc.set_defaults(func=cmd_reconstruct)
    bp = sub.add_parser("bench", help="speed against accuracy: tangents, work-precision, cost, targets "
                                      "(writes bench.json and BENCHMARKS.md)")
    bp.add_argument("--quick", action="store_true", help="fast presets and fewer points (about a minute)")
    bp.add_argument("--out", default=".", help="folder for bench.json and BENCHMARKS.md (default: .)")
    bp.add_argument("--only", action="append", choices=list(BENCH_STUDIES),
                    help="run only this study (repeatable); the other studies of DIR/bench.json are kept")
    bp.set_defaults(func=cmd_bench)
    return ap


def main(argv=None):
    ap = build_parser()
    args = ap.parse_args(argv)
    try:
        args.func(args)
    except ValueError as exc:
        print(f"contactfem: error: {exc}", file=sys.stderr)
        return 2
    except (FloatingPointError, NewtonError) as exc:   # Newton, return map, inverted elements
        print(f"contactfem: solver failed: {exc}", file=sys.stderr)
        hist = getattr(exc, "history", None)
        if hist is not None:
            print("residual history: " + " ".join(f"{r:.3e}" for r in hist), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
