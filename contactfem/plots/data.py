"""The numbers behind every figure: ``NAME.json`` beside ``NAME.png``.

A figure function puts what it plots into a dict, its headline numbers under the run's own
JSON keys (the rolling ring's ``v_final``, the block's ``n_slip``) and the series it draws,
builds its title and labels from that dict, and hands figure, dict and parameters to
``save_figure``, which writes both files. Besides the data's own keys the JSON holds:

    figure         the file's stem (NAME)
    code_version   contactfem's version and a short hash of the package's sources
                   ("0.1.0+src.1a2b3c4d5e"): the same code gives the same string
    parameters     the inputs behind the figure (a scene's resolved parameters; for a study,
                   its grid as well)
    rounding       what rounding does to its numbers (plots/rounding.py: ``contactfem figures
                   --rounding``), kept when the figure is drawn again

``differences`` lists where two such files disagree (a changed number, key or length) to the
tolerance argued at ``RTOL``, or within twice the spread rounding gave a number (plots.rounding);
the code version is reported, not compared.
"""

import hashlib
import json
import re
from functools import lru_cache
from pathlib import Path
from .. import __version__, lazy
from ..problem.scene import jsonable

plt = lazy.module("matplotlib.pyplot")

RESERVED = ("figure", "code_version", "parameters", "rounding")

# Two numbers of a figure's data agree to RTOL, relative to the larger of the two or, inside a
# list, to the largest number of that list (a slip speed of 1e-9 cm/s on a ring rolling at
# 150 cm/s is zero, not a result). Why 1e-8: a run marches the same model to the same records
# bit for bit on one machine; another BLAS or summation order moves the last digits (1e-16
# relative), which the Newton tolerances (1e-10 of the first residual and below) and a few hundred
# steps can grow to about 1e-10; a changed parameter, law or formula moves the numbers the
# figures print (3-4 digits) by 1e-4 or more. 1e-8 sits two decades above the first and four
# below the second.
RTOL = 1e-8
# A number below ROUNDOFF in both files is the rounding of a run, not its result (residual
# norms and equilibrium errors of 1e-12 where the loads are 1e2-1e3); both below it agree.
ROUNDOFF = 1e-9
# Where rounding moves a number past RTOL (plots/rounding.py measures it: ``contactfem figures
# --rounding``), a fresh run agrees with the written one within MARGIN times the recorded spread.
# The spread is the range of five samples of what rounding does (the committed run and four
# conditions); another machine's kernel is one more sample, which falls outside the range of the five
# with probability 2/6 when the samples are alike. Twice the range (the range widened by its own width
# on either side of any sample inside it) holds it unless rounding moves that machine's result twice
# as far as any condition did, which would be a knife edge the study missed: worth a failure.
MARGIN = 2.0
NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")


@lru_cache(maxsize=1)
def source_hash():
    """The first 10 hex digits of the SHA-1 of every .py file of the package (paths and
    contents, in sorted order): any change of the code changes it."""
    root = Path(__file__).resolve().parents[1]
    h = hashlib.sha1()
    for f in sorted(root.rglob("*.py")):
        h.update(str(f.relative_to(root)).encode())
        h.update(f.read_bytes())
    return h.hexdigest()[:10]


def code_version():
    """contactfem's version and the hash of its sources, e.g. "0.1.0+src.1a2b3c4d5e"."""
    return f"{__version__}+src.{source_hash()}"


def dumps(record):
    """JSON text with one top-level key a line (the series compact), for short diffs."""
    return "{\n" + ",\n".join(f" {json.dumps(k)}: {json.dumps(v)}" for k, v in record.items()) + "\n}\n"


def figure_record(stem, data, parameters):
    """The dict written to NAME.json: figure, code_version, parameters, then ``data``'s keys
    (numpy values made plain; a key of RESERVED in ``data`` is a ValueError)."""
    clash = [k for k in data if k in RESERVED]
    if clash:
        raise ValueError(f"figure data of {stem} uses the reserved key(s) {', '.join(clash)}")
    return dict(
        figure=stem,
        code_version=code_version(),
        parameters=jsonable(parameters or {}),
        **jsonable(dict(data), where=stem),
    )


def write_data(path_json, data, parameters):
    """Write ``path_json`` (NAME.json) holding ``data`` and ``parameters`` (see the module's
    docstring); returns its path as a string."""
    path = Path(path_json)
    path.parent.mkdir(parents=True, exist_ok=True)
    record = figure_record(path.stem, data, parameters)
    if path.exists() and "rounding" in (before := load(path)):  # measured for the figure, not the run
        record["rounding"] = before["rounding"]
    path.write_text(dumps(record))
    return str(path)


def save_figure(fig, path_png, data, parameters):
    """Save the matplotlib figure ``fig`` as ``path_png`` (NAME.png, 110 dpi) and close it, and
    write NAME.json beside it with the numbers it plots.

    ``data``: dict of what the figure shows, its headline numbers under the run's own JSON keys
    (e.g. ``v_final``) and the series it draws; numpy arrays and scalars are fine; the keys
    "figure", "code_version" and "parameters" are reserved. ``parameters``: dict of the inputs
    behind it (a scene's resolved parameters, a study's grid). Draw titles and labels from
    ``data``, so the picture and the file say the same. ``fig`` None: only the JSON (a table
    written as markdown). Returns [png path, json path] (only the JSON's for ``fig`` None)."""
    path = Path(path_png)
    path.parent.mkdir(parents=True, exist_ok=True)
    json_path = write_data(path.with_suffix(".json"), data, parameters)
    if fig is None:
        return [json_path]
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return [str(path), json_path]


def load(path):
    """A figure's JSON as a dict."""
    return json.loads(Path(path).read_text())


def _scale(values):
    """The largest |number| in a (nested) list, not looking into dicts."""
    out = 0.0
    for v in values:
        if isinstance(v, list):
            out = max(out, _scale(v))
        elif isinstance(v, (int, float)) and not isinstance(v, bool):
            out = max(out, abs(float(v)))
    return out


def _number_differs(a, b, rtol, scale, width=0.0):
    a, b = float(a), float(b)
    if abs(a) < ROUNDOFF and abs(b) < ROUNDOFF:
        return False
    return abs(a - b) > max(rtol * max(abs(a), abs(b), scale), MARGIN * width)


def _texts_differ(a, b, entry):
    """Two texts differ unless equal or, where rounding moved the numbers in them, alike in words."""
    if a == b:
        return False
    words = lambda t: NUMBER.sub("#", t)  # noqa: E731
    return not ("texts" in entry and words(a) == words(b) and words(b) in {words(t) for t in entry["texts"]})


def _compare(a, b, where, rtol, scale, out, spread):
    entry = spread.get(where, {})
    if isinstance(a, dict) and isinstance(b, dict):
        for k in list(a) + [k for k in b if k not in a]:
            key = f"{where}.{k}" if where else k
            if not where and k in ("code_version", "rounding"):
                continue
            if k not in b:
                out.append(f"{key}: in the file, not from the run")
            elif k not in a:
                out.append(f"{key}: not in the file, from the run")
            else:
                _compare(a[k], b[k], key, rtol, None, out, spread)
    elif isinstance(a, list) and isinstance(b, list):
        if "len" in entry:  # a run whose length rounding decides: its length within the range, widened
            lo, hi = entry["len"]
            if not lo - MARGIN / 2 * (hi - lo) <= len(b) <= hi + MARGIN / 2 * (hi - lo):
                out.append(f"{where}: {len(b)} entries from the run, {lo} to {hi} under rounding")
            return
        if len(a) != len(b):
            out.append(f"{where}: {len(a)} entries in the file, {len(b)} from the run")
            return
        s = _scale(a + b) if scale is None else scale
        width = spread.get(f"{where}[]", {}).get("width", 0.0)
        for i, (x, y) in enumerate(zip(a, b)):
            if width and is_number(x) and is_number(y):
                if _number_differs(x, y, rtol, s, width):
                    out.append(f"{where}[{i}]: {x!r} in the file, {y!r} from the run (rounding moves it {width:.2g})")
            else:
                _compare(x, y, f"{where}[{i}]", rtol, s, out, spread)
    elif is_number(a) and is_number(b):
        width = entry["hi"] - entry["lo"] if "hi" in entry else 0.0
        if _number_differs(a, b, rtol, scale or 0.0, width):
            moved = f" (rounding moves it {width:.2g})" if width else ""
            out.append(f"{where}: {a!r} in the file, {b!r} from the run{moved}")
    elif isinstance(a, str) and isinstance(b, str):
        if _texts_differ(a, b, entry):
            out.append(f"{where}: {a!r} in the file, {b!r} from the run")
    elif a != b and b not in entry.get("values", ()):
        out.append(f"{where}: {a!r} in the file, {b!r} from the run")


def is_number(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def differences(written, fresh, rtol=RTOL):
    """Where two figure records disagree, one line each ("v_final: 149.2 in the file, 149.3
    from the run"): a key or a length that differs, a string, bool or None that differs, a
    number that differs beyond ``rtol`` (see RTOL and ROUNDOFF). Where the written record
    holds a ``rounding`` section (plots/rounding.py), a number agrees within MARGIN times the
    spread rounding gave it, a list whose length rounding moved by its length, a text by its
    words, a flag by any value rounding gave it. ``code_version`` is not compared. [] when
    they agree."""
    out = []
    _compare(written, fresh, "", rtol, None, out, (written.get("rounding") or {}).get("spread", {}))
    return out
