"""State converters between mbjax and Pinocchio or MuJoCo: `(model, q, v) -> (q, v)`.

The coordinates of one joint differ between the engines only in their layout; the joints come in
the same order when the peer numbers them as mbjax does (`load_urdf`'s default sibling order is
Pinocchio's; `load_mjcf`, `from_mujoco` and `load_urdf(..., sibling_order=InDocument())` follow
MuJoCo's).

    joint       mbjax q, v                       Pinocchio q, v                 MuJoCo qpos, qvel
    revolute    angle, rate                      same; a joint without limits   same
                                                 (URDF continuous): cos, sin
    prismatic   displacement, rate               same                           same
    spherical   quaternion wxyz,                 quaternion xyzw, omega_body    wxyz, omega_body
                omega_body
    free        origin, quaternion wxyz;         origin, xyzw;                  origin, wxyz;
                (omega_body; v_origin body)      (v_origin body; omega_body)    (v_origin world;
                                                                                omega_body)

Universal joints have no counterpart in either engine. Each conversion is a few gathers and
scatters with index maps built once per joint layout (no loop over the joints in traced code), so
it composes with jit, vmap and grad; an acceleration converts by `jax.jvp` of the velocity map
along (q_dot, v_dot). Which revolute joints are continuous is read from the model's limits, which
must then be concrete (close over the model rather than passing it through `jax.jit`).
"""

from functools import lru_cache

import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.lie import quat_to_matrix
from mbjax._src.model.joints import JOINT_TYPES
from mbjax._src.model.model import Model

_XYZW = (1, 2, 3, 0)           # Pinocchio's quaternion (x, y, z, w) from mbjax's (w, x, y, z)


def _check(model: Model, q: Array, v: Array, peer: str, nq: int) -> tuple[Array, Array]:
    """q and v as arrays of shapes (nq,) and (model.nv,) (nq: the layout they are given in),
    on a model whose joints the peer has."""
    q, v = jnp.asarray(q), jnp.asarray(v)
    for k, kind in enumerate(model.joint_types):
        if kind == "universal":
            raise ValueError(f"joint {model.joint_names[k]!r} is universal: {peer} has no such "
                             "joint (make it two revolute joints)")
    if q.shape != (nq,) or v.shape != (model.nv,):
        raise ValueError(f"q and v must have shapes ({nq},) and ({model.nv},) for this model in "
                         f"this layout, got {q.shape} and {v.shape}; use jax.vmap for batches")
    return q, v


def _continuous(model: Model) -> tuple[bool, ...]:
    """Per joint: a revolute joint without position limits (URDF's continuous joint)."""
    lower, upper = model.lower, model.upper
    if isinstance(lower, jax.core.Tracer) or isinstance(upper, jax.core.Tracer):
        raise TypeError("the Pinocchio converters read which revolute joints are continuous from "
                        "the model's limits, which are traced here: close over the model instead "
                        "of passing it through jax.jit")
    starts = np.cumsum([0] + [JOINT_TYPES[k].nq for k in model.joint_types])[:-1]
    lower, upper = np.asarray(lower), np.asarray(upper)
    return tuple(bool(kind == "revolute" and np.isinf(lower[i]) and np.isinf(upper[i]))
                 for kind, i in zip(model.joint_types, starts, strict=True))


@lru_cache(maxsize=None)
def _pinocchio_layout(joint_types: tuple[str, ...], continuous: tuple[bool, ...]):
    """Static index maps: Pinocchio's q[dst] = mbjax's q[src] (a permutation of the plain
    coordinates), the continuous joints' (cos, sin) slots, and v_pin = v[v_src]."""
    src, dst, angle, cos_sin, v_src = [], [], [], [], []
    iq = ip = iv = 0
    for kind, cont in zip(joint_types, continuous, strict=True):
        nq, nv = JOINT_TYPES[kind]
        if cont:
            angle.append(iq)
            cos_sin.append((ip, ip + 1))
            ip += 2
        else:
            order = {"spherical": _XYZW, "free": (0, 1, 2, *(3 + i for i in _XYZW))}.get(
                kind, tuple(range(nq)))
            src += [iq + i for i in order]
            dst += list(range(ip, ip + nq))
            ip += nq
        v_src += [iv + i for i in ((3, 4, 5, 0, 1, 2) if kind == "free" else range(nv))]
        iq, iv = iq + nq, iv + nv
    as_array = lambda x: np.asarray(x, dtype=int).reshape(-1)  # noqa: E731
    return dict(nq=ip, src=as_array(src), dst=as_array(dst), angle=as_array(angle),
                cos=as_array([c for c, _ in cos_sin]), sin=as_array([s for _, s in cos_sin]),
                v_src=as_array(v_src), v_dst=np.argsort(v_src))


def state_to_pinocchio(model: Model, q: Array, v: Array) -> tuple[Array, Array]:
    """A state in Pinocchio's layout, for the model Pinocchio builds from the same URDF.

    A free base corresponds to `pin.JointModelFreeFlyer()` as the root joint. Quaternions are
    reordered to (x, y, z, w), a free joint's velocity to (v_origin; omega), and a revolute
    joint without limits (URDF continuous) becomes (cos, sin). Composes with jit, vmap and
    grad.

    Args:
        model: the mbjax model; its limits must be concrete (close over it rather than passing
            it through `jax.jit`).
        q: mbjax configuration, shape (nq,).
        v: mbjax velocity, shape (nv,).

    Returns:
        q_pin: Pinocchio's configuration, shape (model.nq + the number of continuous joints,).
        v_pin: Pinocchio's velocity, shape (nv,).

    Raises:
        ValueError: the model has a universal joint (Pinocchio has none), or q and v have the
            wrong shapes.
        TypeError: the model's limits are traced.
    """
    q, v = _check(model, q, v, "Pinocchio", model.nq)
    lay = _pinocchio_layout(model.joint_types, _continuous(model))
    q_pin = (jnp.zeros(lay["nq"], q.dtype).at[lay["dst"]].set(q[lay["src"]])
             .at[lay["cos"]].set(jnp.cos(q[lay["angle"]]))
             .at[lay["sin"]].set(jnp.sin(q[lay["angle"]])))
    return q_pin, v[lay["v_src"]]


def state_from_pinocchio(model: Model, q: Array, v: Array) -> tuple[Array, Array]:
    """An mbjax state from Pinocchio's layout: the inverse of `state_to_pinocchio`.

    Args:
        model: the mbjax model; its limits must be concrete.
        q: Pinocchio's configuration, shape (nq_pin,).
        v: Pinocchio's velocity, shape (nv,).

    Returns:
        q: mbjax configuration, shape (model.nq,).
        v: mbjax velocity, shape (nv,).

    Raises:
        ValueError: the model has a universal joint, or q and v have the wrong sizes.
        TypeError: the model's limits are traced.
    """
    lay = _pinocchio_layout(model.joint_types, _continuous(model))
    q, v = _check(model, q, v, "Pinocchio", lay["nq"])
    q_mb = (jnp.zeros(model.nq, q.dtype).at[lay["src"]].set(q[lay["dst"]])
            .at[lay["angle"]].set(jnp.arctan2(q[lay["sin"]], q[lay["cos"]])))
    return q_mb, v[lay["v_dst"]]


@lru_cache(maxsize=None)
def _free_joints(joint_types: tuple[str, ...], parents: tuple[int, ...]):
    """(quaternion indices (k, 4), linear-velocity indices (k, 3), angular (k, 3)) of the free
    joints, which MuJoCo allows only on bodies hanging from the world."""
    quat, linear, angular = [], [], []
    iq = iv = 0
    for kind, parent in zip(joint_types, parents, strict=True):
        if kind == "free":
            if parent >= 0:
                raise ValueError("MuJoCo allows free joints only on bodies that hang from the "
                                 "world")
            quat.append(range(iq + 3, iq + 7))
            angular.append(range(iv, iv + 3))
            linear.append(range(iv + 3, iv + 6))
        iq, iv = iq + JOINT_TYPES[kind].nq, iv + JOINT_TYPES[kind].nv
    shape = lambda x, n: np.asarray(x, dtype=int).reshape(-1, n)  # noqa: E731
    return shape(quat, 4), shape(linear, 3), shape(angular, 3)


def _mujoco_velocity(model: Model, q: Array, v: Array, to_world: bool) -> Array:
    """A free joint's (omega; v_origin) in the body frame and MuJoCo's (v_origin in the world;
    omega): the same components, reordered, with the linear part rotated."""
    quat, linear, angular = _free_joints(model.joint_types, model.topology.parents)
    if not quat.size:
        return v
    R = jax.vmap(quat_to_matrix)(q[quat] / jnp.linalg.norm(q[quat], axis=-1, keepdims=True))
    if to_world:          # mbjax (omega; v_body) -> MuJoCo (R v_body; omega)
        return (v.at[angular].set(jnp.einsum("kij,kj->ki", R, v[linear]))
                .at[linear].set(v[angular]))
    # MuJoCo (v_world; omega) in mbjax's slots: v_world at `angular`, omega at `linear`
    return (v.at[angular].set(v[linear])
            .at[linear].set(jnp.einsum("kji,kj->ki", R, v[angular])))


def state_to_mujoco(model: Model, q: Array, v: Array) -> tuple[Array, Array]:
    """A state as MuJoCo's (qpos, qvel), for the MuJoCo model of the same mechanism.

    The joints are numbered as `load_mjcf` and `from_mujoco` number them. Configurations agree;
    a free joint's velocity becomes MuJoCo's (v_origin in the world; omega in the body).

    Args:
        model: the mbjax model.
        q: mbjax configuration, shape (nq,).
        v: mbjax velocity, shape (nv,).

    Returns:
        qpos: MuJoCo's configuration, shape (nq,).
        qvel: MuJoCo's velocity, shape (nv,).

    Raises:
        ValueError: the model has a universal joint, or a free joint on a body that does not
            hang from the world (MuJoCo allows neither), or q and v have the wrong shapes.
    """
    q, v = _check(model, q, v, "MuJoCo", model.nq)
    return q, _mujoco_velocity(model, q, v, to_world=True)


def state_from_mujoco(model: Model, q: Array, v: Array) -> tuple[Array, Array]:
    """An mbjax state from MuJoCo's (qpos, qvel): the inverse of `state_to_mujoco`.

    Args:
        model: the mbjax model.
        q: MuJoCo's qpos, shape (nq,).
        v: MuJoCo's qvel, shape (nv,).

    Returns:
        q: mbjax configuration, shape (nq,).
        v: mbjax velocity, shape (nv,).

    Raises:
        ValueError: the model has a universal joint, or a free joint on a body that does not
            hang from the world, or q and v have the wrong shapes.
    """
    q, v = _check(model, q, v, "MuJoCo", model.nq)
    return q, _mujoco_velocity(model, q, v, to_world=False)
