"""Named frames of a tree: their world poses and Jacobians.

A name is looked up among the model's named frames (URDF links merged through fixed joints and
the fixed joints themselves, MJCF sites: `Model.frame_names`), then its bodies (`Model.names`,
the URDF links or MJCF bodies) and its joints (`Model.joint_names`, whose frame is the body's).
"""


import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.model import Model
from mbjax._src.rigid.kinematics import body_kinematics, forward_kinematics


def frame_names(model: Model) -> tuple[str, ...]:
    """Every name `frame_pose` accepts: named frames, bodies, joints."""
    return tuple(dict.fromkeys((*model.frame_names, *model.names, *model.joint_names)))


def frame_placement(model: Model, name: str) -> tuple[int, Array, Array]:
    """(body, R, p): the frame's body (-1: the ground) and its pose in that body's frame; a
    KeyError that lists the model's names when there is no such frame, body or joint. NumPy
    arrays where the model is concrete (no program compiles for them outside jit)."""
    xp = jnp if isinstance(model.mass, jax.core.Tracer) else np
    if name in model.frame_names:
        i = model.frame_names.index(name)
        return (model.frame_parents[i], xp.asarray(model.frame_rotation)[i],
                xp.asarray(model.frame_translation)[i])
    for names in (model.names, model.joint_names):
        if name in names:
            dtype = model.mass.dtype
            return names.index(name), xp.eye(3, dtype=dtype), xp.zeros(3, dtype)
    known = frame_names(model)
    raise KeyError(f"no frame, body or joint named {name!r}; the model has {len(known)}: "
                   f"{', '.join(known[:12])}{', ...' if len(known) > 12 else ''}")


def frame_pose(model: Model, q: Array, name: str) -> tuple[Array, Array]:
    """World pose of the frame, body or joint called `name`.

    A name is looked up among the model's named frames (URDF links merged through fixed joints
    and the fixed joints themselves, MJCF sites: `Model.frame_names`), then its bodies
    (`Model.names`, the URDF links or MJCF bodies) and its joints (`Model.joint_names`, whose
    frame is the body's). The name is resolved to its body and placement before tracing, so one
    compiled program serves every frame of a model.

    Args:
        model: the tree.
        q: configuration, shape (nq,).
        name: a named frame (URDF link or fixed joint, MJCF site), a body or a joint.

    Returns:
        (R, p): the frame's rotation (frame to world), shape (3, 3), and its origin in the
            world [m], shape (3,).

    Raises:
        KeyError: no frame, body or joint of that name (the message lists the model's names).
    """
    body, R_f, p_f = frame_placement(model, name)
    return _frame_pose(model, q, np.int32(body), R_f, p_f)


@jax.jit
def _frame_pose(model: Model, q: Array, body: Array, R_f: Array, p_f: Array):
    """The pose of a frame fixed at (R_f, p_f) in body `body` (-1: the ground), body traced."""
    R, p = forward_kinematics(model, q)
    on_ground = body < 0
    R_b = jnp.where(on_ground, jnp.eye(3, dtype=R.dtype), R[jnp.maximum(body, 0)])
    p_b = jnp.where(on_ground, 0.0, p[jnp.maximum(body, 0)])
    return R_b @ R_f, p_b + R_b @ p_f


def frame_jacobian(model: Model, q: Array, name: str) -> Array:
    """The Jacobian J with (omega; v) = J v of the frame, body or joint called `name`.

    omega is the frame's angular velocity and v the velocity of its origin, both in world
    components: Pinocchio's LOCAL_WORLD_ALIGNED, in (angular; linear) order. A frame on the
    ground has J = 0. As `frame_pose`, one compiled program serves every frame of a model.

    Args:
        model: the tree.
        q: configuration, shape (nq,).
        name: a named frame, a body or a joint (as `frame_pose`).

    Returns:
        J, shape (6, nv): rows (omega; v), columns the velocity coordinates.

    Raises:
        KeyError: no frame, body or joint of that name.
    """
    body, _, p_f = frame_placement(model, name)
    return _frame_jacobian(model, q, np.int32(body), p_f)


@jax.jit
def _frame_jacobian(model: Model, q: Array, body: Array, p_f: Array) -> Array:
    """The Jacobian of a point p_f fixed in body `body` (-1: the ground), body traced: the
    columns of the joints on its path from the ground (Jerkovsky 1978's path matrix, eq 1)."""
    kin = body_kinematics(model, q, jnp.zeros(model.nv, q.dtype))
    k = jnp.maximum(body, 0)
    x = kin.p[k] + kin.R[k] @ p_f                        # the frame origin, world
    path = jnp.asarray(model.topology.path_matrix()[:, model.dof_body()], bool)   # (n, nv)
    support = path[k] & (body >= 0)
    return jnp.where(support[:, None], point_columns(model, kin.S, x), 0.0).T


def point_columns(model: Model, S: Array, x: Array) -> Array:
    """Each joint column's (angular; linear) velocity of the world points x (..., 3) moving with
    it, (..., nv, 6): (w, v_O + w x x) of the columns S (n, 6, width) at the ground origin.
    A point's Jacobian keeps the columns on its body's path (Jerkovsky 1978 eq 1)."""
    S = model.flat_v(jnp.swapaxes(S, -1, -2))                  # (nv, 6)
    w, v0 = S[:, :3], S[:, 3:]
    return jnp.concatenate([jnp.broadcast_to(w, (*x.shape[:-1], *w.shape)),
                            v0 + jnp.cross(w, x[..., None, :])], -1)


def on_bodies(R: Array, p: Array, bodies, rotation: Array, translation: Array):
    """World poses of frames fixed to `bodies` (a NumPy int array, -1 for the ground) at
    `rotation` (m, 3, 3) and `translation` (m, 3) in them, from the bodies' poses R, p."""
    bodies = np.asarray(bodies, dtype=int)
    on_ground = jnp.asarray(bodies < 0)[:, None]
    R_b = jnp.where(on_ground[..., None], jnp.eye(3, dtype=R.dtype), R[np.maximum(bodies, 0)])
    p_b = jnp.where(on_ground, 0.0, p[np.maximum(bodies, 0)])
    return R_b @ rotation, p_b + jnp.einsum("mij,mj->mi", R_b, translation)


@jax.jit
def frame_poses(model: Model, q: Array) -> tuple[Array, Array]:
    """World poses of all the model's named frames at once (Pinocchio's
    `framesForwardKinematics`).

    Args:
        model: the tree.
        q: configuration, shape (nq,).

    Returns:
        (R, p): the frames' rotations (frame to world), shape (m, 3, 3), and their origins in
            the world [m], shape (m, 3), in the order of `Model.frame_names`.
    """
    R, p = forward_kinematics(model, q)
    return on_bodies(R, p, model.frame_parents, model.frame_rotation, model.frame_translation)
