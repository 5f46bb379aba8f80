"""Animations of body outlines over time (the ring rolling, the cork leaving the bottle).

    frames = [[beam.positions(u)] for u in rec.u]          # one list of polylines per frame
    animate_outlines(frames, "ring.gif", times=rec.t, obstacles=[floor.outline((-50, 500))])

GIF through matplotlib's PillowWriter (Pillow comes with matplotlib); MP4 through
FFMpegWriter when ffmpeg is installed.
"""

from pathlib import Path

import numpy as np

from .. import lazy
from ..bodies.continuum import boundary_loop  # noqa: F401  (public here too)

plt = lazy.module("matplotlib.pyplot")
animation = lazy.module("matplotlib.animation")


def _polylines(frame):
    """A frame is one (n, 2) polyline or a list of them; return a list of (n, 2) arrays."""
    a = frame if isinstance(frame, (list, tuple)) else [frame]
    out = [np.asarray(p, dtype=float) for p in a]
    for p in out:
        if p.ndim != 2 or p.shape[1] != 2:
            raise ValueError(f"parameter frames: each polyline must have shape (n, 2), got {p.shape}")
    return out


def animate_outlines(
    frames, path, times=None, obstacles=(), closed=False, fps=20, title="", xlim=None, ylim=None, dpi=80, marks=None
):
    """Draw the polylines of each frame (bodies' outlines, a beam's centreline) and save
    an animation to `path` (.gif or .mp4). `obstacles` are fixed polylines (rigid masters:
    RigidLine.outline(extent), RigidPolyline.outline(), RigidArc.outline()). `closed`
    (bool or one bool per polyline) joins the last point to the first. `marks`: per frame,
    polylines drawn in red that move with a body (a spoke of a ring shows it turning).
    Returns the path."""
    path = Path(path)
    frames = [_polylines(f) for f in frames]
    if not frames:
        raise ValueError("parameter frames is empty: nothing to animate")
    if not fps > 0:
        raise ValueError(f"parameter fps = {fps!r} is out of range: allowed (0, inf)")
    if path.suffix == ".gif":
        writer = animation.PillowWriter(fps=fps)
    elif path.suffix == ".mp4":
        if not animation.FFMpegWriter.isAvailable():
            raise RuntimeError("writing .mp4 needs ffmpeg on the PATH; write a .gif instead")
        writer = animation.FFMpegWriter(fps=fps)
    else:
        raise ValueError(f"parameter path must end in .gif or .mp4, got {path.name!r}")
    times = None if times is None else np.asarray(times, dtype=float)
    if times is not None and len(times) != len(frames):
        raise ValueError(f"parameter times has {len(times)} entries for {len(frames)} frames")
    obstacles = [np.asarray(o, dtype=float) for o in obstacles]
    marks = None if marks is None else [_polylines(m) for m in marks]
    if marks is not None and len(marks) != len(frames):
        raise ValueError(f"parameter marks has {len(marks)} entries for {len(frames)} frames")
    closed = [closed] * len(frames[0]) if isinstance(closed, bool) else list(closed)

    allpts = np.vstack([p for f in frames for p in f] + obstacles)
    lo, hi = allpts.min(axis=0), allpts.max(axis=0)
    pad = 0.05 * max(hi - lo) + 1e-12
    aspect = np.clip((hi[1] - lo[1] + 2 * pad) / (hi[0] - lo[0] + 2 * pad), 0.3, 2.0)
    fig, ax = plt.subplots(figsize=(6.0, 6.0 * aspect))
    ax.set_aspect("equal")
    ax.set_xlim(xlim or (lo[0] - pad, hi[0] + pad))
    ax.set_ylim(ylim or (lo[1] - pad, hi[1] + pad))
    for o in obstacles:
        ax.plot(o[:, 0], o[:, 1], color="0.3", lw=2)
        if len(o) == 2 and abs(o[0, 1] - o[1, 1]) < 1e-12 * (1 + abs(o[0, 1])):  # a floor: hatch below it
            ax.fill_between(o[:, 0], o[:, 1], o[:, 1] - pad, color="0.85", hatch="///", edgecolor="0.6", lw=0)
    lines = [ax.plot([], [], "-", lw=1.5)[0] for _ in frames[0]]
    spokes = [ax.plot([], [], "-o", color="tab:red", lw=1.5, ms=3)[0] for _ in (marks[0] if marks else ())]
    label = ax.set_title(title)

    def draw(k):
        for line, p, c in zip(lines, frames[k], closed):
            q = np.vstack([p, p[:1]]) if c else p
            line.set_data(q[:, 0], q[:, 1])
        for line, m in zip(spokes, marks[k] if marks else ()):
            line.set_data(m[:, 0], m[:, 1])
        if times is not None:
            label.set_text(f"{title}  t = {times[k]:.4g}".strip())
        return lines

    path.parent.mkdir(parents=True, exist_ok=True)
    ax.set_ylim(ylim or (lo[1] - pad, hi[1] + pad))
    with writer.saving(fig, str(path), dpi):
        for k in range(len(frames)):
            draw(k)
            writer.grab_frame()
    plt.close(fig)
    return str(path)
