"""How a system turns its `control` and `external` into forces: the part every system shares.

A control acts on the system's actuated velocity coordinates (`actuation`: their indices, all of
them by default) and returns one generalized force per actuated coordinate. An external load
returns one world-frame wrench (torque; force) per body, acting at the body's origin, or at a
point fixed in the body (`external_point`, body-frame coordinates) when the system has one.
"""

import equinox as eqx
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.control.base import AbstractControl, as_control


def check_actuation(actuation, nv: int) -> tuple[int, ...] | None:
    """The actuated velocity coordinates as a tuple of distinct indices (in the order of the
    control's outputs), or None (all of them)."""
    if actuation is None:
        return None
    index = np.atleast_1d(np.asarray(actuation))
    if index.dtype == bool:
        if index.shape != (nv,):
            raise ValueError(f"actuation as a mask must have {nv} entries, got {index.shape}")
        index = np.flatnonzero(index)
    if not np.issubdtype(index.dtype, np.integer) or index.ndim != 1:
        raise TypeError(f"actuation must be velocity-coordinate indices (ints) or a boolean mask, "
                        f"got {actuation!r}")
    if len(set(index.tolist())) != len(index) or np.any(index < 0) or np.any(index >= nv):
        raise ValueError(f"actuation must be distinct indices in 0 ... {nv - 1}, got {index.tolist()}")
    return tuple(int(i) for i in index)


def check_control(control, actuation: tuple | None, nv: int) -> AbstractControl | None:
    """The control as an `AbstractControl` (see `as_control`); a constant must have one entry per
    actuated coordinate."""
    control = as_control(control)
    n_act = nv if actuation is None else len(actuation)
    value = getattr(control, "value", None)
    if value is not None and value.shape != (n_act,):
        raise ValueError(f"the constant control (tau) must have shape ({n_act},), got {value.shape}")
    return control


def generalized_control(control: AbstractControl | None, actuation: tuple | None, nv: int,
                        t: Array, q: Array, v: Array) -> Array:
    """The control's forces scattered onto the nv velocity coordinates (zero where unactuated)."""
    if control is None:
        return jnp.zeros(nv, v.dtype)
    tau = jnp.asarray(control(t, q, v), v.dtype)
    n_act = nv if actuation is None else len(actuation)
    if tau.shape != (n_act,):
        raise ValueError(f"the control returned shape {tau.shape}; this system expects ({n_act},): "
                         + ("one force per velocity coordinate" if actuation is None else
                            f"one per actuated coordinate, actuation={actuation}"))
    return tau if actuation is None else jnp.zeros(nv, v.dtype).at[jnp.array(actuation)].set(tau)


def body_wrenches(external: AbstractControl | None, n: int, t: Array, q: Array, v: Array) -> Array | None:
    """The external wrenches (n, 6), world frame, or None."""
    if external is None:
        return None
    f = jnp.asarray(external(t, q, v), v.dtype)
    if f.shape != (n, 6):
        raise ValueError(f"external returned shape {f.shape}; it must return one world-frame "
                         f"wrench (torque; force) per body, shape ({n}, 6)")
    return f


def about_origins(f: Array, R: Array, point: Array | None) -> Array:
    """Wrenches whose forces act at body-fixed points (n, 3), moved to the bodies' origins:
    torque + (R point) x force."""
    if point is None:
        return f
    arm = jnp.einsum("kij,kj->ki", R, point)
    return f.at[:, :3].add(jnp.cross(arm, f[:, 3:]))


def check_points(point, n: int) -> Array | None:
    if point is None:
        return None
    point = jnp.asarray(point, dtype=float)
    point = jnp.broadcast_to(point, (n, 3)) if point.shape == (3,) else point
    if point.shape != (n, 3):
        raise ValueError(f"external_point must be one body-frame point per body, shape ({n}, 3), "
                         f"got {point.shape}")
    return point


def hold(system, t: Array, q: Array, v: Array):
    """The system with its control and external loads as they are over one step from (t, q, v)."""
    if system.control is None and system.external is None:
        return system
    held = tuple(None if c is None else c.hold(t, q, v) for c in (system.control, system.external))
    return eqx.tree_at(lambda s: (s.control, s.external), system, held, is_leaf=lambda x: x is None)
