"""Error bars: every headline quantity of a run with its numerical uncertainty, from a ladder of the
run's own discretisation (solution verification, Roache; ASME V&V 20-2009).

A scene declares its headline quantities (``Quantity``: the result's name, its unit, which
discretisations move it, its closed form where it has one) and how each of its discretisations is
coarsened (``Discretisation``: the time step, the mesh, the penalty where it regularises a
constraint). For every discretisation that moves a quantity, the run is repeated at coarser
levels, twice and four times the step (or the element size, or half and a quarter of the penalty),
so that the user's run stays the finest and costs what it did. From the three values f1 (the run),
f2, f3 of a quantity at the sizes h1 < h2 < h3:

    e21 = f2 - f1, e32 = f3 - f2, R = e21 / e32     convergence class: monotone 0 < R < 1,
                                                      oscillatory R < 0, divergent R >= 1 (with unequal
                                                      ratios R is scaled by ln r32 / ln r21)
    p from  e32 / e21 = r21^p (r32^p - 1) / (r21^p - 1)   the observed order (Celik et al. 2008; the
                                                      ratios r21 = h2 / h1, r32 = h3 / h2 need not be equal)
    delta = e21 / (r21^p - 1)                        Richardson's estimate of f1's error; f1 - delta
                                                      the extrapolated value
    band = FS(P) |delta|,  P = p / p_th              Xing & Stern's factor of safety (2010), p_th the
                                                      discretisation's theoretical order:
    FS(P) = FS1 P + FS0 (1 - P) for P <= 1,  FS1 P + FS0 (P - 1) for P > 1,  FS0 = 2.45, FS1 = 1.6

Xing & Stern chose FS0 and FS1 so that the band holds the true error with 95 % reliability over
304 grid triplets of 17 studies (fluids, heat transfer, structures), at and away from the asymptotic
range; Roache's Grid Convergence Index (the factor 1.25 where p is near p_th, 3 elsewhere) holds
less often where p > p_th (its band shrinks with delta while its factor stays 1.25).

The coarser levels do not always serve. A level may fail, or fall outside its parameter's range (a
ring of fewer than 8 elements), or, coarser in time, no longer resolve the contacts' period (``resolved``:
the penalty's spring rings under the step, and its quantities do not converge like the scheme's order);
the levels may oscillate, diverge, or show an order far above the
scheme's (P > P_MAX), which in a contact problem is most often a coarsest level outside the
asymptotic range: the paper's sloping impact gives 1.462, 1.455 and 1.330 at dt, 2 dt and 4 dt (an
order of 4 for a first-order integrator), while the run refined in time goes to 1.58. Then the ladder
moves one level finer (h / 2, h, 2 h; then h / 4, h / 2, h), whose cost is counted, and the band of the
run is its known difference to the finest level plus the band of that level. Where even the finest
triplet is not acceptable: monotone levels with P > P_MAX take Roache's band for an order that cannot
be trusted, 3 max(|e21|, |e32| / r32^p_th) / (r21^p_th - 1) (the slowest convergence the scheme allows: a
finer difference smaller than the coarser one carried down at p_th is a plateau, not the error); levels that agree to
Newton's tolerance are ``converged``; oscillatory or divergent levels, or levels that fail, give no band,
and the run warns, naming the quantity. (An oscillation's envelope is no band: the paper's frictional
sloping impact oscillates within 1.3 % over dt / 4 ... dt while its time error is 5 %, a slow drift under
the oscillation.)

The parts of a quantity's band (one per discretisation) add up: their errors were estimated one
discretisation at a time and may have the same sign, so a root sum of squares (V&V 20's combination
of independent uncertainties) could undercut their sum. A band past the run's tolerance (5 % by
default, relative to the quantity, or to its scale where it is near zero) is an accuracy indicator
past its threshold: AccuracyWarning, and ``--strict`` exits 1.

The coarser levels are whole runs of the same scene (``bands``), without error bars of their own
and without their warnings; their results are not kept, only the quantities' values, the parameters
that changed and the time they took (``wall_time_s``: the error bars' cost beside the run's).
"""

import math
import time
import warnings
from dataclasses import dataclass, field
from typing import Callable

from .. import environment
from .accuracy import TOLERANCE, indicator  # TOLERANCE: the relative band a quantity may have (--tolerance)
from .resources import check_resources
from .time_integration import contact_integration, newmark_of

FS0, FS1 = 2.45, 1.6  # Xing & Stern (2010): the factor of safety at P = 0 and P = 1
P_MAX = 2.0  # beyond, the coarsest level of the triplet is outside the asymptotic range
ROACHE_FS = 3.0  # Roache's factor of safety where the observed order cannot be used
NOISE = 1e-8  # levels that agree to this fraction of the quantity differ by Newton's tolerance only
FINER = 2  # at most this many finer levels (h / 2, h / 4) where the coarser ones do not serve
FINER_COST = 4.0  # and none that costs more than this many times the run (its unknowns times its steps): a
# time step halved twice, a ring's mesh refined twice, a 2-D mesh refined once


@dataclass(frozen=True)
class Quantity:
    """A headline quantity of a scene: the result's ``name``, its ``unit``, the discretisations that
    move it (``controls``: names of the scene's Discretisations), the ``scale`` below which it counts as
    near zero (a number, or a function of the parameters; its band and its error are then relative to
    the scale instead of itself: max(|value|, scale); None: always relative to itself), its closed form
    (``exact``: the name of the result that holds it, or a number; the run's error against it is an
    accuracy indicator held to the tolerance), and theoretical orders where they differ from the
    discretisation's (``orders``: name -> p_th; a pressure converges as h, a displacement as h^2)."""

    name: str
    unit: str = ""
    controls: tuple = ("step",)
    scale: float | Callable[[dict], float] | None = None
    exact: str | float | None = None
    orders: dict = field(default_factory=dict)

    def reference(self, params, value):
        """What the quantity's band and error are relative to: |value|, or its scale where larger."""
        s = self.scale(params) if callable(self.scale) else self.scale
        return max(abs(value), s or 0.0)


@dataclass(frozen=True)
class Discretisation:
    """A discretisation of a scene's run: its ``name`` (what a Quantity's controls say), the ``label``
    the bands print ("time step"), ``coarsen(params, r)``: the parameters of the run with its size
    times r (a dict of overrides; r < 1 refines), ``size(params)``: the size h (a step, an element's
    length, the penalty's compliance 1 / c_N), ``order(params)``: its theoretical order p_th, and
    ``applies(params)``: whether the run has it at all (a penalty with Lagrange multipliers does not)."""

    name: str
    label: str
    coarsen: Callable[[dict, float], dict]
    size: Callable[[dict], float]
    order: Callable[[dict], float]
    applies: Callable[[dict], bool] = lambda params: True


def integrator_order(params):
    """The theoretical order of a scene's time integration: 2 for the trapezoidal rule (Newmark
    delta = 1/2), the energy-consistent midpoint rule and central differences; 1 for Newmark with
    delta > 1/2 (its numerical damping is an error of first order in dt); 1 in the tolerance of a run
    at a tolerance (its error is held proportional to it)."""
    if params.get("accuracy"):
        return 1.0
    if params.get("integrator", "newmark") != "newmark" or contact_integration(params) == "energy_consistent":
        return 2.0
    if "delta" not in params:  # a scene file's own stepper: the trapezoidal rule's, unless it says (order=)
        return 2.0
    delta, _ = newmark_of(params)
    return 2.0 if delta == 0.5 else 1.0


def time_step(dt="dt", count=None, also=(), order=integrator_order):
    """The time step: the parameter ``dt`` times r, and the parameters in ``also`` with it (the cork's
    fine step and travel limit); ``count``: the parameter that counts the steps (n_steps), divided by r
    and rounded up, dt then set so that the run ends when it did. A run at a tolerance (its parameter
    ``accuracy`` > 0) is coarsened in its tolerance instead, up to its largest allowed value. ``order``: the
    theoretical order, a function of the parameters or a number (a scene file's own integrator). A coarser
    tolerance past its range, like any level outside a parameter's range, is refused and not taken."""

    def coarsen(params, r):
        if params.get("accuracy"):
            return {"accuracy": params["accuracy"] * r}
        out = {k: params[k] * r for k in (dt, *also)}
        if count is not None:
            n = max(1, math.ceil(params[count] / r - 1e-9))
            out.update({count: n, dt: params[dt] * params[count] / n})
        return out

    def size(params):
        return params["accuracy"] if params.get("accuracy") else params[dt]

    return Discretisation("step", "time step", coarsen, size, order if callable(order) else (lambda params: order))


def mesh(*counts, low=None, order=2.0, extra=None):
    """The mesh: each parameter in ``counts`` (elements along a direction) divided by r and rounded,
    at least ``low`` (a number, or name -> number; below, the level is not taken); ``extra(params, n)``:
    more overrides for the level with counts n (a step or penalty tied to the element size, held).
    The size h is 1 / the first count; p_th = ``order`` (linear elements: 2 for displacements)."""

    def floor(name):
        return (low.get(name) if isinstance(low, dict) else low) or 1

    def coarsen(params, r):
        n = {k: max(1, round(params[k] / r)) for k in counts}
        if any(n[k] < floor(k) for k in counts) or all(n[k] == params[k] for k in counts):
            raise ValueError(f"no mesh {r:g} times coarser than {', '.join(f'{k} = {params[k]}' for k in counts)}")
        return dict(n, **(extra(params, n) if extra else {}))

    return Discretisation("mesh", "mesh", coarsen, lambda params: 1.0 / params[counts[0]], lambda params: order)


def penalty(name="c_N", enforcement="enforcement"):
    """The penalty where it regularises a constraint: ``name`` divided by r (softer: coarser); the size
    is the compliance 1 / c_N, p_th = 1 (the penalty's error is proportional to the penetration it
    allows). Only with the penalty method (``enforcement`` = penalty): multipliers make c_N a steering."""

    return Discretisation(
        "penalty",
        "penalty",
        lambda params, r: {name: params[name] / r},
        lambda params: 1.0 / params[name],
        lambda params: 1.0,
        lambda params: params.get(enforcement, "penalty") == "penalty",
    )


def check_tolerance(tolerance):
    """The tolerance as a float in (0, 1] (ValueError naming it and its range)."""
    if isinstance(tolerance, bool):
        raise ValueError(f"tolerance must be a number in (0, 1], got {tolerance!r}")
    try:
        value = float(tolerance)
    except (TypeError, ValueError):
        raise ValueError(f"tolerance must be a number in (0, 1], got {tolerance!r}") from None
    if not 0.0 < value <= 1.0:
        raise ValueError(f"tolerance = {tolerance!r} is out of range: allowed (0, 1]")
    return value


def error_bars_default():
    """Whether runs get error bars when nobody says: yes, unless the environment variable
    CONTACTFEM_ERROR_BARS is 0, off, no or false (every run of a process without them: the test suite's
    runs, whose tests of the bands turn them on); 1, on, yes or true say yes; any other value is a
    ValueError naming it."""
    value = environment.read("CONTACTFEM_ERROR_BARS", "on")
    said = value.strip().lower()
    if said not in OFF + ON:
        raise ValueError(
            f"environment variable CONTACTFEM_ERROR_BARS = {value!r}: allowed {', '.join(OFF)} (off) "
            f"or {', '.join(ON)} (on)"
        )
    return said in ON


OFF, ON = ("0", "off", "no", "false"), ("1", "on", "yes", "true")  # CONTACTFEM_ERROR_BARS's values


def factor_of_safety(P):
    """Xing & Stern's factor of safety FS(P), P = p / p_th (module docstring)."""
    return FS1 * P + FS0 * (1.0 - P) if P <= 1.0 else FS1 * P + FS0 * (P - 1.0)


def observed_order(e21, e32, r21, r32):
    """The observed order p of monotone levels with refinement ratios r21, r32: the root of
    e32 / e21 = r21^p (r32^p - 1) / (r21^p - 1) (Celik et al. 2008; with equal ratios p = ln(e32 / e21) / ln r),
    found by bisection in ln p (the right side grows with p from ln r32 / ln r21)."""
    target = math.log(e32 / e21)

    def gap(p):
        return p * math.log(r21) + math.log(math.expm1(p * math.log(r32)) / math.expm1(p * math.log(r21))) - target

    lo, hi = 1e-9, 64.0
    if gap(lo) >= 0.0:
        return lo
    if gap(hi) <= 0.0:
        return hi
    for _ in range(200):
        mid = math.sqrt(lo * hi)
        lo, hi = (mid, hi) if gap(mid) < 0.0 else (lo, mid)
        if hi / lo - 1.0 < 1e-14:
            break
    return math.sqrt(lo * hi)


def classify(f1, f2, f3, scale, r21=2.0, r32=2.0):
    """The convergence class of three levels (finest first, refinement ratios r21, r32): converged (they
    agree to NOISE of the scale), monotone, oscillatory or divergent (module docstring). With unequal ratios
    R is e21 / e32 times ln r32 / ln r21, so that R < 1 is still convergence at some order p > 0 (the ratio
    e32 / e21 of a power law h^p falls to ln r32 / ln r21 as p -> 0). Levels of which two agree to NOISE and
    the third does not are divergent (R = 0 or infinite: no order)."""
    e21, e32 = f2 - f1, f3 - f2
    if max(abs(e21), abs(e32)) <= NOISE * scale:
        return "converged"
    if min(abs(e21), abs(e32)) <= NOISE * scale or (e21 / e32) * math.log(r32) / math.log(r21) >= 1.0:
        return "divergent"
    return "monotone" if e21 / e32 > 0 else "oscillatory"


def estimate(levels, p_th, user=0, scale=None):
    """The band of the value at ``levels[user]`` from three levels [(h, f), ...], finest first:
    dict(band, cls, observed_order, P, factor_of_safety, richardson, method). band is None where the
    class is oscillatory or divergent."""
    (h1, f1), (h2, f2), (h3, f3) = levels
    f_user = levels[user][1]
    scale = scale if scale is not None else max(abs(f1), abs(f2), abs(f3))
    r21, r32 = h2 / h1, h3 / h2
    cls = classify(f1, f2, f3, scale, r21, r32)
    out = dict(cls=cls, observed_order=None, P=None, factor_of_safety=None, richardson=None, method=None)
    known = abs(f_user - f1)  # the difference to the finest level (0 where the run is the finest)
    if cls == "converged":
        return dict(out, band=known + max(abs(f2 - f1), abs(f3 - f2)), method="levels agree")
    if cls != "monotone":
        return dict(out, band=None)
    p = observed_order(f2 - f1, f3 - f2, r21, r32)
    P = p / p_th
    delta = (f2 - f1) / (r21**p - 1.0)
    out.update(observed_order=p, P=P, richardson=f1 - delta)
    if P > P_MAX:  # the order cannot be trusted: Roache's band for the slowest order the scheme allows
        band = ROACHE_FS * slowest(f2 - f1, f3 - f2, r32, p_th) / (r21**p_th - 1.0)
        return dict(out, band=known + band, factor_of_safety=ROACHE_FS, method="Roache, p = p_th")
    fs = factor_of_safety(P)
    return dict(out, band=known + fs * abs(delta), factor_of_safety=fs, method="Xing & Stern")


def slowest(e21, e32, r32, p_th):
    """The finer difference as the slowest convergence the scheme allows makes it: |e21|, or the coarser
    difference carried one level finer at the theoretical order, |e32| / r32^p_th, where that is larger. An order
    far above the scheme's means the finer difference is smaller than the scheme's convergence explains (a
    plateau where two errors of opposite sign cancel: the rolling ring's v_final moves by 1.64, 0.067, 0.19,
    0.074 as its step is halved four times from the fast preset's), so it cannot stand for the error alone."""
    return max(abs(e21), abs(e32) / r32**p_th)


def acceptable(est):
    """Whether a triplet's estimate is one to keep (else a finer triplet is tried): converged levels, or
    monotone ones whose observed order is in range (P <= P_MAX). Oscillatory levels, or an order far
    above the scheme's, are often a coarsest level outside the asymptotic range: a finer triplet is tried,
    and where none is better the finest one's Roache band, or no band."""
    return est["cls"] == "converged" or (est["cls"] == "monotone" and est["P"] <= P_MAX)


def resolved(results, tolerance):
    """Whether a run resolves its contacts' period in time: dt sqrt(k / m) (its ``penalty_steps``) at most
    sqrt(12 tolerance), where the trapezoidal rule's period error, (omega dt)^2 / 12 (Hughes 1987, Sec. 9.3;
    Newmark's with delta > 1/2 is of the same order), is within the tolerance. A run without that
    indicator (no impact) resolves what it has."""
    ind = (results.get("accuracy") or {}).get("penalty_steps")
    return ind is None or ind.get("value") is None or ind["value"] <= math.sqrt(12.0 * tolerance)


def ladder(run, params, results, quantities, disc, tolerance=TOLERANCE):
    """The part of each quantity's band that ``disc`` makes: levels 2 h and 4 h first, then finer
    triplets where a level fails, leaves its parameter's range, or the levels are not acceptable.
    ``run(overrides)`` -> results or an Exception (one call per level, shared by the quantities);
    ``results``: the run's own (the level k = 0). A coarser level of the time step that does not resolve the
    contacts' period (``resolved``) is outside the asymptotic range and is not taken: the penalty's spring
    rings under the step and its quantities do not converge like its order (the sloping impact's trapezoidal
    v_y is 1.671, 1.565, 1.534 at dt = 0.2, 0.1, 0.05, then 1.581 and 1.623 at 0.025 and 0.0125). Returns
    name -> part dict, and the levels run."""
    cache = {0: dict(overrides={}, h=disc.size(params), results=results, error=None)}

    def level(k):  # the run at size h r^k (k = 0: the user's run)
        if k not in cache:
            r = 2.0**k
            try:
                over = disc.coarsen(params, r)
            except ValueError as err:  # no such level (a mesh below its floor)
                cache[k] = dict(overrides=None, error=str(err), h=None, results=None, unused=False)
                return cache[k]
            res = run(over)
            h = disc.size(dict(params, **over))
            if not isinstance(res, Exception) and not res.get("accuracy", {}).get("separated", {}).get("ok", True):
                res = Unused("the level ends in contact: its rebound would be read mid-impact")
            if not isinstance(res, Exception) and not res.get("accuracy", {}).get("missed", {}).get("ok", True):
                res = Unused("the level has no impact: its rebound would be the velocity it started with")
            if not isinstance(res, Exception) and k > 0 and disc.name == "step" and not resolved(res, tolerance):
                res = Unused("the level does not resolve the contacts' period (penalty_steps)")
            cache[k] = dict(
                overrides=over,
                h=h,
                results=None if isinstance(res, Exception) else res,
                error=_why_not(res) if isinstance(res, Exception) else None,
                unused=isinstance(res, Unused),
            )
        return cache[k]

    parts = {}
    for q in quantities:
        p_th = q.orders.get(disc.name, disc.order(params))
        est, tried, found = None, [], []
        for start in range(0, -FINER - 1, -1):  # the finest level of the triplet: 0, -1, -2
            ks = (start, start + 1, start + 2)
            lv = [level(k) for k in ks]
            values = [None if L["results"] is None else value_of(L["results"], q) for L in lv]
            failed = [L["error"] or "no value" for L, v in zip(lv, values) if v is None]
            if failed:
                tried.append(dict(levels=_levels(ks, lv, values), why=failed[0]))
                continue
            scale = max(q.reference(params, v) for v in values)
            est = dict(estimate([(L["h"], v) for L, v in zip(lv, values)], p_th, user=-start, scale=scale))
            est["levels"] = _levels(ks, lv, values)
            tried.append(dict(levels=est["levels"], why=_verdict(est, p_th)))
            found.append(est)
            if acceptable(est):
                break
        # none acceptable: the finest triplet the ladder could run decides (Roache's band where it is monotone
        # with P > P_MAX; no band where it oscillates or diverges): a coarser triplet was judged already
        est = found[-1] if found else None
        part = dict(
            band=None if est is None else est["band"],
            convergence=None if est is None else est["cls"],
            observed_order=None if est is None else est["observed_order"],
            theoretical_order=p_th,
            factor_of_safety=None if est is None else est["factor_of_safety"],
            richardson=None if est is None else est["richardson"],
            method=None if est is None else est["method"],
            levels=est["levels"] if est is not None else tried[-1]["levels"],
            tried=[
                dict(
                    factors=[lv["factor"] for lv in t["levels"]],
                    values=[lv["value"] for lv in t["levels"]],
                    why=t["why"],
                )
                for t in tried
            ],
        )
        if part["band"] is None:
            part["why"] = "; ".join(f"levels {_text(t['levels'])}: {t['why']}" for t in tried)
        parts[q.name] = part
    runs = [L for k, L in cache.items() if k != 0 and L["overrides"] is not None]
    return parts, runs


class Unused(Exception):
    """A level that ran but is not used: outside the asymptotic range (its contacts unresolved in time), or
    read where its quantity is not defined (mid-impact, no impact)."""


def _why_not(err):
    """Why a level gives no value, in one line: an Unused level's reason; a failure's type and message."""
    text = str(err).splitlines()[0][:200] if str(err) else ""
    return text if isinstance(err, Unused) else f"{type(err).__name__}: {text}"


def _levels(ks, lv, values):
    return [dict(factor=2.0**k, h=L["h"], value=v, overrides=L["overrides"]) for k, L, v in zip(ks, lv, values)]


def _verdict(est, p_th):
    """A triplet's convergence class, and why a monotone one is not taken: its order far above the scheme's."""
    if est["cls"] == "monotone" and est["P"] > P_MAX:
        return f"monotone, but of order {est['observed_order']:.3g}, more than {P_MAX:g} times the scheme's {p_th:g}"
    return est["cls"]


def _text(levels):
    return ", ".join("-" if L["value"] is None else f"{L['value']:.6g}" for L in levels)


def value_of(results, q):
    """A quantity's value in a run's results: a finite number, or None."""
    v = results.get(q.name)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        return None
    return float(v)


def bands(run, params, results, quantities, discretisations, tolerance=TOLERANCE, settled=None):
    """The ``uncertainty`` section of a run (module docstring): ``run(overrides)`` runs a level (its
    results, or the Exception that stopped it), ``results`` are the run's own. ``settled``: overrides that
    end the levels once the quantities are decided (the scene's ``settles``; the levels are coarsened from
    them). Returns the section and the accuracy indicators of the bands (name_band: the relative band
    against the tolerance)."""
    t0 = time.perf_counter()
    known = {d.name: d for d in discretisations}
    for q in quantities:
        unknown = [n for n in q.controls if n not in known]
        if unknown:
            raise ValueError(f"quantity {q.name}: no discretisation {unknown[0]!r} (the scene declares {list(known)})")
    absent = [q for q in quantities if q.controls and q.name not in results]  # (a name the measure never gives)
    quantities = [q for q in quantities if q.controls and q.name in results]  # (none: its closed form alone)
    out, runs = {}, []
    for q in quantities:
        out[q.name] = dict(value=value_of(results, q), unit=q.unit, parts={})
    for d in discretisations:
        if not d.applies(params):
            continue
        moved = [q for q in quantities if d.name in q.controls and value_of(results, q) is not None]
        if not moved:
            continue
        parts, level_runs = ladder(run, dict(params, **(settled or {})), results, moved, d, tolerance)
        runs += level_runs
        for name, part in parts.items():
            out[name]["parts"][d.name] = dict(part, label=d.label)
    indicators = {
        f"{q.name}_band": _no_band(
            q,
            f"the scene's measure returns no value named {q.name}",
            "a headline quantity the scene declares is a result its measure returns (Scene.quantities)",
        )
        for q in absent
    }
    for q in quantities:
        entry = out[q.name]
        parts = entry["parts"]
        value = entry["value"]
        if value is None:  # not a number in this run (a ring that never rolls): nothing to band
            entry.update(band=None, relative_band=None, convergence=None, observed_order=None, levels=1)
            continue
        missing = [p["label"] for p in parts.values() if p["band"] is None]
        band = None if missing else sum(p["band"] for p in parts.values())
        dominant = max(parts.values(), key=lambda p: -1.0 if p["band"] is None else p["band"], default=None)
        ref = q.reference(params, value)
        entry.update(
            band=band,
            relative_band=None if band is None or ref == 0 else band / ref,
            convergence=_worst([p["convergence"] for p in parts.values()]),
            observed_order=None if dominant is None else dominant["observed_order"],
            levels=1 + sum(len(p["levels"]) - 1 for p in parts.values()),  # the run and the levels its bands used
        )
        if band is None:
            why = "; ".join(f"{p['label']}: {p['why']}" for p in parts.values() if p["band"] is None)
            indicators[f"{q.name}_band"] = _no_band(q, why)
        elif ref > 0:
            indicators[f"{q.name}_band"] = indicator(
                band / ref,
                tolerance,
                f"the error band of {line(q.name, entry)} over "
                + ("its value" if ref == abs(value) else f"its scale {ref:g}"),
                "the run's tolerance (--tolerance TOL, tolerance= in Python; 5 % by default)",
            )
    section = dict(
        tolerance=tolerance,
        quantities=out,
        runs=len(runs),
        failed_runs=sum(1 for L in runs if L["results"] is None),  # failed, or ran and not used:
        unused_runs=sum(1 for L in runs if L.get("unused")),  # ran, outside the asymptotic range or the quantity's
        wall_time_s=time.perf_counter() - t0,
        method="ladders of coarser runs (2 h, 4 h; finer where needed); Richardson's estimate with Xing & Stern's "
        "factor of safety; the parts by discretisation added",
    )
    return section, indicators


def _worst(classes):
    order = ("divergent", "oscillatory", "monotone", "converged")
    present = [c for c in classes if c is not None]
    if len(present) < len(classes):
        return None
    return min(present, key=order.index, default="converged")


def _no_band(q, why, source="an error band needs monotone levels (Roache; ASME V&V 20)"):
    return dict(
        value=None,
        threshold=None,
        ok=False,
        what=f"no error band of {q.name} could be estimated ({why})",
        source=source,
        bound="at most",
    )


def line(name, entry):
    """'rebound_vy = 1.462 +- 0.12 (time step)': a quantity and its band, as the command line prints it
    (the parts in brackets, largest first)."""
    v, band = entry["value"], entry.get("band")
    unit = f" {entry['unit']}" if entry.get("unit") else ""
    if v is None:
        return f"{name} = -"
    if band is None:
        return f"{name} = {v:.6g}{unit} (no error band)"
    parts = sorted(((p["band"], p["label"]) for p in entry["parts"].values()), reverse=True)
    what = ", ".join(label if len(parts) == 1 else f"{label} {b:.2g}" for b, label in parts)
    return f"{name} = {_digits(v, band)} +- {band:.2g}{unit}" + (f" ({what})" if what else "")


def _digits(v, band):
    """v to the digits its band leaves (one more than the band's first), at least 4 significant."""
    if band <= 0 or v == 0:
        return f"{v:.6g}"
    keep = max(4, int(math.floor(math.log10(abs(v)))) - int(math.floor(math.log10(band))) + 2)
    return f"{v:.{min(keep, 12)}g}"


def _work(scene, params):
    """A run's size as its cost: unknowns times steps (Scene.size; 1 where the scene does not say)."""
    size = scene.size(params) if scene.size is not None else {}
    return float(max(1.0, size.get("unknowns", 1))) * float(max(1.0, size.get("steps", 1)))


def run_level(scene_run, scene, params, overrides):
    """One level of a ladder: the scene at ``params`` with ``overrides`` (checked as a user's values
    are: a level outside a parameter's range, or past the resources a run may take without --force, is
    not taken), without error bars and without its warnings. Returns the results, or the Exception that
    stopped it."""
    try:
        p = scene.with_values(params, overrides)
        check_resources(scene, p)
        ratio = _work(scene, p) / _work(scene, params)
        if ratio > FINER_COST * (1 + 1e-9):
            raise ValueError(f"a level {ratio:.3g} times the run's size is not taken (at most {FINER_COST:g})")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return scene_run(p)
    except (KeyboardInterrupt, SystemExit):
        raise
    except Exception as err:  # noqa: BLE001 (a level that fails is a result of the ladder: a finer one is taken)
        return err
