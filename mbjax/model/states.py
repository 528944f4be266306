"""State converters between mbjax and Pinocchio or MuJoCo: `(model, q, v) -> (q, v)`.

The coordinates of one joint differ between the engines only in their layout; the joints come in
the same order when the peer numbers them as mbjax does (`load_urdf`'s default sibling order is
Pinocchio's; `load_mjcf`, `from_mujoco` and `load_urdf(..., sibling_order="document")` follow
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

Universal joints have no counterpart in either engine. The functions are jax-traceable, so an
acceleration converts by `jax.jvp` of the velocity map along (q_dot, v_dot).
"""

import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax.lie import quat_to_matrix
from mbjax.model.joints import JOINT_TYPES
from mbjax.model.model import Model


def _continuous(model: Model, k: int, q_start: int) -> bool:
    """A revolute joint without position limits: URDF's continuous joint."""
    return (model.joint_types[k] == "revolute"
            and not np.isfinite(np.asarray(model.lower[q_start]))
            and not np.isfinite(np.asarray(model.upper[q_start])))


def _split(model: Model, q: Array, v: Array, peer: str):
    """Per joint: (kind, q_k, v_k, k, q_start)."""
    if q.shape != (model.nq,) or v.shape != (model.nv,):
        raise ValueError(f"q and v must have shapes ({model.nq},) and ({model.nv},) for this "
                         f"model, got {q.shape} and {v.shape}")
    iq = iv = 0
    for k, kind in enumerate(model.joint_types):
        nq, nv = JOINT_TYPES[kind]
        if kind == "universal":
            raise ValueError(f"joint {model.joint_names[k]!r} is universal: {peer} has no such "
                             "joint (make it two revolute joints)")
        yield kind, q[iq:iq + nq], v[iv:iv + nv], k, iq
        iq, iv = iq + nq, iv + nv


def _xyzw(quat):
    return jnp.concatenate([quat[1:], quat[:1]])


def _wxyz(quat):
    return jnp.concatenate([quat[3:], quat[:3]])


def state_to_pinocchio(model: Model, q: Array, v: Array) -> tuple[Array, Array]:
    """(q, v) in Pinocchio's layout for the model Pinocchio builds from the same URDF (a free
    base: `pin.JointModelFreeFlyer()` as the root joint)."""
    qs, vs = [], []
    for kind, qk, vk, k, iq in _split(model, jnp.asarray(q), jnp.asarray(v), "Pinocchio"):
        if kind == "free":
            qk, vk = jnp.concatenate([qk[:3], _xyzw(qk[3:])]), jnp.concatenate([vk[3:], vk[:3]])
        elif kind == "spherical":
            qk = _xyzw(qk)
        elif _continuous(model, k, iq):
            qk = jnp.stack([jnp.cos(qk[0]), jnp.sin(qk[0])])
        qs.append(qk)
        vs.append(vk)
    return jnp.concatenate(qs), jnp.concatenate(vs)


def state_from_pinocchio(model: Model, q: Array, v: Array) -> tuple[Array, Array]:
    """Inverse of `state_to_pinocchio`."""
    q, v = jnp.asarray(q), jnp.asarray(v)
    qs, vs, iq, iv = [], [], 0, 0
    for k, kind in enumerate(model.joint_types):
        nq, nv = JOINT_TYPES[kind]
        start = sum(JOINT_TYPES[t].nq for t in model.joint_types[:k])
        continuous = _continuous(model, k, start)
        width = 2 if continuous else nq
        qk, vk = q[iq:iq + width], v[iv:iv + nv]
        if kind == "universal":
            raise ValueError(f"joint {model.joint_names[k]!r} is universal: Pinocchio has no "
                             "such joint")
        if kind == "free":
            qk, vk = jnp.concatenate([qk[:3], _wxyz(qk[3:])]), jnp.concatenate([vk[3:], vk[:3]])
        elif kind == "spherical":
            qk = _wxyz(qk)
        elif continuous:
            qk = jnp.arctan2(qk[1:], qk[:1])
        qs.append(qk)
        vs.append(vk)
        iq, iv = iq + width, iv + nv
    if iq != q.shape[0] or iv != v.shape[0]:
        raise ValueError(f"Pinocchio q and v must have {iq} and {iv} entries for this model, got "
                         f"{q.shape[0]} and {v.shape[0]}")
    return jnp.concatenate(qs), jnp.concatenate(vs)


def _check_root(model: Model, k: int) -> None:
    if model.topology.parents[k] >= 0:
        raise ValueError(f"joint {model.joint_names[k]!r}: MuJoCo allows free joints only on "
                         "bodies that hang from the world")


def state_to_mujoco(model: Model, q: Array, v: Array) -> tuple[Array, Array]:
    """(qpos, qvel) for the MuJoCo model of the same mechanism (`load_mjcf`/`from_mujoco`
    numbering)."""
    qs, vs = [], []
    for kind, qk, vk, k, _ in _split(model, jnp.asarray(q), jnp.asarray(v), "MuJoCo"):
        if kind == "free":
            _check_root(model, k)
            R = quat_to_matrix(qk[3:] / jnp.linalg.norm(qk[3:]))
            vk = jnp.concatenate([R @ vk[3:], vk[:3]])
        qs.append(qk)
        vs.append(vk)
    return jnp.concatenate(qs), jnp.concatenate(vs)


def state_from_mujoco(model: Model, q: Array, v: Array) -> tuple[Array, Array]:
    """Inverse of `state_to_mujoco`."""
    qs, vs = [], []
    for kind, qk, vk, k, _ in _split(model, jnp.asarray(q), jnp.asarray(v), "MuJoCo"):
        if kind == "free":
            _check_root(model, k)
            R = quat_to_matrix(qk[3:] / jnp.linalg.norm(qk[3:]))
            vk = jnp.concatenate([vk[3:], R.T @ vk[:3]])
        qs.append(qk)
        vs.append(vk)
    return jnp.concatenate(qs), jnp.concatenate(vs)
