"""Batches and grids of Carpal Wrists for `mbjax.trajopt.sweep`, and the actuator-sizing number
along a tool path (Canfield 1997 §6)."""


import itertools

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from mbjax._src.synthesis.baseline import ToolPath
from mbjax._src.wrist import CarpalWrist

FIELDS = ("base_radius", "link_length", "phi0", "tool_mass", "tool_inertia", "tool_com", "gravity")


def batch(base: CarpalWrist, **values) -> CarpalWrist:
    """base with the given fields replaced by arrays of n variants (leading axis n, all equal) and
    every other field repeated n times."""
    n = {np.shape(v)[0] for v in values.values()}
    if len(n) != 1:
        raise ValueError(f"all swept fields need the same number of variants, got {sorted(n)}")
    n = n.pop()
    unknown = set(values) - set(FIELDS)
    if unknown:
        raise ValueError(f"unknown wrist fields {sorted(unknown)}; sweepable: {FIELDS}")
    leaves = [jnp.asarray(values[f], dtype=float) if f in values
              else jnp.broadcast_to(getattr(base, f), (n,) + jnp.shape(getattr(base, f))) for f in FIELDS]
    return eqx.tree_at(lambda w: [getattr(w, f) for f in FIELDS], base, leaves)


def grid(base: CarpalWrist, **axes) -> tuple[CarpalWrist, tuple[int, ...]]:
    """A grid of wrists for `mbjax.trajopt.sweep`: the Cartesian product of per-field values.

    Args:
        base: the wrist whose other fields every variant keeps.
        **axes: field name (base_radius, link_length, phi0, tool_mass, tool_inertia,
            tool_com, gravity) -> a sequence of values of that field's shape.

    Returns:
        (wrists, shape): one batched `CarpalWrist` whose leaves have a leading axis of
            prod(shape) variants in C order, and the grid's shape (one length per field).

    Raises:
        ValueError: an unknown field.
    """
    names = list(axes)
    rows = list(itertools.product(*(list(axes[k]) for k in names)))
    values = {k: np.stack([np.asarray(r[i], dtype=float) for r in rows]) for i, k in enumerate(names)}
    return batch(base, **values), tuple(len(axes[k]) for k in names)


def peak_torque(wrist: CarpalWrist, path: ToolPath, samples: int = 64):
    """The largest |motor torque| (inverse dynamics) along a tool path: the actuator-sizing
    number of Canfield 1997 eq 6.16.

    Args:
        wrist: the `CarpalWrist`.
        path: the `ToolPath`.
        samples: number of evenly spaced times in [0, duration].

    Returns:
        max over the samples and motors of |tau| [N m], a scalar.
    """
    ts = jnp.linspace(0.0, path.duration, samples)
    q, q_dot, q_ddot, _ = jax.vmap(lambda t: path.joint_motion(wrist, t))(ts)
    tau = jax.vmap(wrist.inverse_dynamics)(q, q_dot, q_ddot)
    return jnp.max(jnp.abs(tau))
