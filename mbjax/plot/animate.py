"""Animations of a mechanism moving: a 3-D stick-and-frame view, written as a GIF.

`stick_animation` draws, at each saved state, a stick from every body's frame origin to its
parent's (the ground origin for a base body), each frame's axes as a small red-green-blue triad,
and the path of one chosen point (a tool, a flange, a tip). It takes the world poses that every
tree system's `frames(q)` returns (`mbjax.rigid.TreeSystem`, `mbjax.flex.FlexibleSystem`, a
`ClosedSystem`'s tree; a robot loaded from URDF or MJCF included), so any model animates without
code of its own. `frames_along` evaluates them along a trajectory in one vmapped call.
"""

from pathlib import Path

import jax
import numpy as np
from matplotlib.animation import FuncAnimation, PillowWriter
from matplotlib.figure import Figure

from mbjax.progress import step

__all__ = ["frames_along", "stick_animation"]

AXIS_COLORS = ("#d62728", "#2ca02c", "#1f77b4")     # x, y, z


def frames_along(system, qs):
    """(R (T, m, 3, 3), p (T, m, 3)) of the system's frames at each saved configuration."""
    R, p = jax.jit(jax.vmap(system.frames))(qs)
    return np.asarray(R), np.asarray(p)


def _limits(points: np.ndarray):
    """Equal-aspect cube around every point of the motion."""
    lo, hi = points.reshape(-1, 3).min(0), points.reshape(-1, 3).max(0)
    centre, half = (lo + hi) / 2, max(float(np.max(hi - lo)) / 2, 1e-3) * 1.1
    return [(c - half, c + half) for c in centre]


def stick_animation(path: Path, ts, R, p, parents, *, title: str = "", trace: int | None = None,
                    axis_length: float | None = None, frames: int = 60, fps: int = 15,
                    triads: bool = True, view: tuple[float, float] | None = None) -> Path:
    """Write a GIF of the mechanism moving.

    ts (T,): save times; R (T, m, 3, 3), p (T, m, 3): world poses of the m frames at each time
    (the first len(parents) are bodies; any further ones, markers or named frames, are drawn as
    triads only); parents: each body's parent (-1: the ground); trace: the frame whose origin
    leaves a path (default: the last body); axis_length: the triads' length (default: a tenth of
    the motion's extent); triads=False draws the sticks alone (a beam's centreline as a chain of
    points, say); view: the camera's (elevation, azimuth) in degrees, (90, -90) looking down on
    the x-y plane. At most `frames` of the saved states are drawn, evenly spaced."""
    step(f"animation {Path(path).name}")
    ts, R, p = np.asarray(ts), np.asarray(R), np.asarray(p)
    parents = np.asarray(parents, dtype=int)
    n = len(parents)
    keep = np.unique(np.linspace(0, len(ts) - 1, min(frames, len(ts))).round().astype(int))
    limits = _limits(np.concatenate([p.reshape(-1, 3), np.zeros((1, 3))]))
    length = axis_length or 0.1 * (limits[0][1] - limits[0][0])
    trace = n - 1 if trace is None else trace

    fig = Figure(figsize=(5.2, 5.2), layout="constrained")
    ax = fig.add_subplot(projection="3d")
    ax.set(xlim=limits[0], ylim=limits[1], zlim=limits[2], xlabel="x [m]", ylabel="y [m]",
           zlabel="z [m]")
    ax.set_box_aspect((1, 1, 1))
    if view is not None:
        ax.view_init(*view)
    sticks = [ax.plot([], [], [], "-o", color="0.25", lw=2.5, ms=3)[0] for _ in range(n)]
    triads = [[ax.plot([], [], [], color=c, lw=1.2)[0] for c in AXIS_COLORS]
              for _ in range(p.shape[1] if triads else 0)]
    path_line = ax.plot([], [], [], color="#9467bd", lw=1, alpha=0.7)[0]
    label = ax.set_title("")

    def draw(i):
        k = keep[i]
        for body, stick in enumerate(sticks):
            start = p[k, parents[body]] if parents[body] >= 0 else np.zeros(3)
            seg = np.stack([start, p[k, body]])
            stick.set_data_3d(seg[:, 0], seg[:, 1], seg[:, 2])
        for f, triad in enumerate(triads):
            for a, line in enumerate(triad):
                seg = np.stack([p[k, f], p[k, f] + length * R[k, f, :, a]])
                line.set_data_3d(seg[:, 0], seg[:, 1], seg[:, 2])
        trail = p[keep[:i + 1], trace]
        path_line.set_data_3d(trail[:, 0], trail[:, 1], trail[:, 2])
        label.set_text(f"{title}  t = {ts[k]:.2f} s".strip())
        return [*sticks, *(line for triad in triads for line in triad), path_line, label]

    animation = FuncAnimation(fig, draw, frames=len(keep), blit=False)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    animation.save(path, writer=PillowWriter(fps=fps), dpi=72)
    return path
