"""Parameter sweeps over Carpal Wrist variants: one jitted `vmap` on one device, the same
computation sharded across devices with `jax.sharding`.

A batch of wrists is one `CarpalWrist` whose array leaves carry a leading variant axis
(`batch`, `grid`). `sweep(fn, wrists)` maps fn over that axis in one compiled call; with
`devices`, the variant axis is split over a one-axis mesh (`NamedSharding(mesh, P("variants"))`)
and XLA partitions the vmapped computation, so each device runs its share. The same code runs on
the GPUs of a host, or, after `jax.distributed.initialize()`, over the devices of several hosts
(`jax.devices()` then lists them all; only one host is tested here, with forced CPU devices).
"""

import itertools

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax.sharding import Mesh, NamedSharding, PartitionSpec

from mbjax.trajopt.baseline import ToolPath
from mbjax.wrist import CarpalWrist

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
    """The Cartesian product of per-field value lists (each a sequence of values of that field's
    shape), as one batch in C order, and the grid's shape."""
    names = list(axes)
    rows = list(itertools.product(*(list(axes[k]) for k in names)))
    values = {k: np.stack([np.asarray(r[i], dtype=float) for r in rows]) for i, k in enumerate(names)}
    return batch(base, **values), tuple(len(axes[k]) for k in names)


def size(wrists: CarpalWrist) -> int:
    """The number of variants in a batch."""
    return int(jnp.shape(wrists.tool_mass)[0])


def sweep(fn, wrists: CarpalWrist, *, devices=None):
    """fn(wrist) for every variant: jit(vmap(fn)); with `devices` (a list, e.g. jax.devices()),
    the variants are sharded over them (padded to a multiple of their number) and the outputs
    come back sharded the same way, trimmed to the variants given."""
    mapped = jax.vmap(fn)
    if devices is None or len(devices) == 1:
        return jax.jit(mapped)(wrists)
    n, k = size(wrists), len(devices)
    pad = -n % k
    if pad:
        wrists = jax.tree.map(lambda x: jnp.concatenate([x, jnp.repeat(x[-1:], pad, axis=0)]), wrists)
    sharding = NamedSharding(Mesh(np.asarray(devices), ("variants",)), PartitionSpec("variants"))
    out = jax.jit(mapped, out_shardings=sharding)(jax.device_put(wrists, sharding))
    return jax.tree.map(lambda x: x[:n], out) if pad else out


def peak_torque(wrist: CarpalWrist, path: ToolPath, samples: int = 64):
    """The largest |motor torque| (inverse dynamics) along a tool path, and where (time index):
    the actuator-sizing number of seed 003 eq 6.16."""
    ts = jnp.linspace(0.0, path.duration, samples)
    q, q_dot, q_ddot, _ = jax.vmap(lambda t: path.joint_motion(wrist, t))(ts)
    tau = jax.vmap(wrist.inverse_dynamics)(q, q_dot, q_ddot)
    return jnp.max(jnp.abs(tau))
