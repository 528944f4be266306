"""Animations of a mechanism moving: a 3-D stick-and-frame view, written as a GIF.

`stick_animation` draws, at each saved state, a stick from every body's frame origin to its
parent's (the ground origin for a base body), each frame's axes as a small red-green-blue triad,
and the path of one chosen point (a tool, a flange, a tip). It takes the world poses that every
tree system's `frames(q)` returns (`mbjax.rigid.TreeSystem`, `mbjax.flex.FlexibleSystem`, a
`ClosedSystem`'s tree; a robot loaded from URDF or MJCF included), so any model animates without
code of its own. `frames_along` evaluates them along a trajectory in one vmapped call;
`animate` picks the picture for any system (`wrist_animation` for the Carpal Wrist, whose legs
are not a tree).
"""

from collections.abc import Sequence
from pathlib import Path

import jax
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator
from PIL import Image

from mbjax.wrist import WristSystem
from mbjax_harness.progress import step

__all__ = ["animate", "frames_along", "gait_animation", "geom_animation", "stick_animation",
           "wrist_animation", "write_gif"]

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


def _scene(limits):
    """A figure and its 3-D axes over `limits` ((x, y, z) ranges [m]), equal scales."""
    fig = Figure(figsize=(5.2, 5.2), layout="constrained")
    ax = fig.add_subplot(projection="3d")
    ax.set(xlim=limits[0], ylim=limits[1], zlim=limits[2], xlabel="x [m]", ylabel="y [m]",
           zlabel="z [m]")
    ax.set_box_aspect((1, 1, 1))
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_major_locator(MaxNLocator(4))      # tick labels that never run into each other
    return fig, ax


def stick_animation(path: Path, ts, R, p, parents, *, title: str = "",
                    trace: int | Sequence[int] | None = None, axis_length: float | None = None,
                    frames: int = 60, fps: int = 15, triads: bool | Sequence[int] = True,
                    view: tuple[float, float] | None = None, anchors=None) -> Path:
    """Write a GIF of the mechanism moving.

    ts (T,): save times; R (T, m, 3, 3), p (T, m, 3): world poses of the m frames at each time
    (the first len(parents) are bodies; any further ones, markers or named frames, are drawn as
    triads only); parents: each body's parent (-1: the ground); trace: the frame, or frames, whose
    origin leaves a path (default: the last body); axis_length: the triads' length (default: a
    tenth of the motion's extent); triads: True draws every frame's triad, False none (a beam's
    centreline as a chain of points, say), a sequence the triads of those frames; view: the
    camera's (elevation, azimuth) in degrees, (90, -90) looking down on the x-y plane; anchors
    (n, 3): where each base body's stick starts (default: the ground origin; anchored at its own
    origin or at NaN, a body is a dot). At most `frames` of the saved states are drawn, evenly
    spaced."""
    step(f"animation {Path(path).name}")
    ts, R, p = np.asarray(ts), np.asarray(R), np.asarray(p)
    parents = np.asarray(parents, dtype=int)
    n = len(parents)
    keep = np.unique(np.linspace(0, len(ts) - 1, min(frames, len(ts))).round().astype(int))
    anchors = np.zeros((n, 3)) if anchors is None else np.asarray(anchors, dtype=float)
    fixed = anchors[parents < 0]
    limits = _limits(np.concatenate([p.reshape(-1, 3), fixed[np.isfinite(fixed).all(axis=1)]]))
    length = axis_length or 0.1 * (limits[0][1] - limits[0][0])
    traced = [n - 1] if trace is None else list(np.atleast_1d(trace))
    with_triads = range(p.shape[1]) if triads is True else [] if triads is False else list(triads)

    fig, ax = _scene(limits)
    if view is not None:
        ax.view_init(*view)
        if abs(view[0]) == 90:          # looking along z: its ticks would pile up on one corner
            ax.set_zticks([])
            ax.set_zlabel("")
    sticks = [ax.plot([], [], [], "-o", color="0.25", lw=2.5, ms=3)[0] for _ in range(n)]
    triad_lines = {f: [ax.plot([], [], [], color=c, lw=1.2)[0] for c in AXIS_COLORS]
                   for f in with_triads}
    paths = {f: ax.plot([], [], [], color="#9467bd", lw=1, alpha=0.7)[0] for f in traced}
    label = ax.set_title("")

    def draw(i):
        k = keep[i]
        for body, stick in enumerate(sticks):
            start = p[k, parents[body]] if parents[body] >= 0 else anchors[body]
            seg = np.stack([start, p[k, body]])
            stick.set_data_3d(seg[:, 0], seg[:, 1], seg[:, 2])
        for f, triad in triad_lines.items():
            for a, line in enumerate(triad):
                seg = np.stack([p[k, f], p[k, f] + length * R[k, f, :, a]])
                line.set_data_3d(seg[:, 0], seg[:, 1], seg[:, 2])
        for f, line in paths.items():
            trail = p[keep[:i + 1], f]
            line.set_data_3d(trail[:, 0], trail[:, 1], trail[:, 2])
        label.set_text(f"{title}  t = {ts[k]:.2f} s".strip())
        return [*sticks, *(line for triad in triad_lines.values() for line in triad),
                *paths.values(), label]

    return write_gif(path, fig, draw, len(keep), fps)


def _holder(model, name: str) -> int:
    """The body that the frame, body or joint called `name` moves with, looked up as
    `mbjax.rigid.frame_pose` does: a named frame's body (`Model.frame_parents`), else the body or
    the joint's body."""
    if name in model.frame_names:
        return int(model.frame_parents[model.frame_names.index(name)])
    return (model.names if name in model.names else model.joint_names).index(name)


def gait_animation(path: Path, tree, ts, qs, feet: Sequence[str], forces, mu: float, *,
                   title: str = "", frames: int = 60, reach: float = 0.3) -> Path:
    """Write a GIF of a legged robot walking: its bodies as sticks down to its feet (the
    floating base a dot), and at each foot on the ground the ground's force as an arrow (the
    largest `reach` metres long) inside its friction cone (half-angle arctan mu about the
    vertical).

    ts (T,): times; qs (T, nq): configurations; feet: the feet's frame names; forces (T, F, 3):
    the ground's force on each foot [N], zero where the foot is in the air."""
    from mbjax.rigid import frame_pose

    step(f"animation {Path(path).name}")
    ts, forces = np.asarray(ts), np.asarray(forces)
    model = tree.model
    R, p = frames_along(tree, qs)
    parents = np.asarray(model.topology.parents, dtype=int)
    n = len(parents)
    p = np.asarray(p)[:, :n]
    holders = [_holder(model, f) for f in feet]
    feet = np.asarray(jax.jit(jax.vmap(lambda q: jax.numpy.stack(
        [frame_pose(model, q, f)[1] for f in feet])))(qs))
    keep = np.unique(np.linspace(0, len(ts) - 1, min(frames, len(ts))).round().astype(int))
    limits = _limits(np.concatenate([p.reshape(-1, 3), feet.reshape(-1, 3)]))
    scale = reach / max(float(np.linalg.norm(forces, axis=-1).max()), 1e-12)
    ground = float(feet[..., 2].min())
    height = 0.6 * reach
    circle = np.linspace(0.0, 2 * np.pi, 25)

    fig, ax = _scene(limits)
    for x in np.linspace(*limits[0], 5):        # the ground
        ax.plot([x, x], limits[1], [ground, ground], color="0.8", lw=0.6)
    for y in np.linspace(*limits[1], 5):
        ax.plot(limits[0], [y, y], [ground, ground], color="0.8", lw=0.6)
    sticks = [ax.plot([], [], [], "-o", color="0.25", lw=2.5, ms=3)[0]
              for _ in range(n + len(holders))]
    arrows = [ax.plot([], [], [], color="#d62728", lw=2)[0] for _ in range(feet.shape[1])]
    cones = [[ax.plot([], [], [], color="#1f77b4", lw=0.8, alpha=0.7)[0] for _ in range(5)]
             for _ in range(feet.shape[1])]
    label = ax.set_title("")

    def draw(i):
        k = keep[i]
        ends = [(p[k, parents[b]] if parents[b] >= 0 else p[k, b], p[k, b]) for b in range(n)]
        ends += [(p[k, b], feet[k, i]) for i, b in enumerate(holders)]
        for stick, seg in zip(sticks, ends, strict=True):
            seg = np.stack(seg)
            stick.set_data_3d(seg[:, 0], seg[:, 1], seg[:, 2])
        for foot, (arrow, cone) in enumerate(zip(arrows, cones, strict=True)):
            apex, f = feet[k, foot], forces[k, foot]
            if not np.any(f):                     # in the air: nothing drawn
                for line in (arrow, *cone):
                    line.set_data_3d([], [], [])
                continue
            seg = np.stack([apex, apex + scale * f])
            arrow.set_data_3d(seg[:, 0], seg[:, 1], seg[:, 2])
            rim = apex + np.stack([mu * height * np.cos(circle), mu * height * np.sin(circle),
                                   np.full_like(circle, height)], axis=1)
            cone[0].set_data_3d(rim[:, 0], rim[:, 1], rim[:, 2])
            for line, j in zip(cone[1:], (0, 6, 12, 18), strict=True):
                line.set_data_3d([apex[0], rim[j, 0]], [apex[1], rim[j, 1]], [apex[2], rim[j, 2]])
        label.set_text(f"{title}  t = {ts[k]:.2f} s".strip())
        return [*sticks, *arrows, *(line for cone in cones for line in cone), label]

    return write_gif(path, fig, draw, len(keep), fps=15)


def geom_animation(path: Path, ts, panels: Sequence[tuple[str, np.ndarray, np.ndarray]], *,
                   title: str = "", frames: int = 60, fps: int = 15, columns: int = 2) -> Path:
    """Write a GIF of robots drawn by their collision geometry, one 3-D panel each, on a floor.

    Args:
        path: the GIF's path.
        ts: the save times, (T,).
        panels: (title, segments, radii) per panel: each capsule's axis as a segment from end
            to end, a sphere's (or box's) centre twice, in world coordinates, (T, g, 2, 3) [m];
            the geoms' radii, (g,) [m] (a line's width follows its radius).
        title: the figure's title, followed by the time.
        frames: at most this many of the saved states, evenly spaced.
        fps: frames per second.
        columns: panels per row.

    Returns:
        The path.
    """
    step(f"animation {Path(path).name}")
    ts = np.asarray(ts)
    keep = np.unique(np.linspace(0, len(ts) - 1, min(frames, len(ts))).round().astype(int))
    rows = -(-len(panels) // columns)
    fig = Figure(figsize=(3.4 * columns, 3.2 * rows + 0.4), layout="constrained")
    lines = []
    for index, (name, segments, radii) in enumerate(panels):
        segments = np.asarray(segments)
        centre = segments[:, :, :, :2].reshape(-1, 2).mean(0)
        half = max(float(np.ptp(segments[..., :2].reshape(-1, 2), axis=0).max()) / 2, 0.5)
        top = max(float(segments[..., 2].max()), 0.5)
        ax = fig.add_subplot(rows, columns, index + 1, projection="3d")
        ax.set(xlim=(centre[0] - half, centre[0] + half), ylim=(centre[1] - half, centre[1] + half),
               zlim=(0.0, top), title=name)
        ax.set_box_aspect((2 * half, 2 * half, top))
        ax.view_init(18, -60)
        for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
            axis.set_major_locator(MaxNLocator(3))
        floor = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1], [-1, -1]]) * half + centre
        ax.plot(floor[:, 0], floor[:, 1], 0.0, color="0.6", lw=1)
        widths = 2 + 60 * np.asarray(radii, float)
        lines.append([(ax.plot([], [], [], "-", color="#1f77b4", lw=w, solid_capstyle="round",
                                marker="o", ms=w)[0], segments) for w in widths])
    label = fig.suptitle("")

    def draw(i):
        k = keep[i]
        moving = []
        for panel in lines:
            for g, (line, segments) in enumerate(panel):
                seg = segments[k, g]
                line.set_data_3d(seg[:, 0], seg[:, 1], seg[:, 2])
                moving.append(line)
        label.set_text(f"{title}  t = {ts[k]:.2f} s".strip())
        return [*moving, label]

    return write_gif(path, fig, draw, len(keep), fps)


def write_gif(path: Path, fig: Figure, draw, frames: int, fps: int, dpi: int = 72) -> Path:
    """Write `frames` frames of `fig` as a GIF: its still parts (axes, panes, ticks, labels)
    rendered once, then for frame i only the artists `draw(i)` updates and returns, drawn over a
    copy of them (blitting, where matplotlib's writers redraw the whole 3-D axes for every
    frame). All frames share one palette.

    Args:
        path: the GIF's path (its folder is made if missing).
        fig: the figure, its moving artists at any state.
        draw: draw(i) sets the moving artists to frame i and returns them (the same artists
            for every i).
        frames: the number of frames.
        fps: frames per second.
        dpi: the resolution.

    Returns:
        The path.
    """
    fig.set_dpi(dpi)
    canvas = FigureCanvasAgg(fig)
    moving = draw(0)
    canvas.draw()                       # lays out the figure and places the moving artists
    fig.set_layout_engine("none")       # (a title, say) as a full draw would
    for artist in moving:
        artist.set_animated(True)       # left out of the still parts' draw
    canvas.draw()
    still = canvas.copy_from_bbox(fig.bbox)
    rgb = []
    for i in range(frames):
        canvas.restore_region(still)
        for artist in draw(i):
            fig.draw_artist(artist)
        rgb.append(np.array(canvas.buffer_rgba())[..., :3])
    # one palette for every frame, from all of them stacked (a third of the time of a palette
    # per frame, and the colours exact where there are at most 255)
    stack = Image.fromarray(np.concatenate(rgb)).quantize(255)
    height = rgb[0].shape[0]
    images = [stack.crop((0, i * height, stack.width, (i + 1) * height)) for i in range(frames)]
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    images[0].save(path, save_all=True, append_images=images[1:], duration=round(1000 / fps),
                   loop=0)
    return path


def animate(path: Path, system, ts, qs, *, title: str = "", frames: int = 60) -> Path:
    """Write a GIF of any mbjax system moving through the saved configurations qs at times ts:
    the Carpal Wrist's legs and plates (`wrist_animation`), a closed loop's spanning tree with a
    stick from each body of a cut joint to the joint's frame on it (so the loop is seen closed),
    or a tree system's bodies (`stick_animation` of its `frames`)."""
    if isinstance(system, WristSystem):
        return wrist_animation(path, system.model, ts, qs, title=title, frames=frames)
    tree = getattr(system, "tree", system)          # a ClosedSystem draws its tree
    R, p = frames_along(tree, qs)
    parents = list(tree.model.topology.parents)
    n, m = len(parents), p.shape[1]                # bodies, then markers or named frames
    anchors = np.zeros((n, 3))
    extra = []                                      # (parent body or -1, points (T, 3), anchor)
    for joint in getattr(system, "closures", ()):
        if not hasattr(joint, "origin_a"):          # a prescribed motion: nothing to draw
            continue
        a, b = joint.body_a, joint.body_b
        extra.append((a, p[:, a] + R[:, a] @ np.asarray(joint.origin_a), None))
        if b >= 0:
            extra.append((b, p[:, b] + R[:, b] @ np.asarray(joint.origin_b), None))
        else:                                       # on the ground: a fixed dot
            extra.append((-1, np.broadcast_to(np.asarray(joint.origin_b), p[:, 0].shape),
                          np.asarray(joint.origin_b)))
    if extra:
        body_R, body_p = R[:, :n], p[:, :n]
        points = np.stack([points for _, points, _ in extra], axis=1)
        R = np.concatenate([body_R, np.broadcast_to(np.eye(3), (*points.shape[:2], 3, 3)),
                            R[:, n:]], axis=1)
        p = np.concatenate([body_p, points, p[:, n:]], axis=1)
        anchors = np.concatenate([anchors, [np.zeros(3) if anchor is None else anchor
                                            for _, _, anchor in extra]])
        parents += [parent for parent, _, _ in extra]
    triads = [*range(n), *range(n + len(extra), m + len(extra))]   # not the cut joints' points
    return stick_animation(path, ts, R, p, parents, title=title, frames=frames,
                           trace=n - 1, triads=triads, anchors=anchors)


def wrist_animation(path: Path, wrist, ts, thetas, *, title: str = "", frames: int = 60) -> Path:
    """Write a GIF of the Carpal Wrist moving through the input angles thetas (T, 3): the three
    legs (base revolute, knee, distal revolute: `CarpalWrist.leg_points`), the base and distal
    plates, and the tool (its frame at the plate's centre, a stick along its axis whose end
    leaves its path)."""
    legs = np.asarray(jax.jit(jax.vmap(wrist.leg_points))(thetas))   # (T, joint, leg, 3)
    pose = jax.jit(jax.vmap(wrist.forward_kinematics))(thetas)
    centre, R = np.asarray(pose.centre), np.asarray(pose.rotation)
    b, m, d = legs[:, 0], legs[:, 1], legs[:, 2]
    tip = centre + 0.8 * float(wrist.base_radius) * R[:, :, 2]
    # frames: b (dots), m, d (the legs), the plates' edges, the tool's centre and tip
    p = np.concatenate([b, m, d, d[:, [1, 2, 0]], b[:, [1, 2, 0]], centre[:, None], tip[:, None]],
                       axis=1)
    parents = [-1, -1, -1, 0, 1, 2, 3, 4, 5, 6, 7, 8, 0, 1, 2, -1, 15]
    anchors = np.zeros((17, 3))
    anchors[:3] = b[0]          # dots at the base revolutes
    anchors[15] = np.nan        # the tool's frame at the moving plate centre: no stick to it
    Rs = np.broadcast_to(R[:, None], (len(R), 17, 3, 3))
    return stick_animation(path, ts, Rs, p, parents, anchors=anchors, title=title, trace=16,
                           triads=[15], frames=frames)
