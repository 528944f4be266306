"""A contact with the ground held fixed: a cut joint between a frame of the robot and the
ground (Jerkovsky 1978 §VI), in the two kinds Crocoddyl and Pinocchio use for legged robots."""

from typing import ClassVar

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.lie.inputs import check_point
from mbjax._src.model.closures import GROUND, CutJoint, active_flag
from mbjax._src.model.model import Model
from mbjax._src.rigid.frames import frame_placement, frame_pose


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

    Raises:
        TypeError: frame is not a name.
        ValueError: the normal is not a finite nonzero 3-vector, or active is not a boolean.

    Attributes:
        size: the number of constraints (3 for a point, 6 for a surface).
        kind: the kind of its cut joint ("spherical" for a point, "weld" for a surface).
    """

    frame: str = eqx.field(static=True)
    normal: Array
    active: Array
    size: ClassVar[int]
    kind: ClassVar[str]

    def __init__(self, frame: str, normal=(0.0, 0.0, 1.0), active=True):
        if not isinstance(frame, str):
            raise TypeError(f"frame must be a frame's name, got {type(frame).__name__}")
        self.frame = frame
        self.normal = _normal(normal)
        self.active = active_flag(active, "active")

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

    def wrench(self, multipliers: Array, rotation: Array) -> Array:
        """The ground's wrench on the frame from this contact's multipliers, in world
        components at the frame's origin, (torque; force).

        Args:
            multipliers: the contact's multipliers, shape (size,).
            rotation: the orientation of the closure's ground frame, shape (3, 3).

        Returns:
            The wrench, shape (6,).
        """
        return jnp.concatenate([jnp.zeros(3, multipliers.dtype), multipliers[:3]])


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

    Raises:
        ValueError: the normal is not a finite nonzero 3-vector, or active is not a boolean.
    """

    size: ClassVar[int] = 3
    kind: ClassVar[str] = "spherical"


class SurfaceContact(AbstractContact):
    """A frame of the robot held flat on the ground: 6 constraints, position and orientation
    (Crocoddyl's `ContactModel6D`, Pinocchio's `CONTACT_6D`): a foot's sole. The ground pushes
    on it with a force and a torque.

    Args:
        frame (str): the frame held, e.g. "left_sole_link".
        normal (ArrayLike): the ground's normal, world components, shape (3,); z by default.
        active (ArrayLike): True (the default) for a sole on the ground, False for one in the
            air (see `AbstractContact`).

    Raises:
        ValueError: the normal is not a finite nonzero 3-vector, or active is not a boolean.
    """

    size: ClassVar[int] = 6
    kind: ClassVar[str] = "weld"

    def wrench(self, multipliers, rotation):
        # the weld's rotation rows are vee(R_B^T R_A - R_A^T R_B) / 2, whose rate is the
        # relative angular velocity in the ground frame B's components: their multipliers are
        # a torque in B's components
        return jnp.concatenate([rotation @ multipliers[3:6], multipliers[:3]])


def wrenches(contacts, closures, multipliers: Array, rotations=None) -> Array:
    """Each contact's wrench (`AbstractContact.wrench`) from the stacked multipliers of its
    closure, in order: shape (len(contacts), 6). The closures' ground-frame orientations are
    read from `closures`, or given as `rotations` (len(contacts), 3, 3)."""
    starts = np.cumsum([0] + [c.size for c in contacts])
    if rotations is None:
        rotations = [j.rotation_b for j in closures]
    return jnp.stack([c.wrench(multipliers[s:s + c.size], R)
                      for c, R, s in zip(contacts, rotations, starts, strict=False)])
