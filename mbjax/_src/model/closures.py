"""Loop closures: cut joints and prescribed motions as holonomic constraints Phi(q, t) = 0
(Jerkovsky 1978 eq 85, Anderson 1993 eq 87).

A closed chain is modelled as a spanning tree (`mbjax.model.Model`) plus cut joints. A cut joint
ties a frame A fixed in body `body_a` to a frame B fixed in body `body_b` (or in the ground,
body_b = -1); each frame is a placement (rotation, origin) in its body's frame, and the joint's
axis is the frame's z axis. Its residual for each kind, with its number of equations, is in
`CutJoint`'s docstring.

A `Coupling` ties one configuration coordinate to another, q_a = multiplier q_b + offset (URDF's
mimic joints, which `load_urdf` returns in `Model.closures`; the form of MJCF's joint equality,
which `load_mjcf` does not map). A `Prescribed` motion drives one velocity coordinate,
q_j = q0 + rate t (a rheonomic constraint,
e.g. a crank turning at constant speed), or q_j = motion(t) for any differentiable motion (a
spin-up profile): its velocity and acceleration terms come from autodiff in t.

Planar mechanisms' redundant equations are detected and reported by the solvers
(`mbjax._src.loops.coupled`).
"""

import abc
from collections.abc import Callable
from typing import ClassVar

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.lie.inputs import check_point, check_rotation
from mbjax._src.tree.take import take

GROUND = -1             # the ground as a body index (`CutJoint`'s body_b)


def _vee_antisym(R: Array) -> Array:
    """vee((R - R^T) / 2): sin(angle) * axis, zero at R = I."""
    return 0.5 * jnp.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])


def _orientation(RA: Array, RB: Array) -> Array:
    """vee((R_B^T R_A - R_A^T R_B) / 2): the orientation error of frame A in frame B."""
    return _vee_antisym(RB.T @ RA)


class AbstractCutKind(eqx.Module):
    """What a `CutJoint` holds (`Spherical`, `Revolute`, `Universal`, `Weld`, `SpatialWeld`,
    `Prismatic`, `PointOnLine`, `PointOnPlane`), passed to it as `kind`.

    A subclass sets `size`, its number of equations, and implements `residual`.
    """

    size: ClassVar[int]

    @abc.abstractmethod
    def residual(self, d: Array, RA: Array, RB: Array) -> Array:
        """Phi of the joint from its frames' world poses.

        Args:
            d: p_A - p_B, frame A's origin less frame B's, world components [m], shape (3,).
            RA: frame A's rotation in the world, shape (3, 3).
            RB: frame B's rotation in the world, shape (3, 3).

        Returns:
            The residual, shape (size,).
        """


class Spherical(AbstractCutKind):
    """A ball joint: the origins coincide, p_A - p_B = 0 (3 equations)."""

    size: ClassVar[int] = 3

    def residual(self, d: Array, RA: Array, RB: Array) -> Array:
        """p_A - p_B, shape (3,) (arguments as `AbstractCutKind.residual`)."""
        return d


class Revolute(AbstractCutKind):
    """A hinge about the frames' common z axis: the origins coincide and z_A is normal to x_B
    and y_B (5 equations)."""

    size: ClassVar[int] = 5

    def residual(self, d: Array, RA: Array, RB: Array) -> Array:
        """(p_A - p_B, z_A . x_B, z_A . y_B), shape (5,) (arguments as
        `AbstractCutKind.residual`)."""
        z_A, (x_B, y_B, _) = RA.T[2], RB.T
        return jnp.concatenate([d, jnp.stack([z_A @ x_B, z_A @ y_B])])


class Universal(AbstractCutKind):
    """A Hooke joint: the origins coincide and x_A is normal to y_B (4 equations)."""

    size: ClassVar[int] = 4

    def residual(self, d: Array, RA: Array, RB: Array) -> Array:
        """(p_A - p_B, x_A . y_B), shape (4,) (arguments as `AbstractCutKind.residual`)."""
        return jnp.concatenate([d, (RA.T[0] @ RB.T[1])[None]])


class Weld(AbstractCutKind):
    """A rigid connection: the origins coincide and the frames are aligned (6 equations); the
    position rows in world components."""

    size: ClassVar[int] = 6

    def residual(self, d: Array, RA: Array, RB: Array) -> Array:
        """(p_A - p_B, vee((R_B^T R_A - R_A^T R_B) / 2)), shape (6,) (arguments as
        `AbstractCutKind.residual`)."""
        return jnp.concatenate([d, _orientation(RA, RB)])


class SpatialWeld(AbstractCutKind):
    """A rigid connection whose position rows are in the mean of the frames' axes,
    (R_A + R_B)^T (p_A - p_B) / 2, so that their second derivative at rest is the spatial
    acceleration (6 equations)."""

    size: ClassVar[int] = 6

    def residual(self, d: Array, RA: Array, RB: Array) -> Array:
        """((R_A + R_B)^T d / 2, vee((R_B^T R_A - R_A^T R_B) / 2)), shape (6,) (arguments as
        `AbstractCutKind.residual`)."""
        return jnp.concatenate([0.5 * (RA + RB).T @ d, _orientation(RA, RB)])


class Prismatic(AbstractCutKind):
    """A slider along frame B's z axis: the offset has no x_B or y_B part and the frames are
    aligned (5 equations)."""

    size: ClassVar[int] = 5

    def residual(self, d: Array, RA: Array, RB: Array) -> Array:
        """(d . x_B, d . y_B, vee((R_B^T R_A - R_A^T R_B) / 2)), shape (5,) (arguments as
        `AbstractCutKind.residual`)."""
        x_B, y_B, _ = RB.T
        return jnp.concatenate([jnp.stack([d @ x_B, d @ y_B]), _orientation(RA, RB)])


class PointOnLine(AbstractCutKind):
    """Frame A's origin on frame B's z line: d . x_B = d . y_B = 0 (2 equations; a planar
    pin)."""

    size: ClassVar[int] = 2

    def residual(self, d: Array, RA: Array, RB: Array) -> Array:
        """(d . x_B, d . y_B), shape (2,) (arguments as `AbstractCutKind.residual`)."""
        x_B, y_B, _ = RB.T
        return jnp.stack([d @ x_B, d @ y_B])


class PointOnPlane(AbstractCutKind):
    """Frame A's origin on frame B's xy plane: d . z_B = 0 (1 equation; a massless slider
    pinned to a planar mechanism)."""

    size: ClassVar[int] = 1

    def residual(self, d: Array, RA: Array, RB: Array) -> Array:
        """(d . z_B,), shape (1,) (arguments as `AbstractCutKind.residual`)."""
        return (d @ RB.T[2])[None]


_KIND_NAMES = {"spherical": "Spherical()", "revolute": "Revolute()", "universal": "Universal()",
               "weld": "Weld()", "spatial_weld": "SpatialWeld()", "prismatic": "Prismatic()",
               "point_on_line": "PointOnLine()", "point_on_plane": "PointOnPlane()"}


def check_cut_kind(kind) -> AbstractCutKind:
    """`kind` itself, or a TypeError naming the argument and the kinds.

    Raises:
        TypeError: kind is not a cut-joint kind (the strings of earlier versions included).
    """
    if not isinstance(kind, AbstractCutKind):
        hint = (f" (the string {kind!r} is no longer accepted: use mbjax.loops."
                f"{_KIND_NAMES[kind]})" if isinstance(kind, str) and kind in _KIND_NAMES else "")
        raise TypeError(f"kind must be a cut-joint kind, one of mbjax.loops."
                        f"{', '.join(_KIND_NAMES.values())}, got {type(kind).__name__}{hint}")
    return kind


def active_flag(active, name: str) -> Array:
    """A joint's `active` flag as a float scalar array (1.0 held, 0.0 let go), or a ValueError
    naming it where it is concrete and not a boolean scalar."""
    if isinstance(active, str | bytes):
        raise TypeError(f"{name} must be True or False, got the string {active!r}")
    value = jnp.asarray(active, dtype=float)
    if value.ndim != 0:
        raise ValueError(f"{name} must be True or False, got shape {value.shape}")
    if not isinstance(value, jax.core.Tracer) and float(value) not in (0.0, 1.0):
        raise ValueError(f"{name} must be True or False, got {float(value)!r}")
    return value


class CutJoint(eqx.Module):
    """A joint between frame A in body `body_a` and frame B in body `body_b` (-1: the ground),
    cut to make the mechanism a tree; its residual Phi(q, t) = 0 per kind is listed in
    docs/details.md.

    A closed chain is modelled as a spanning tree (`mbjax.model.Model`) plus cut joints. Each
    frame is a placement (rotation, origin) in its body's frame; the joint's axis is the frame's
    z axis. For a flexible tree, `body_a` and `body_b` may also be marker frames (n, n + 1, ...).

    Args:
        kind (AbstractCutKind): what the joint holds: `Spherical()`, `Revolute()`,
            `Universal()`, `Weld()`, `SpatialWeld()`, `Prismatic()`, `PointOnLine()` or
            `PointOnPlane()`; static.
        body_a: the body (frame index) of frame A, >= 0; static.
        body_b: the body of frame B, or `GROUND` (-1); static.
        origin_a (Array): origin of frame A in body_a's frame [m], shape (3,).
        origin_b (Array): origin of frame B in body_b's frame (or the world) [m], shape (3,).
        rotation_a (Array | None): rotation of frame A in body_a's frame, shape (3, 3); None: the
            identity.
        rotation_b (Array | None): rotation of frame B in body_b's frame, shape (3, 3); None: the
            identity.
        active (ArrayLike): True (the default) to hold the joint, False to let it go: its
            residual is multiplied by it, so its rows of the constraint Jacobian vanish and its
            multipliers are zero. An array, not a static flag: systems that differ only in
            which joints hold (the stances of a gait, a foot in the air) share one compiled
            program.

    Raises:
        ValueError: the same body twice, the ground as body_a, an origin not
            of shape (3,), a rotation that is not one (orthonormal within 1e-6, det +1), or an
            `active` that is not a boolean scalar.
        TypeError: a kind that is not a cut-joint kind (a string, say), body indices that are
            not ints.

    More on residuals: the documentation site's Details page (docs/details.md).
    """

    kind: AbstractCutKind = eqx.field(static=True)
    body_a: int = eqx.field(static=True)
    body_b: int = eqx.field(static=True)
    rotation_a: Array
    origin_a: Array
    rotation_b: Array
    origin_b: Array
    active: Array

    def __init__(self, kind: AbstractCutKind, body_a: int, body_b: int = GROUND, *,
                 origin_a=(0.0, 0.0, 0.0), origin_b=(0.0, 0.0, 0.0), rotation_a=None,
                 rotation_b=None, active=True):
        kind = check_cut_kind(kind)
        if not (isinstance(body_a, int | np.integer) and isinstance(body_b, int | np.integer)):
            raise TypeError("body_a and body_b must be body indices (int; -1 for the ground)")
        if body_a == body_b:
            raise ValueError(f"a cut joint needs two different bodies, got body {body_a} twice")
        if body_a < 0:
            raise ValueError("body_a must be a body of the model (the ground can only be body_b)")
        self.kind, self.body_a, self.body_b = kind, int(body_a), int(body_b)
        self.rotation_a = check_rotation(np.eye(3) if rotation_a is None else rotation_a,
                                         f"cut joint {kind!r}: rotation_a")
        self.rotation_b = check_rotation(np.eye(3) if rotation_b is None else rotation_b,
                                         f"cut joint {kind!r}: rotation_b")
        self.origin_a, self.origin_b = (check_point(x, f"cut joint {kind!r}: {name}", "a point")
                                        for x, name in ((origin_a, "origin_a"),
                                                        (origin_b, "origin_b")))
        self.active = active_flag(active, f"cut joint {kind!r}: active")

    @property
    def size(self) -> int:
        """Number of scalar constraint equations."""
        return self.kind.size

    @property
    def rows(self) -> Array:
        """The number of equations held: `size`, or 0 where the joint is let go (`active`)."""
        return self.size * self.active

    def residual(self, R: Array, p: Array, q: Array, t) -> Array:
        """Phi of this joint from the frames' world poses (zero where it is let go).

        Args:
            R: rotations of the tree's frames, shape (n_frames, 3, 3).
            p: origins of the tree's frames [m], shape (n_frames, 3).
            q: configuration (unused).
            t: time (unused).

        Returns:
            The residual, shape (size,).
        """
        return self._residual(R, p) * self.active

    def _residual(self, R: Array, p: Array) -> Array:
        if self.body_b == GROUND:
            return self.pose_residual(R[self.body_a], p[self.body_a], None, None)
        return self.pose_residual(R[self.body_a], p[self.body_a], R[self.body_b], p[self.body_b])

    def pose_residual(self, R_a: Array, p_a: Array, R_b: Array | None, p_b: Array | None) -> Array:
        """Phi of this joint, before `active`, from the world poses of body_a and body_b (None
        for the ground), shape (size,)."""
        RA = R_a @ self.rotation_a
        pA = p_a + R_a @ self.origin_a
        if R_b is None:
            RB, pB = self.rotation_b, self.origin_b
        else:
            RB = R_b @ self.rotation_b
            pB = p_b + R_b @ self.origin_b
        return self.kind.residual(pA - pB, RA, RB)


def cut_joint_rows(closures, cut: Callable, other: Callable, frames) -> Array:
    """Every closure's rows, in order: cut(joint, frame_a, frame_b) for the cut joints, other(c)
    for the rest. Cut joints alike but for their arrays and bodies (a stance's feet) are one
    `vmap`, not one program piece each.

    Args:
        closures: the closures, in order.
        cut: (joint, frame_a, frame_b) -> the joint's rows (size,); frame_a the pytree `frames`
            at body_a's row, frame_b at body_b's, or None for the ground.
        other: (closure) -> its rows (size,).
        frames: a pytree of per-frame arrays, each with a first axis of the tree's frames.

    Returns:
        The rows, shape (sum of the closures' sizes,).
    """
    start = np.cumsum([0] + [c.size for c in closures])
    pieces, order = [], []
    for idx, template, stacked in cut_joint_groups(closures):
        joints = [closures[i] for i in idx]
        frame_a = jax.tree.map(lambda x: take(x, np.array([j.body_a for j in joints])), frames)
        frame_b = (None if template.body_b == GROUND else
                   jax.tree.map(lambda x: take(x, np.array([j.body_b for j in joints])), frames))
        rows = jax.vmap(lambda arrays, fa, fb: cut(eqx.combine(arrays, template), fa, fb))(
            stacked, frame_a, frame_b)
        pieces.append(rows.reshape(-1))
        order += [np.arange(start[i], start[i + 1]) for i in idx]
    for i, c in enumerate(closures):
        if not isinstance(c, CutJoint):
            pieces.append(other(c))
            order.append(np.arange(start[i], start[i + 1]))
    rows = jnp.concatenate(pieces)
    inverse = np.argsort(np.concatenate(order))
    return rows if np.array_equal(inverse, np.arange(len(inverse))) else take(rows, inverse)


def cut_joint_groups(closures) -> list:
    """The cut joints as groups alike but for their arrays and bodies: (their places in
    closures, a template (the first's static part), their arrays stacked)."""
    groups = {}
    for i, c in enumerate(closures):
        if isinstance(c, CutJoint):
            arrays, static = eqx.partition(c, eqx.is_array)
            key = (c.kind, c.body_b == GROUND,
                   tuple((a.shape, a.dtype) for a in jax.tree.leaves(arrays)))
            groups.setdefault(key, (static, []))[1].append((i, arrays))
    # the joints' arrays differ in their static part (their bodies): stack leaf by leaf
    return [([i for i, _ in members], static,
             jax.tree.unflatten(jax.tree.structure(members[0][1]),
                                [jnp.stack(a) for a in zip(*[jax.tree.leaves(a)
                                                              for _, a in members])]))
            for static, members in groups.values()]


class Prescribed(eqx.Module):
    """Coordinate `dof` (a 1-dof joint's angle or slide) driven as q0 + rate t, or as motion(t)
    when `motion` is given: a rheonomic constraint q[dof] - motion(t) = 0.

    Args:
        dof: the coordinate's index (in q, which must equal v's layout: nq == nv); static.
        q0 (float): its value at t = 0 [rad or m].
        rate (float): its constant rate [rad/s or m/s].
        motion: a differentiable callable t -> the coordinate's value, replacing q0 + rate t;
            its velocity and acceleration terms come from autodiff in t.

    Raises:
        ValueError: a negative or non-int dof.
        TypeError: a motion that is not callable.
    """

    dof: int = eqx.field(static=True)
    q0: Array
    rate: Array
    motion: Callable | None

    def __init__(self, dof: int, q0=0.0, rate=0.0, motion: Callable | None = None):
        if not isinstance(dof, int | np.integer) or dof < 0:
            raise ValueError(f"dof must be a non-negative int, got {dof!r}")
        if motion is not None and not callable(motion):
            raise TypeError("motion must be a callable t -> coordinate")
        self.dof = int(dof)
        self.q0 = jnp.asarray(q0, float)
        self.rate = jnp.asarray(rate, float)
        self.motion = motion

    @property
    def size(self) -> int:
        """One equation."""
        return 1

    def residual(self, R: Array, p: Array, q: Array, t) -> Array:
        """q[dof] - motion(t), shape (1,) (R and p unused)."""
        if self.motion is not None:
            return (q[self.dof] - self.motion(t))[None]
        return (q[self.dof] - self.q0 - self.rate * t)[None]


class Coupling(eqx.Module):
    """Configuration coordinate `coordinate` tied to `reference`: q_a = multiplier q_b + offset
    (a URDF mimic joint, as `load_urdf` returns it in `Model.closures`; indices into q).

    Args:
        coordinate: the index a of the coupled coordinate in q; static.
        reference: the index b of the coordinate it follows in q; static.
        multiplier (float): the factor on q_b.
        offset (float): the offset [rad or m].

    Raises:
        ValueError: negative or non-int indices, or a coordinate coupled to itself.
    """

    coordinate: int = eqx.field(static=True)
    reference: int = eqx.field(static=True)
    multiplier: Array
    offset: Array

    def __init__(self, coordinate: int, reference: int, multiplier=1.0, offset=0.0):
        for what, value in (("coordinate", coordinate), ("reference", reference)):
            if not isinstance(value, int | np.integer) or value < 0:
                raise ValueError(f"{what} must be a non-negative int, got {value!r}")
        if coordinate == reference:
            raise ValueError(f"coordinate {coordinate} cannot be coupled to itself")
        self.coordinate, self.reference = int(coordinate), int(reference)
        self.multiplier = jnp.asarray(multiplier, float)
        self.offset = jnp.asarray(offset, float)

    @property
    def size(self) -> int:
        """One equation."""
        return 1

    def residual(self, R: Array, p: Array, q: Array, t) -> Array:
        """q_a - multiplier q_b - offset, shape (1,) (R, p and t unused)."""
        return (q[self.coordinate] - self.multiplier * q[self.reference] - self.offset)[None]
