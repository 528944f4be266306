"""A contact with the ground held fixed: a cut joint between a frame of the robot and the
ground (Jerkovsky 1978 §VI), in the two kinds Crocoddyl and Pinocchio use for legged robots."""

from typing import ClassVar

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.lie.inputs import check_point
from mbjax._src.model.closures import (GROUND, AbstractCutKind, CutJoint, SpatialWeld, Spherical,
                                       Weld, active_flag, cut_joint_groups)
from mbjax._src.model.model import Model
from mbjax._src.rigid.frames import frame_placement, frame_pose
from mbjax._src.tree.take import take


# how far from its ground (`AbstractContact.height`) a contact's frame may be when a stance or
# an impulse starts to hold it [m]
GROUND_TOLERANCE = 1e-3


def _height(height) -> Array:
    """The ground's height as a float scalar; a ValueError naming it where it is concrete and
    not a finite scalar."""
    h = jnp.asarray(height, dtype=float)
    if h.ndim != 0:
        raise ValueError(f"height must be a scalar [m], got shape {h.shape}")
    if not isinstance(h, jax.core.Tracer) and not np.isfinite(float(h)):
        raise ValueError(f"height must be finite, got {float(h)}")
    return h


def on_ground(model: Model, q: Array, contacts) -> None:
    """A ValueError naming the first active contact whose frame is farther than
    `GROUND_TOLERANCE` from its ground in configuration q (where q, active and the height are
    concrete; contacts without a height pass)."""
    for i, contact in enumerate(contacts):
        gap = contact.clearance(model, q)
        if gap is None:
            continue
        try:
            gap, active = float(gap), bool(contact.active)
        except jax.errors.ConcretizationTypeError:
            continue                                   # traced: nobody can raise
        if active and not abs(gap) <= GROUND_TOLERANCE:
            raise ValueError(
                f"contacts[{i}] ({contact.frame!r}) is {gap:.4g} m "
                f"{'above' if gap > 0 else 'below'} its ground (height {float(contact.height):.4g} m along its normal): a stance "
                f"holds a frame where it is, so start it where the frame is on the ground (within "
                f"{GROUND_TOLERANCE:g} m), or give the contact no height to hold it where it is")


def _normal(normal) -> Array:
    """The ground's normal as a unit 3-vector; a ValueError naming it where it is concrete and
    not finite or zero."""
    n = check_point(normal, "normal", "the ground's normal")
    if not isinstance(n, jax.core.Tracer) and not np.linalg.norm(np.asarray(n)) > 0:
        raise ValueError(f"normal must be a nonzero vector, got {np.asarray(n).tolist()}")
    return n / jnp.linalg.norm(n)


class AbstractContact(eqx.Module):
    """A frame of the robot held on the ground: the foot of a stance phase.

    A contact is a closure with the ground (`mbjax.loops.CutJoint` with body_b the ground),
    made at a configuration by `closure`: the frame is held where it is there. Its
    multipliers are the ground's reaction on the frame (`contact_wrenches`).

    Args:
        frame (str): the frame held (a named frame, a body or a joint of the model, as
            `mbjax.rigid.frame_pose` takes it).
        normal (ArrayLike): the ground's normal, world components, shape (3,); z by default.
            Normalized.
        active (ArrayLike): True (the default) for a frame on the ground, False for one in
            the air: its constraint rows vanish and its wrench is zero. An array, so that the
            stances of a gait made of the same contacts, some in the air, share one compiled
            program (`mbjax.trajopt.Problem` compiles each distinct phase once).
        height (ArrayLike | None): where the ground is, the plane normal . x = height [m];
            `stance` and `impulse` then refuse to hold the frame where it is not on it (farther
            than `GROUND_TOLERANCE`). None (the default): the ground is wherever the frame is
            when the stance starts.

    Raises:
        TypeError: frame is not a name.
        ValueError: the normal is not a finite nonzero 3-vector, active is not a boolean, or
            height is not a finite scalar.

    Attributes:
        size: the number of constraints (3 for a point, 6 for a surface).
        kind: the kind of its cut joint (`mbjax.loops.Spherical()` for a point; `Weld()` or
            `SpatialWeld()` for a surface).
    """

    frame: str = eqx.field(static=True)
    normal: Array
    active: Array
    height: Array | None
    size: ClassVar[int]
    kind: ClassVar[AbstractCutKind]

    def __init__(self, frame: str, normal=(0.0, 0.0, 1.0), active=True, height=None):
        if not isinstance(frame, str):
            raise TypeError(f"frame must be a frame's name, got {type(frame).__name__}")
        self.frame = frame
        self.normal = _normal(normal)
        self.active = active_flag(active, "active")
        self.height = None if height is None else _height(height)

    def clearance(self, model: Model, q: Array) -> Array | None:
        """How far the frame is above its ground in configuration q (negative: below), along
        the normal; None where the contact has no height.

        Args:
            model: the robot.
            q: a configuration, shape (nq,).

        Returns:
            The distance [m], a scalar, or None.
        """
        if self.height is None:
            return None
        return jnp.dot(self.normal, frame_pose(model, q, self.frame)[1]) - self.height

    def closure(self, model: Model, q: Array) -> CutJoint:
        """The cut joint that holds the frame at its pose in configuration q.

        Args:
            model: the robot.
            q: the configuration where the contact starts, shape (nq,).

        Returns:
            A `CutJoint` from the frame's body to the ground.

        Raises:
            KeyError: the model has no frame, body or joint called `frame`.
        """
        body, R_f, p_f = frame_placement(model, self.frame)
        R, p = frame_pose(model, q, self.frame)
        return CutJoint(self.kind, int(body), GROUND, origin_a=p_f, origin_b=p, rotation_a=R_f,
                        rotation_b=R, active=self.active)


class PointContact(AbstractContact):
    """A point of the robot held on the ground: 3 constraints (Crocoddyl's `ContactModel3D`,
    Pinocchio's `CONTACT_3D`). The ground pushes on it with a force and no torque.

    Args:
        frame (str): the frame held (a named frame, a body or a joint of the model, as
            `mbjax.rigid.frame_pose` takes it), e.g. "LF_FOOT".
        normal (ArrayLike): the ground's normal, world components, shape (3,); z by default.
            Normalized. The friction cone and the normal force are measured along it.
        active (ArrayLike): True (the default) for a foot on the ground, False for one in the
            air (see `AbstractContact`).
        height (ArrayLike | None): the ground's height along the normal [m], checked where a
            stance starts (see `AbstractContact`); None: wherever the frame is.

    Raises:
        ValueError: the normal is not a finite nonzero 3-vector, or active is not a boolean.
    """

    size: ClassVar[int] = 3
    kind: ClassVar[AbstractCutKind] = Spherical()


class SurfaceContact(AbstractContact):
    """A frame of the robot held flat on the ground: 6 constraints, position and orientation
    (Crocoddyl's `ContactModel6D`, Pinocchio's `CONTACT_6D`): a foot's sole. The ground pushes
    on it with a force and a torque.

    Which acceleration of the sole is held is a convention, the same on the ground (a sole at
    rest) but not for a moving one, nor for the Baumgarte terms' drift:

    - spatial=False (the default), a weld: the residual is the frame's position and
      orientation error (`mbjax.loops.Weld`), whose second derivative is the
      frame's classical acceleration (its origin's acceleration and its angular acceleration).
    - spatial=True: the position rows are the offset in the mean of the frame's and the
      anchor's axes, (R_A + R_B)^T (p_A - p_B) / 2 (`mbjax.loops.SpatialWeld`),
      whose rate on the ground is the frame's twist in its own axes and whose second
      derivative there is its spatial acceleration: what Pinocchio's `CONTACT_6D` and
      Crocoddyl's `ContactModel6D` hold. Rebuild a Crocoddyl or Pinocchio problem with it; the
      two conventions differ by omega x v on a moving sole. (Off the anchor, where a Baumgarte
      position term acts, it agrees with their SE(3) logarithm to first order in the offset.)

    Args:
        frame (str): the frame held, e.g. "left_sole_link".
        normal (ArrayLike): the ground's normal, world components, shape (3,); z by default.
        active (ArrayLike): True (the default) for a sole on the ground, False for one in the
            air (see `AbstractContact`).
        height (ArrayLike | None): the ground's height along the normal [m] (see
            `AbstractContact`); None: wherever the sole is.
        spatial (bool): hold the sole's spatial acceleration, as Pinocchio and Crocoddyl do
            (see above); static.

    Raises:
        ValueError: the normal is not a finite nonzero 3-vector, or active is not a boolean.
    """

    spatial: bool = eqx.field(static=True)
    size: ClassVar[int] = 6

    def __init__(self, frame: str, normal=(0.0, 0.0, 1.0), active=True, height=None, *,
                 spatial: bool = False):
        super().__init__(frame, normal, active, height)
        self.spatial = bool(spatial)

    @property
    def kind(self) -> AbstractCutKind:
        return SpatialWeld() if self.spatial else Weld()


def frame_wrench(joint: CutJoint, R: Array, p: Array, multipliers: Array) -> Array:
    """The wrench that a ground closure's multipliers put on its frame A, (torque about the
    frame's origin; force) in world components: the transpose of the closure's rate along the
    frame's twist (Jerkovsky 1978 eq 93), exact at any pose, so that the frame Jacobian's
    transpose of the wrench is the closure's generalized force A^t K.

    Args:
        joint: the cut joint, to the ground.
        R: the orientation of its body_a, shape (3, 3).
        p: the origin of its body_a [m], shape (3,).
        multipliers: the joint's multipliers, shape (size,).

    Returns:
        The wrench, shape (6,).
    """
    def rate(omega, v):           # the frame's angular velocity and its origin's velocity
        R_dot = jnp.cross(omega, R.T).T
        # the body origin's velocity, with the residual's own term, so that a point's torque
        # cancels exactly
        p_dot = v - R_dot @ joint.origin_a
        return jax.jvp(lambda R_, p_: joint.pose_residual(R_, p_, None, None), (R, p),
                       (R_dot, p_dot))[1]

    zero = jnp.zeros(3, multipliers.dtype)
    torque, force = jax.vjp(rate, zero, zero)[1](multipliers)
    return jnp.concatenate([torque, force])


def wrenches(closures, multipliers: Array, R: Array, p: Array) -> Array:
    """Each ground closure's wrench on its frame (`frame_wrench`) from the stacked multipliers,
    in order, shape (len(closures), 6), the tree's frames at (R, p) ((n_frames, 3, 3),
    (n_frames, 3))."""
    starts = np.cumsum([0] + [j.size for j in closures])
    pieces, order = [], []
    for idx, template, stacked in cut_joint_groups(closures):   # joints alike: one vmap
        bodies = np.array([closures[i].body_a for i in idx])
        rows = np.concatenate([np.arange(starts[i], starts[i + 1]) for i in idx])
        pieces.append(jax.vmap(lambda arrays, R_, p_, K: frame_wrench(
            eqx.combine(arrays, template), R_, p_, K))(
                stacked, take(R, bodies), take(p, bodies),
                take(multipliers, rows).reshape(len(idx), -1)))
        order += idx
    out = jnp.concatenate(pieces)
    inverse = np.argsort(order)
    return out if np.array_equal(inverse, np.arange(len(order))) else take(out, inverse)
