"""Command line: `contactfem list | show | run | figures | sweep | bench | equations | readme |
reconstruct | site | course` (`contactfem COMMAND --help` for each).

Exit codes: 0 done; 2 bad input (unknown scene, unknown, repeated, out-of-range or
inapplicable parameter, a law that breaks the protocol or returns NaN in the range the
scene meets, an output that cannot be written, a run too large for this machine), one
line on stderr, found before any solve; 1 a failed solve, its cause in one line and the
residual history on the next, or a law that returned a value no law may return during
the run (one line naming the law, the value and the point), a scene file whose own code
failed during the run (one line naming the file, the function and the line), or a sweep
with failed runs;
130 interrupted (Ctrl-C): one line saying where and what was written (a run writes none of its
output files unless all were complete; a sweep's table, written as each point ends, holds the
points done); 143 ended by SIGTERM, the same without the line.

$CONTACTFEM_READY_FILE, if set, names a file the command line creates as soon as it
answers Ctrl-C with its one line (for a supervisor, or a test, that interrupts it)."""

import contextlib
import os
import re
import signal
import sys
import time
import warnings
from pathlib import Path

_LOADING = time.perf_counter()
import argparse  # noqa: E402  (timed: the command line's own import is import time too)

from .clock import defer_interrupt, imports_timed  # noqa: E402
from . import environment, lazy

# What the commands use, loaded on first use (contactfem/lazy.py): `contactfem list` loads neither
# scipy, scikit-fem nor matplotlib, nor the plots or the lab, and the command line answers Ctrl-C
# before any of them is loaded
np = lazy.module("numpy")
json = lazy.module("json")
secrets = lazy.module("secrets")
shutil = lazy.module("shutil")
traceback = lazy.module("traceback")
scenes = lazy.module("contactfem.scenes")
equations = lazy.module("contactfem.equations")
protocol = lazy.module("contactfem.laws.protocol")
newton = lazy.module("contactfem.solver.newton")
rounding = lazy.module("contactfem.solver.rounding")
problem_scene = lazy.module("contactfem.problem.scene")
uncertainty = lazy.module("contactfem.problem.uncertainty")
accuracy = lazy.module("contactfem.problem.accuracy")
outputs = lazy.module("contactfem.io.outputs")
progress_bars = lazy.module("contactfem.io.progress")
runs = lazy.module("contactfem.io.runs")
animate = lazy.module("contactfem.io.animate")
plots = lazy.module("contactfem.plots")
plots_rounding = lazy.module("contactfem.plots.rounding")
summary = lazy.module("contactfem.plots.summary")
lawfile = lazy.module("contactfem.lab.lawfile")
sweeps = lazy.module("contactfem.lab.sweep")
bench = lazy.module("contactfem.lab.bench")
reconstruct = lazy.module("contactfem.lab.reconstruct")
readme = lazy.module("contactfem.lab.readme")
site = lazy.module("contactfem.lab.site")
course_layer = lazy.module("contactfem.lab.course")
handout = lazy.module("contactfem.lab.course.handout")

_OWN_IMPORT_S = [time.perf_counter() - _LOADING]  # counted once, by the first command of the process
_CLOCK = {}  # the import clock of the command running (contactfem.clock)


class UsageError(Exception):
    """Malformed command line (argparse's complaint), reported in one line, exit 2."""


class Parser(argparse.ArgumentParser):
    def error(self, message):
        raise UsageError(f"{message} (see {self.prog} --help)")


_RUN = {}  # what `run` is doing, for the message of an interrupt: phase, progress


def parse_sets(items):
    """["mu=0.3", ...] -> {"mu": "0.3"}; a malformed or repeated NAME is a ValueError."""
    out = {}
    for item in items or []:
        if "=" not in item:
            raise ValueError(f"--set expects NAME=VALUE, got {item!r}")
        k, v = item.split("=", 1)
        k, v = k.strip(), v.strip()
        if not k:
            raise ValueError(f"--set expects NAME=VALUE, got {item!r}")
        if k in out:
            raise ValueError(f"--set {k} is given twice ({out[k]!r} and {v!r}): give each parameter once")
        out[k] = v
    return out


def cmd_list(args):
    for name, sc in scenes.all_scenes().items():
        print(f"{name:16s} {sc.title}")


def cmd_show(args):
    sc = scenes.get_scene(args.scene)
    print(f"{sc.name}: {sc.title}")
    fast = sc.resolve("fast")
    paper = sc.resolve("paper") if "paper" in sc.presets else fast  # a scene file may have no paper preset
    rows = [("parameter", "fast (run)", "paper", "unit", "allowed")]
    for p in sc.params:
        rows.append(
            (
                p.name,
                _show_value(fast[p.name]),
                "" if paper[p.name] == fast[p.name] else _show_value(paper[p.name]),
                p.unit or "-",
                p.range_text(),
            )
        )
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    right = (False, True, True, False, False)
    for r, p in zip(rows, (None,) + tuple(sc.params)):
        cells = [c.rjust(w) if rj else c.ljust(w) for c, w, rj in zip(r, widths, right)]
        note = ""
        if p is not None:
            kind = sc.law_param_kind(p.name)
            if sc.law_choice is not None and p.name == sc.law_choice[0]:
                law = f"{'|'.join(map(str, sc.law_choice[1]))} choose the friction law"
            else:
                law = f"builds the {kind} law" if kind else ""
            note = "; ".join(x for x in (p.doc, f"used only with {p.when_text()}" if p.when else "", law) if x)
        print("  ".join(cells) + f"  -- {note}" if note else "  ".join(cells).rstrip())
    for name, values in sc.presets.items():
        if name not in ("fast", "paper"):
            print(f"preset {name}: " + ", ".join(f"{k}={v}" for k, v in values.items()))
    if sc.notes:
        print(sc.notes)
    print(
        "The column 'fast (run)' is the fast preset, what `contactfem run` uses unless --preset is given; 'paper' "
        "shows where --preset paper differs. Values: --set NAME=VALUE."
    )
    if sc.laws:
        print(
            f"Laws: {' and '.join(sc.laws)}; replace them with --friction / --normal (a law file FILE.py:CLASS, "
            "a module path or a shipped law), their fields with --set law.NAME=VALUE."
        )
    else:
        print("Laws: none to replace (no contact interface of its own).")
    if sc.reports:
        print("reports: " + ", ".join(sc.reports))
    if sc.quantities:  # what run's error bars band, and what moves each
        labels = {d.name: d.label for d in sc.discretisations}
        print(
            "headline quantities (with error bands unless --no-error-bars): "
            + "; ".join(
                f"{q.name}"
                + (f" [{q.unit}]" if q.unit else "")
                + (
                    f" ({', '.join(labels[c] for c in q.controls)})"
                    if q.controls
                    else " (no band: checked against its closed form)"
                )
                for q in sc.quantities
            )
        )


def _show_value(v):
    if v == "":
        return ""
    if isinstance(v, float):
        return f"{v:g}"
    return str(v)


def cmd_run(args):
    scene = scenes.get_scene(args.scene)
    overrides, laws, notes = laws_from_args(args)  # law.NAME=... go to --friction / --normal
    params = scene.resolve(args.preset, overrides)
    tolerance = uncertainty.check_tolerance(args.tolerance)
    error_bars = uncertainty.error_bars_default() if args.error_bars is None else args.error_bars
    out = outputs.Outputs()  # every output checked before the run
    if args.json is not None:  # (an empty name is refused, not skipped)
        out.add("--json", args.json, (".json",))
    if args.save is not None:
        out.add("--save", args.save, (".json", ".npz"))
    if args.gif is not None:
        out.add("--gif", args.gif, (".gif", ".mp4"))
        if not scene.outlines:
            animated = ", ".join(n for n, s in scenes.all_scenes().items() if s.outlines)
            raise ValueError(f"--gif: scene {scene.name} records no outlines to animate (these do: {animated})")
        if args.gif.lower().endswith(".mp4"):
            if shutil.which("ffmpeg") is None:
                raise ValueError(f"--gif {args.gif}: writing .mp4 needs ffmpeg on the PATH; write a .gif instead")
    est = problem_scene.check_resources(scene, params, args.force, args.linear_algebra)
    warnings = scene.preflight(params, laws) if laws and not args.no_check else []  # the laws over the scene's range
    for note in notes:  # (after every refusal: a refusal is one line)
        print(f"contactfem: note: {note}", file=sys.stderr)
    for warning in warnings:
        print(f"contactfem: warning: {warning}", file=sys.stderr)
    if est is not None and est.get("elements", 0) > 1e5:
        print(
            f"{scene.name}: building the mesh and the system ({problem_scene.describe(est)}) ...",
            file=sys.stderr,
            flush=True,
        )
    progress = None
    if args.progress:
        progress = progress_bars.progress_bar
        _RUN["progress"] = True
    _RUN["phase"] = "run"
    res, notes = run_quietly(
        lambda: scenes.run_scene(
            args.scene,
            args.preset,
            overrides,
            progress=progress,
            linear_algebra=args.linear_algebra,
            check=False,
            error_bars=error_bars,
            tolerance=tolerance,
            **laws,
        )
    )
    if "imported" in _CLOCK:  # what this process spent loading modules, up to here
        res["import_time_s"] = _CLOCK["imported"][0] + _CLOCK["own"]
    _RUN["phase"] = "write"
    with out:  # temporaries first, then all renamed at once
        if args.json is not None:
            out.temp("--json").write_text(json.dumps(res, indent=1, allow_nan=False))
        if args.save is not None:
            runs.save_run(runs.as_arrays(res), out.temp("--save"))
        if args.gif is not None:
            write_animation(res, out.temp("--gif"))
        written = out.commit()
    _RUN["phase"] = "done"
    for what, path, replaced in written:
        if replaced:
            print(f"contactfem: note: {what} {path}: the file that was there is replaced", file=sys.stderr)
    for note in notes:
        print(f"contactfem: warning: {note}", file=sys.stderr)
    for k, v in res.items():  # scalars, and short lists of numbers (the block's residuals)
        if not isinstance(v, (list, dict)):
            print(f"{k}: {v}")
        elif isinstance(v, list) and 0 < len(v) <= 8 and all(isinstance(x, (int, float)) for x in v):
            print(f"{k}: [{', '.join(f'{x:.6g}' for x in v)}]")
    bars = res.get("uncertainty")
    if bars and bars["quantities"]:  # each headline quantity with its band, and what the bands cost (none: no line)
        for name, entry in bars["quantities"].items():
            print(uncertainty.line(name, entry))
        unused = bars.get("unused_runs", 0)
        print(
            f"error bars: {bars['runs']} coarser or finer runs"
            + (f" ({unused} of them ran but are not used: the bands' parts say why)" if unused else "")
            + f" in {bars['wall_time_s']:.3g} s (the run alone: {res['wall_time_s']:.3g} s);"
            + f" tolerance {bars['tolerance']:g}"
        )
    for what, path in out.paths.items():
        print(f"{what} -> {path}")
    # the indicators' names (an indicator's line: "NAME = value, ..." or "NAME: no error band of ... (why)")
    flagged = [
        re.match(r"\w+", note.removeprefix("accuracy: ")).group(0) for note in notes if note.startswith("accuracy:")
    ]
    if args.strict and flagged:  # an accuracy indicator past its threshold: said last, after the results
        print(
            f"contactfem: strict: the run is flagged by {len(flagged)} accuracy warning"
            f"{'s' if len(flagged) > 1 else ''} above ({', '.join(flagged)}): exit code 1",
            file=sys.stderr,
        )
        return 1


def run_quietly(fn):
    """fn() with numpy's floating-point warnings off (a non-finite value is caught by the
    solver and reported as the cause) and other libraries' warnings dropped; returns
    (result, contactfem's own warning messages) so they are printed once, after the run."""
    with warnings.catch_warnings(record=True) as caught, np.errstate(all="ignore"):
        warnings.simplefilter("always")
        res = fn()
    own = [str(w.message) for w in caught if own_warning(w.category, w.filename)]
    return res, list(dict.fromkeys(own))


def own_warning(category, filename):
    """contactfem's warnings: every AccuracyWarning (it points at the line that asked for the run, outside the
    package), and the other UserWarnings raised in the package (or in a scene file's call into it)."""
    return issubclass(category, accuracy.AccuracyWarning) or (
        issubclass(category, UserWarning) and "contactfem" in str(filename)
    )


def laws_from_args(args, sets=None):
    """Scene overrides, the --friction / --normal law objects (fields from --set law.NAME=...)
    and the notes to print (fields a law took from the scene). Checks, before anything is
    built, that the scene has those laws and that no parameter is set that builds a law they
    replace."""
    overrides, law_sets = lawfile.split_sets(parse_sets(args.set) if sets is None else sets)
    if args.friction is None and args.normal is None and not any(law_sets.values()):
        return overrides, {}, []
    scene = scenes.get_scene(args.scene)
    classes = {
        k: lawfile.load_class(s, f"--{k}")
        for k, s in (("friction", args.friction), ("normal", args.normal))
        if s is not None
    }
    scenes.check_laws(scene, classes, overrides)
    params = scene.resolve(args.preset, overrides)
    from_scene = {k: {n: params[n] for n in scene.law_params.get(k, ()) if n in params} for k in classes}
    notes = []
    laws = lawfile.laws_from_options(args.friction, args.normal, law_sets, from_scene, notes)
    return overrides, laws, notes


def cmd_figures(args):
    outputs.check_output_dir(
        plots.default_outdir(args.preset) if args.outdir is None else args.outdir, "--outdir"
    )  # before anything heavy
    from .lab import reconstruct as _reconstruct  # noqa: F401  (imported for its effect: registers a figure)
    from .lab.bench import figures as _bench  # noqa: F401  (imported for its effect: registers the bench figures)

    if args.only and not any(args.only in stem for stem in plots.load_all()):
        raise ValueError(
            f"--only {args.only!r} matches no figure: the figures are {', '.join(sorted(plots.load_all()))}"
        )
    # an option overrides the condition in the environment (the rounding study's processes carry theirs there)
    given = rounding.current()
    condition = rounding.checked(  # before any work
        args.linear_algebra or given.linear_algebra, given.perturbation if args.perturb is None else args.perturb
    )
    if args.rounding:
        if args.preset != "paper" or condition.tag():
            raise ValueError("--rounding measures the paper preset's figures: give it with --preset paper alone")
        folder = args.outdir or plots.default_outdir("paper")
        for path in summary.reprint(folder, list(plots_rounding.study(folder, args.only))):
            print(f"{path}: redrawn from its data with the spreads recorded")
        refill_readme(folder)
        return 0
    with rounding.rounding(condition.linear_algebra, condition.perturbation):
        for path in plots.make_all(args.preset, args.outdir, args.only):
            print(path)
    refill_readme(args.outdir or plots.default_outdir(args.preset))


def refill_readme(folder):
    """After the checkout's own figures/ are written: the README's blocks filled from them (lab.readme)."""
    repo = Path(__file__).resolve().parents[1]
    if Path(folder).resolve() == (repo / "figures").resolve() and (repo / "README.md").is_file():
        if readme.write(repo):
            print(f"{repo / 'README.md'}: its blocks filled from the figures' data")


def cmd_sweep(args):
    if args.jobs < 1:
        raise ValueError(f"parameter jobs = {args.jobs} is out of range: allowed [1, inf)")
    tolerance = uncertainty.check_tolerance(args.tolerance)
    if args.time_limit is not None and not args.time_limit > 0:
        raise ValueError(f"parameter time-limit = {args.time_limit:g} is out of range: allowed (0, inf) seconds")
    if args.time_limit is not None and args.scheduler:
        raise ValueError("--time-limit applies to local workers; with --scheduler, the cluster's own limits apply")
    outputs.check_output_path(args.out, "--out", (".csv", ".json"))
    if not args.set:
        raise ValueError(
            "sweep needs at least one --set NAME=V1,V2,... (the values to sweep); for one run use contactfem run"
        )
    grid = sweeps.parse_grid(parse_sets(args.set))
    table = sweeps.Table(args.out, resume=args.resume)  # with --resume, the rows already done are read now
    replaced = not args.resume and Path(args.out).exists()  # said with the summary: never replaced silently
    _RUN.update(phase="sweep", table=table)
    with said_at_once():  # the laws' check, then each flagged point as it ends: one line each
        rows = sweeps.sweep(
            args.scene,
            grid,
            args.preset,
            args.jobs,
            args.scheduler,
            friction=args.friction,
            normal=args.normal,
            check=not args.no_check,
            force=args.force,
            table=table,
            timeout=args.time_limit,
            error_bars=uncertainty.error_bars_default() if args.error_bars is None else args.error_bars,
            tolerance=tolerance,
        )
    _RUN["phase"] = "done"
    done, failed, left = table.counts(strict=args.strict)
    flagged = table.flagged()
    kept = f" ({table.kept} kept from the table)" if table.kept else ""
    marked = f" ({len(flagged)} flagged)" if flagged and not args.strict else ""
    print(f"{len(table.points)} points: {done} done{kept}{marked}, {failed} failed, {left} left -> {args.out}")
    if replaced and table.written is not None:
        print(
            f"contactfem: note: --out {args.out}: the file that was there is replaced (--resume keeps its rows)",
            file=sys.stderr,
        )
    for r in rows:
        point = sweeps.point_text({k[6:]: v for k, v in r.items() if k.startswith("param.")})
        if r.get("error"):
            print(f"  failed: {point}: {r['error']}")
        elif r in flagged:
            what = f"accuracy flagged: {r.get('accuracy.flags') or r.get('warnings')}"
            print(f"  failed: {point}: {what}" if args.strict else f"  flagged: {point}: {what}")
    if failed:
        strict = len(flagged) if args.strict else 0
        why = ["the table's error column says why"] if failed > strict else []
        why += [f"{strict} flagged, with --strict: its accuracy.flags and warnings columns say why"] if strict else []
        print(f"contactfem: sweep: {failed} of {len(rows)} points failed ({'; '.join(why)})", file=sys.stderr)
        return 1
    return 0


@contextlib.contextmanager
def said_at_once():
    """contactfem's warnings printed as they come, one line each (`contactfem: warning: ...`);
    other libraries' dropped, as a run drops them (run_quietly)."""

    def say(message, category, filename, lineno, file=None, line=None):
        if own_warning(category, filename):
            print(f"contactfem: warning: {message}", file=sys.stderr, flush=True)

    with warnings.catch_warnings():
        warnings.simplefilter("always")
        warnings.showwarning = say
        yield


def cmd_readme(args):
    repo = readme.checkout()
    if args.check:
        name = readme.first_difference(repo)
        if name is not None:
            print(
                f"contactfem readme: README.md's block {name!r} is not what the data give: run contactfem readme",
                file=sys.stderr,
            )
            return 1
        print("README.md: every block is what the data give")
        return 0
    print(f"{repo / 'README.md'}: {'written' if readme.write(repo) else 'unchanged'}")
    return 0


def cmd_equations(args):
    table = equations.markdown_table()
    if args.markdown or not sys.stdout.isatty():
        print(table)
    else:
        print(plain_table(table))


def plain_table(markdown):
    """A Markdown table as aligned plain text for a terminal: no pipes, escapes or backquotes."""
    rows = []
    for line in markdown.splitlines():
        if re.fullmatch(r"\|?(\s*:?-+:?\s*\|)+\s*", line):
            continue
        cells = re.split(r"(?<!\\)\|", line.strip().strip("|"))
        rows.append([c.strip().replace("\\|", "|").replace("`", "") for c in cells])
    widths = [max(len(r[i]) for r in rows if i < len(r)) for i in range(max(map(len, rows)))]
    return "\n".join("  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows)


def _course_layer(otter=True):
    """The course's layer; with `otter`, the build tool of the course extra must be there (grading
    needs it not: its sandbox says what it lacks)."""
    if otter:
        try:
            import otter  # noqa: F401  (optional extra, course: may be absent)
        except ImportError:
            raise ValueError("contactfem course needs the course extra: pip install -e '.[course]'") from None
    return course_layer


def cmd_course_build(args):
    course = _course_layer()
    if args.out is not None:
        outputs.check_output_dir(args.out, "--out")
    out = course.check_out_dir(course.default_out(args.instructor) if args.out is None else args.out)
    _RUN["said"] = f"during the course build; nothing written in {out}"
    written = course.build_versions(
        {"instructor" if args.instructor else "student": out},
        force=args.force,
        on_write=lambda: _RUN.update(phase="done"),
    )
    version = (
        "instructor (solutions, check cells, autograder/)"
        if args.instructor
        else f"student (no solutions; the handout: {out / handout.STUDENT_ZIP})"
    )
    print(f"{len(next(iter(written.values())))} lectures, {version} -> {out}")


def cmd_course_grade(args):
    course = _course_layer(otter=False)
    limits = course.Limits(
        notebook=args.notebook_timeout,
        check=args.check_timeout,
        memory=int(args.memory * 2**20) if args.memory else None,
    )
    outputs.make_parents(
        outputs.check_output_path(args.out, "--out", (".csv",))
    )  # the table's folder, as every output's
    seed = secrets.randbits(63) if args.seed is None else args.seed  # said at the end: --seed repeats the grading
    t0 = time.perf_counter()

    def progress(done, total):
        print(f"\r{done} of {total} notebooks graded", end="\n" if done == total else "", file=sys.stderr, flush=True)

    try:
        rows = course.grade(
            args.folder,
            args.out,
            autograders=args.autograders,
            jobs=args.jobs,
            roster=args.roster,
            deadline=args.deadline,
            lecture=args.lecture,
            limits=limits,
            review=args.review,
            feedback=args.feedback,
            progress=progress if sys.stderr.isatty() else None,
            seed=seed,
            unsafe_no_sandbox=args.unsafe_no_sandbox,
        )
    except course.GradingInterrupted as exc:
        print(f"\ncontactfem: {exc.message}" if sys.stderr.isatty() else f"contactfem: {exc.message}", file=sys.stderr)
        return 130
    count = {s: sum(1 for r in rows if r["status"] == s) for s in ("graded", "stopped", "not graded", "missing")}
    what = ", ".join(f"{n} {s}" for s, n in count.items() if n)
    print(f"{len(rows)} rows ({what}) in {time.perf_counter() - t0:.0f} s, hidden checks' seed {seed} -> {args.out}")


def cmd_site(args):
    out = site.check_out(site.default_out(args.instructor) if args.out is None else args.out)
    pages = f"the site in {out} is unchanged" if (out / "index.html").exists() else f"no page written in {out}"

    def said():  # read when the interrupt is reported, after the clean-up
        cache = site.work_dir(out) / "cache"
        return f"during the site build; {pages}" + (
            f" (notebooks executed so far are cached in {site.work_dir(out)})" if cache.is_dir() else ""
        )

    _RUN["said"] = said
    try:
        index = site.build(out, instructor=args.instructor, on_write=lambda: _RUN.update(phase="done"))
    except RuntimeError as err:  # Sphinx's own messages, then one line of ours
        head, _, detail = str(err).partition("\n")
        head = head.rstrip(":")
        if detail.strip():
            print(detail.rstrip(), file=sys.stderr)
        print(f"contactfem: error: {head}" + (" (Sphinx's messages above)" if detail.strip() else ""), file=sys.stderr)
        raise SystemExit(1) from None
    print(f"site -> {index}")


def cmd_reconstruct(args):
    if args.json is not None:
        outputs.check_output_path(args.json, "--json", (".json",))  # before anything heavy
    reconstruct.main(args.scene, quick=args.quick, top=args.top, json_path=args.json, cache=not args.no_cache)


BENCH_STUDIES = (
    "tangents",
    "work_precision",
    "cost",
    "targets",
    "enforcement",
    "speed",
    "semismooth",
    "scaling",
    "coverage",
    "adaptive",
    "error_bars",
)  # = lab.bench.STUDIES


def cmd_bench(args):
    """`contactfem bench [--quick] [--out DIR] [--only NAME ...]`: bench.json and BENCHMARKS.md."""
    out = ("bench-quick" if args.quick else ".") if args.out is None else args.out
    if Path(out).exists() and not Path(out).is_dir():
        raise ValueError(f"--out {out}: is a file; give a folder (it gets bench.json and BENCHMARKS.md)")
    outputs.check_output_dir(out, "--out")
    old = Path(out) / "bench.json"
    earlier = None
    if old.exists():
        try:
            earlier = json.loads(old.read_text())
        except ValueError:
            earlier = None
    if earlier is not None and bool(earlier.get("quick")) != bool(args.quick):
        kind = "a quick" if earlier.get("quick") else "a full"
        raise ValueError(
            f"--out {out}: {old} holds {kind} bench run; a {'quick' if args.quick else 'full'} run "
            "would replace or mix with it: write it to another folder (--out DIR)"
        )
    res = bench.run_bench(quick=args.quick, only=args.only, progress=lambda m: print(m, file=sys.stderr, flush=True))
    if args.only and earlier is not None:  # keep the other studies of an earlier run (those the bench still has)
        meta = ("quick", "machine", "target_values")
        kept = {
            k: v
            for k, v in earlier.items()
            if k in meta or k.removesuffix("_bench_s").removesuffix("_machine") in bench.STUDIES
        }
        for name in bench.STUDIES:  # an earlier study keeps the machine (and its load) it ran on
            if name in kept and f"{name}_machine" not in kept and "machine" in earlier:
                kept[f"{name}_machine"] = earlier["machine"]
        res = dict(kept, **res)
    for path in bench.write_outputs(res, out):
        print(path)


def write_animation(res, path):
    """Animate the outlines a scene recorded (rings, the cork) into a GIF or MP4."""
    if not res.get("outlines"):
        raise ValueError(f"--gif: scene {res['scene']} records no outlines to animate")
    anim = res.get("animation") or {}
    outlines = anim.get("outlines", res["outlines"])
    frames = [[np.asarray(f)] if np.asarray(f).ndim == 2 else [np.asarray(p) for p in f] for f in outlines]
    animate.animate_outlines(
        frames,
        path,
        times=anim.get("t", res.get("outline_t")),
        closed=True,
        obstacles=anim.get("obstacles", res.get("obstacles", ())),
        title=res["scene"],
        marks=anim.get("marks"),
    )
    return path


def add_error_bar_options(parser):
    """--no-error-bars and --tolerance, as run and sweep take them."""
    bars = parser.add_mutually_exclusive_group()
    bars.add_argument(
        "--no-error-bars",
        dest="error_bars",
        action="store_false",
        default=None,
        help="skip the error bands of the headline quantities (by default each comes with its numerical "
        "uncertainty, from runs at coarser steps and meshes: the JSON's uncertainty section)",
    )
    bars.add_argument(
        "--error-bars",
        dest="error_bars",
        action="store_true",
        default=None,
        help="the error bands even where the environment variable CONTACTFEM_ERROR_BARS is off",
    )
    parser.add_argument(
        "--tolerance",
        type=float,
        default=0.05,
        metavar="TOL",
        help="the run's tolerance, in (0, 1] (default 0.05): the relative error band (and error against a closed "
        "form) past which a headline quantity warns, and the error the time-resolution indicators (impact_steps, "
        "penalty_steps) hold the integrator to; --strict makes a warning exit 1",
    )


def build_parser():
    ap = Parser(prog="contactfem", description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="command", required=True)
    sub.add_parser("list", help="the scenes").set_defaults(func=cmd_list)
    sp = sub.add_parser("show", help="a scene's parameters with defaults, units and allowed ranges")
    sp.add_argument("scene")
    sp.set_defaults(func=cmd_show)
    rp = sub.add_parser("run", help="run a scene")
    rp.add_argument("scene")
    rp.add_argument(
        "--preset",
        default="fast",
        help="fast (default): coarse meshes and steps, seconds; paper: the paper's data; "
        "or a named variant of the scene (listed by show)",
    )
    rp.add_argument(
        "--set",
        action="extend",
        nargs="+",
        metavar="NAME=VALUE",
        help="override parameters, or fields of the --friction / --normal law as law.NAME=VALUE "
        "(friction.NAME, normal.NAME where both laws have it); several after one --set, or "
        "--set repeated",
    )
    rp.add_argument(
        "--friction",
        metavar="LAW",
        help="replace the scene's friction law: FILE.py:CLASS (a law file), "
        "package.module:CLASS, or a shipped law (coulomb, parabolic_slip, slip_hardening, frictionless, "
        "stribeck, dieterich_ruina, archard_wear)",
    )
    rp.add_argument(
        "--normal",
        metavar="LAW",
        help="replace the scene's normal law: FILE.py:CLASS, "
        "package.module:CLASS, or a shipped law (power_law, exponential_law)",
    )
    rp.add_argument(
        "--no-check",
        action="store_true",
        help="skip the check of the --friction / --normal law over the range the scene meets before "
        "solving (the values it returns are still checked during the run)",
    )
    rp.add_argument("--json", metavar="FILE", help="write all results to FILE as JSON")
    rp.add_argument("--gif", metavar="FILE", help="animate the recorded outlines (.gif, or .mp4 with ffmpeg)")
    rp.add_argument("--progress", action="store_true", help="show a progress bar on stderr during the time loop")
    rp.add_argument(
        "--linear-algebra",
        default=None,
        choices=["auto", "dense", "banded", "sparse"],
        help="how K is stored and factorised (default auto: dense up to 100 unknowns, banded where "
        "the band is narrow, else sparse); the JSON's linear_algebra says what was used",
    )
    rp.add_argument(
        "--strict",
        action="store_true",
        help="exit with code 1 when an accuracy indicator of the run is past its threshold, a headline "
        "quantity's error band past the tolerance among them (each one prints a warning line either way)",
    )
    add_error_bar_options(rp)
    rp.add_argument("--save", metavar="FILE", help="save the run (.json or .npz) for contactfem.io.load_run")
    rp.add_argument(
        "--force",
        action="store_true",
        help="run even if the estimated size exceeds the limits (2 GB, 1e6 unknowns, 1e6 steps)",
    )
    rp.set_defaults(func=cmd_run)
    fp = sub.add_parser(
        "figures",
        help="regenerate every figure and table of the paper, each with NAME.json beside it (the "
        "numbers it plots, its parameters and the code version); --preset paper: into "
        "figures/; the default fast preset: into figures/fast/. The runs are kept in "
        "$CONTACTFEM_CACHE/figures (default ~/.cache/contactfem/figures) and reused by the "
        "same code",
    )
    fp.add_argument("--preset", default="fast", choices=["fast", "paper"])
    fp.add_argument(
        "--outdir",
        default=None,
        help="default: the repo's figures/ folder for --preset paper (the figures kept with the code), "
        "figures/fast/ for the fast preset",
    )
    fp.add_argument("--only", default=None, help="only figures whose file name contains this text")
    fp.add_argument(
        "--linear-algebra",
        default=None,
        choices=["auto", "dense", "banded", "sparse"],
        help="the factorisation of every system the figures' runs solve (default auto: each its own)",
    )
    fp.add_argument(
        "--perturb",
        default=None,
        metavar="EPS",
        help="start every time loop from the initial state perturbed by EPS of itself (at most 1e-6): "
        "what the figures' numbers hold under rounding",
    )
    fp.add_argument(
        "--rounding",
        action="store_true",
        help="measure what rounding does to every figure of --preset paper: draw each again under other "
        "OpenBLAS kernels, SuperLU and a perturbed initial state, and record each number's spread in the "
        "figure's NAME.json (its rounding section)",
    )
    fp.set_defaults(func=cmd_figures)
    ep = sub.add_parser("equations", help="the equation index: paper equation -> implementing function")
    ep.add_argument("--markdown", action="store_true", help="a Markdown table (the default when not on a terminal)")
    ep.set_defaults(func=cmd_equations)
    mp = sub.add_parser(
        "readme",
        help="fill the README's generated blocks (every number it states from a run) from the committed data: "
        "figures/*.json, bench.json; writes README.md in place",
    )
    mp.add_argument("--check", action="store_true", help="write nothing; exit 1 naming the first block that differs")
    mp.set_defaults(func=cmd_readme)
    sw = sub.add_parser("sweep", help="run a scene over a grid of parameter values, in parallel")
    sw.add_argument("scene")
    sw.add_argument(
        "--preset",
        default="fast",
        help="the preset every run starts from, as for run: fast (default), paper, or a named variant "
        "of the scene (listed by show)",
    )
    sw.add_argument(
        "--set",
        action="extend",
        nargs="+",
        metavar="NAME=V1,V2,...",
        help="values of parameters, or of a law's field as law.NAME=V1,V2,... (several after one "
        "--set, or --set repeated; at least one)",
    )
    sw.add_argument(
        "--jobs",
        type=int,
        default=1,
        help="local worker processes (default 1); a worker that dies "
        "is replaced and its point run once more, then recorded as failed with the reason",
    )
    sw.add_argument(
        "--scheduler",
        default=None,
        metavar="ADDRESS",
        help="Dask scheduler address (tcp://HOST:PORT): run on that cluster instead",
    )
    sw.add_argument(
        "--out",
        default="sweep.csv",
        help="table of results, .csv or .json (default: sweep.csv), "
        "rewritten as each point ends: always a complete table of the points done",
    )
    sw.add_argument(
        "--resume",
        action="store_true",
        help="keep the points of the --out table done by the same scene, preset, laws and code "
        "(its code_version column) and run only the others (failed ones included)",
    )
    sw.add_argument(
        "--time-limit",
        type=float,
        default=None,
        metavar="SECONDS",
        help="stop a run that takes longer and record it as failed (local workers)",
    )
    sw.add_argument(
        "--friction",
        metavar="LAW",
        help="the friction law of every run, as for run; sweep its fields with --set law.NAME=V1,V2,...",
    )
    sw.add_argument("--normal", metavar="LAW", help="the normal law of every run, as for run")
    sw.add_argument("--no-check", action="store_true", help="skip the laws' check before the runs, as for run")
    add_error_bar_options(sw)
    sw.add_argument(
        "--strict",
        action="store_true",
        help="count a point whose run is flagged (an accuracy indicator past its threshold: its warning line, "
        "the table's accuracy.flags) as failed, in the summary and the exit code 1",
    )
    sw.add_argument(
        "--force",
        action="store_true",
        help="run even if a run's estimated size, or the memory of the runs going at once, exceeds "
        "the limits (2 GB, 1e6 unknowns, 1e6 steps)",
    )
    sw.set_defaults(func=cmd_sweep)
    st = sub.add_parser("site", help="build the course website (lectures executed, gallery, equation index, API)")
    st.add_argument(
        "--out",
        default=None,
        metavar="DIR",
        help="output folder, DIR/index.html (default: build/site "
        "in the checkout, build/site-instructor with --instructor): new, empty, or a site built "
        "before; every file of the build is written there, its cache in DIR/.contactfem-site",
    )
    st.add_argument(
        "--instructor",
        action="store_true",
        help="the instructor version of the lectures (with the solutions) instead of the student version",
    )
    st.set_defaults(func=cmd_site)
    cp = sub.add_parser("course", help="the course: student and instructor versions of the lectures, grading")
    csub = cp.add_subparsers(dest="course_command", required=True)
    cb = csub.add_parser(
        "build",
        help="build the student version (no solutions) or, with --instructor, the "
        "instructor version (solutions, checks and the grading configurations)",
    )
    cb.add_argument("--instructor", action="store_true", help="the instructor version")
    cb.add_argument(
        "--out",
        default=None,
        metavar="DIR",
        help="output folder (default: build/course/student or build/course/instructor); the student "
        "version also goes into one zip there, the handout",
    )
    cb.add_argument(
        "--force",
        action="store_true",
        help="replace notebooks that differ from what the build writes (answered or edited ones), "
        "after moving them to DIR/backup-TIME/ (without --force the build refuses)",
    )
    cb.set_defaults(func=cmd_course_build)
    cg = csub.add_parser(
        "grade",
        help="grade a folder of submitted notebooks into a CSV: one row per submission, "
        "one column per exercise, the total and the hints of what failed",
    )
    cg.add_argument("folder", help="a folder of submitted notebooks (*.ipynb, subfolders included)")
    cg.add_argument("--out", required=True, metavar="FILE.csv", help="the table of scores")
    cg.add_argument(
        "--autograders",
        default=None,
        metavar="DIR",
        help="the instructor's grading material: a folder holding hidden_checks/ (the hidden "
        "checks, one file per lecture), e.g. the autograder/ folder of an instructor build (default, "
        "and where DIR has none: the checkout's lectures/hidden_checks/)",
    )
    cg.add_argument("--jobs", type=int, default=1, help="submissions graded in parallel (default 1)")
    cg.add_argument(
        "--roster",
        default=None,
        metavar="FILE.csv",
        help="the class: a CSV with the columns id, name, file (the submission's path in FOLDER) and "
        "optionally submitted (ISO time); every student gets a row, missing submissions marked",
    )
    cg.add_argument(
        "--deadline",
        default=None,
        metavar="TIME",
        help="ISO time (e.g. 2026-12-03T23:59); a submission after it is flagged late (its time: the "
        "roster's submitted, else the file's modification time when the grader copied it, before any notebook ran)",
    )
    cg.add_argument(
        "--lecture",
        default=None,
        metavar="NN_topic",
        help="the lecture every submission answers (default: from each notebook's metadata or NN_ prefix)",
    )
    cg.add_argument(
        "--notebook-timeout",
        type=float,
        default=900.0,
        metavar="S",
        help="seconds for one notebook, its cells and checks (default 900: over three times the slowest "
        "lecture's solution graded two at a time on a shared 2-core machine); a notebook over it "
        "gets its row with the reason",
    )
    cg.add_argument(
        "--check-timeout",
        type=float,
        default=20.0,
        metavar="S",
        help="seconds for one call of a student's function in a check (default 20: the calls take "
        "milliseconds; checks that run a scene allow their calls 60-120 s)",
    )
    cg.add_argument(
        "--memory",
        type=float,
        default=4096.0,
        metavar="MB",
        help="memory limit of each process of a submission's sandbox in MB (default 4096; 0: none)",
    )
    cg.add_argument(
        "--unsafe-no-sandbox",
        action="store_true",
        help="grade without the sandbox (where user namespaces are not to be had): the submissions then run "
        "as you, see your files and can change them; every row says so",
    )
    cg.add_argument(
        "--seed",
        type=int,
        default=None,
        metavar="N",
        help="the seed of the hidden checks' parameters (default: drawn afresh; give one to repeat a grading)",
    )
    cg.add_argument(
        "--review",
        default=None,
        metavar="DIR",
        help="the review files of the written answers, one per lecture, and the sheets for their "
        "scores (default: next to --out, named after it, with -review)",
    )
    cg.add_argument(
        "--feedback",
        default=None,
        metavar="DIR",
        help="one feedback file per student (default: next to --out, named after it, with -feedback)",
    )
    cg.set_defaults(func=cmd_course_grade)
    rc = sub.add_parser(
        "reconstruct",
        help="the scan's lost values as an inverse problem: run every reading "
        "the scan allows, record how it ends (converged, no equilibrium, no convergence, "
        "physically rejected), score the admissible ones against what the paper prints, print "
        "the ranked table",
    )
    rc.add_argument("scene", help="block | sloping_impact")
    rc.add_argument("--quick", action="store_true", help="a small profile of the search (seconds)")
    rc.add_argument("--top", type=int, default=25, help="rows of the ranked table to print")
    rc.add_argument(
        "--json",
        metavar="FILE.json",
        help="write every reading, its outcome and its scores to FILE.json (checked before the study)",
    )
    rc.add_argument(
        "--no-cache",
        action="store_true",
        help="recompute every reading (default: reuse the "
        "results of earlier runs of the same code, in $CONTACTFEM_CACHE or ~/.cache/contactfem)",
    )
    rc.set_defaults(func=cmd_reconstruct)
    bp = sub.add_parser(
        "bench",
        help="speed against accuracy: tangents, work-precision, cost, targets, "
        "enforcement, speed, semi-smooth Newton, scaling against plain scikit-fem, the error bands' coverage and cost "
        "(writes bench.json and BENCHMARKS.md)",
    )
    bp.add_argument("--quick", action="store_true", help="fast presets and fewer points (seconds)")
    bp.add_argument(
        "--out",
        default=None,
        help="folder for bench.json and BENCHMARKS.md (default: . for a full run, bench-quick/ for "
        "--quick); a quick run never replaces or mixes with a full one",
    )
    bp.add_argument(
        "--only",
        action="extend",
        nargs="+",
        choices=list(BENCH_STUDIES),
        metavar="STUDY",
        help="run only these studies (several after one --only, or --only repeated: "
        f"{', '.join(BENCH_STUDIES)}); the other studies of OUT/bench.json are kept",
    )
    bp.set_defaults(func=cmd_bench)
    return ap


def interrupted(exc):
    """The one line of a Ctrl-C: where the run was, and what was written (nothing, unless
    the outputs were already complete). A command whose outputs are not all or nothing sets
    _RUN["said"] to its own account ("during the site build; the site in X is unchanged"), a
    text or a function that returns it (called when the interrupt is reported), and
    _RUN["phase"] = "done" once its outputs are complete."""
    phase = _RUN.get("phase")
    if phase == "done":
        return "contactfem: interrupted after the outputs were written"
    said = _RUN.get("said")  # a command's own account: where it was, what is on disk
    if said:
        return f"contactfem: interrupted {said() if callable(said) else said}"
    if getattr(exc, "step", None) is not None:
        of = f" of {exc.n_steps}" if getattr(exc, "n_steps", None) else " (adaptive steps)"
        where = f" at t = {exc.t:.6g}, step {exc.step}{of}"
    elif phase == "write":
        where = " while writing the outputs"
    elif phase == "run":
        where = " during the run"
    elif phase == "sweep":
        table = _RUN.get("table")
        if table is not None and table.written is not None:
            done, failed, left = table.written
            return (
                f"contactfem: interrupted during the sweep; {table.path} holds the points done ({done} done, "
                f"{failed} failed, {left} left: --resume runs the rest)"
            )
        where = " during the sweep"
    else:
        where = " before the run started"
    return f"contactfem: interrupted{where}; nothing written"


def main(argv=None):
    """The command line; returns the exit code. Called without argv (as the program), a
    Ctrl-C after the work is done (while Python shuts down) no longer changes the outcome."""
    if argv is None:
        _catch_interrupts()
    try:
        with imports_timed() as imported:
            _CLOCK.update(imported=imported, own=_OWN_IMPORT_S.pop() if _OWN_IMPORT_S else 0.0)
            code = _main(argv)
    finally:
        _CLOCK.clear()
        if argv is None:
            signal.signal(signal.SIGINT, signal.SIG_IGN)
    if argv is None and code == 130:
        # an interrupt met inside a library's import leaves CPython's "unhandled KeyboardInterrupt"
        # flag set, which would end the process by SIGINT after our line: exit with 130 ourselves
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(130)
    return code


_INTERRUPTED = []


def _on_sigint(signum, frame):
    _INTERRUPTED.append(True)
    if not defer_interrupt():  # inside a library's import: raised when it returns
        raise KeyboardInterrupt


def _on_sigterm(signum, frame):
    raise SystemExit(128 + signum)


def _catch_interrupts():
    """Record every Ctrl-C before raising it: a library interrupted inside its import may
    turn the KeyboardInterrupt into an error of its own (numpy: "ImportError: numpy._core
    .multiarray failed to import"); what follows a recorded interrupt is that interrupt.
    SIGTERM (a `kill`, a job's time limit) ends the program with exit code 143 the way an
    exception would: the outputs' temporaries are removed and a child process (Sphinx for
    `site`) is stopped with it, rather than left running."""
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        signal.signal(signal.SIGINT, _on_sigint)
    if signal.getsignal(signal.SIGTERM) is signal.SIG_DFL:
        signal.signal(signal.SIGTERM, _on_sigterm)


def _report_ready():
    path = environment.read("CONTACTFEM_READY_FILE")
    if path:
        try:
            with open(path, "w"):
                pass
        except OSError:
            pass


def _main(argv):
    _RUN.clear()
    try:
        _report_ready()
        args = build_parser().parse_args(argv)
        code = args.func(args)  # None: done (0); a command may return its own code
        if code:
            return code
    except KeyboardInterrupt as exc:
        print(("\n" if _RUN.get("progress") else "") + interrupted(exc), file=sys.stderr)
        return 130
    except UsageError as exc:
        print(f"contactfem: error: {exc}", file=sys.stderr)
        return 2
    except ValueError as exc:
        if _INTERRUPTED:  # the interrupt, turned into another error by a library
            print(("\n" if _RUN.get("progress") else "") + interrupted(exc), file=sys.stderr)
            return 130
        if isinstance(exc, protocol.LawValueError):  # a law returned a bad value during the run: the run failed
            print(("\n" if _RUN.get("progress") else "") + f"contactfem: law failed: {_one_line(exc)}", file=sys.stderr)
            return 1
        print(f"contactfem: error: {_one_line(exc)}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # the reader went away (`contactfem equations | head`)
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())  # so that Python's exit flush does not fail again
        return 0
    except MemoryError:
        print("contactfem: out of memory: use a coarser mesh (see contactfem show SCENE)", file=sys.stderr)
        return 1
    except Exception as exc:
        if _INTERRUPTED:  # the interrupt, turned into another error by a library
            print(("\n" if _RUN.get("progress") else "") + interrupted(exc), file=sys.stderr)
            return 130
        if isinstance(exc, scenes.SceneError):  # a scene file's own code failed during the run
            print(
                ("\n" if _RUN.get("progress") else "") + f"contactfem: scene failed: {_one_line(exc)}", file=sys.stderr
            )
            return 1
        if isinstance(exc, (ZeroDivisionError, OverflowError)):  # Python arithmetic at the float limits
            print(
                f"contactfem: solver failed: {_one_line(exc)} in {_where(exc)} (parameter values near the limits "
                "of floating point?)",
                file=sys.stderr,
            )
            return 1
        if not isinstance(exc, (FloatingPointError, newton.NewtonError)):  # Newton, return map, inverted elements
            if environment.read("CONTACTFEM_DEBUG") == "1":
                raise
            print(
                f"contactfem: internal error: {type(exc).__name__}: {_one_line(exc)} "
                "(CONTACTFEM_DEBUG=1 shows the traceback)",
                file=sys.stderr,
            )
            return 3
        print(f"contactfem: solver failed: {_one_line(exc)}", file=sys.stderr)
        hist = getattr(exc, "history", None)
        if hist is not None:
            text = " ".join(f"{r:.3e}" for r in hist) if hist else "(empty: no finite residual was reached)"
            print(f"residual history: {text}", file=sys.stderr)
        return 1
    return 0


def _where(exc):
    """The innermost function of contactfem the exception passed through: 'name (module)'."""
    frames = [f for f in traceback.extract_tb(exc.__traceback__) if "contactfem" in f.filename]
    if not frames:
        return "a library"
    f = frames[-1]
    return f"{f.name} ({f.filename.split('contactfem')[-1].strip('/').replace('/', '.')[:-3]}, line {f.lineno})"


def _one_line(exc):
    return " ".join(str(exc).split()) or type(exc).__name__


if __name__ == "__main__":
    sys.exit(main())
