"""Study 1, tangents: the paper's central claim (Sec. 4.2). Newton with the consistent
non-symmetric tangent (eqs 49-50) against a symmetrised tangent, the tangent without the
coupling c_N^s C ("frozen") and the staggered normal-then-friction algorithm of Sec. 2.2
(contactfem.solver.staggered), on the block (Sec. 5.1) and the frictional sloping impact
(Sec. 5.3): linear solves and time to the same tolerance; divergence is recorded."""

import time

import numpy as np

from ...scenes import block, get_scene, sloping_impact
from ...solver import Newmark, NewtonError, Static, integrate
from ...solver.staggered import Staggered


def _block_variant(params, variant):
    """One block solve (whole load in one step) with a tangent variant or the staggered
    algorithm: dict(converged, iterations, time_s, u or error)."""
    t0 = time.perf_counter()
    try:
        if variant == "staggered":
            b = block.build(dict(params, tangent="consistent"))
            system = b.system
            stepper = Staggered(
                Static(system, atol=params["atol"], rtol=params["rtol"], maxit=params["maxit"]), max_cycles=200
            )
            u = np.zeros(system.ndof)
            u, _, _, res = stepper.step(0.0, u, u, u, 1.0, label="block, staggered", state=system.start(u))
            extra = dict(cycles=res.cycles, phase_iterations=res.phase_iterations)
        else:
            s = block.solve(dict(params, tangent=variant))
            u, res, extra = s["u"], s["result"], {}
    except NewtonError as err:
        return dict(
            converged=False,
            iterations=None,
            time_s=time.perf_counter() - t0,
            error=str(err).splitlines()[0][:200],
            residuals=list(err.history)[:12],
        )
    return dict(
        converged=True,
        iterations=int(res.iterations),
        time_s=time.perf_counter() - t0,
        residuals=list(res.residuals),
        u=u,
        **extra,
    )


def _impact_variant(params, variant):
    """The frictional sloping impact (Sec. 5.3) with a tangent variant or the staggered
    algorithm: total linear solves, step cutbacks, rebound velocity."""
    tangent = "consistent" if variant == "staggered" else variant
    m = sloping_impact.build(dict(params, tangent=tangent))
    ring, system = m.parts["ring"], m.system
    newmark = Newmark(system, params["delta"], params["beta_newmark"], atol=1e-10, rtol=1e-10, maxit=30)
    stepper = Staggered(newmark, max_cycles=100) if variant == "staggered" else newmark
    u0 = np.zeros(ring.body.ndof)
    t0 = time.perf_counter()
    try:
        hist = integrate(
            stepper,
            0.0,
            u0,
            ring.initial_velocity((params["vx0"], params["vy0"])),
            n_steps=params["n_steps"],
            dt=params["dt"],
            cutback=True,
            max_cuts=6,
        )
    except NewtonError as err:
        part = getattr(err, "partial", None)
        return dict(
            converged=False,
            iterations=None,
            time_s=time.perf_counter() - t0,
            error=str(err).splitlines()[0][:200],
            steps_done=int(len(part.t) - 1) if part is not None else None,
        )
    vx, vy = ring.velocity_of_mass(hist.v)
    return dict(
        converged=True,
        iterations=int(np.sum(hist.iterations)),
        time_s=time.perf_counter() - t0,
        step_cuts=int(np.sum(hist.cuts)),
        rebound_vx=float(vx),
        rebound_vy=float(vy),
        max_iterations_per_step=int(np.max(hist.iterations)),
    )


VARIANTS = ("consistent", "symmetric", "frozen", "staggered")


def tangent_study(quick=False):
    """Study 1 (module docstring). The block with Coulomb (mu = 0.3) and the parabolic law
    (paper Table 1); the frictional sloping impact (paper data, 200 steps; 60 if quick)."""
    block = get_scene("block")
    out = {"block": {}, "sloping_impact": {}}
    _block_variant(block.resolve("paper", {"law": "coulomb"}), "consistent")  # warm-up: first-call costs untimed
    for law in ("coulomb",) if quick else ("coulomb", "parabolic"):
        params = block.resolve("paper", {"law": law})
        rows = {v: _block_variant(params, v) for v in VARIANTS}
        ref = rows["consistent"].get("u")
        for r in rows.values():
            u = r.pop("u", None)
            if ref is not None and u is not None:
                r["max_difference_to_consistent"] = float(np.max(np.abs(u - ref)))
        out["block"][law] = rows
    impact = get_scene("sloping_impact")
    params = impact.resolve("paper", {"variant": "frictional", **({"n_steps": 40} if quick else {})})
    out["sloping_impact"] = {v: _impact_variant(params, v) for v in VARIANTS}
    out["sloping_impact_steps"] = params["n_steps"]
    return out
