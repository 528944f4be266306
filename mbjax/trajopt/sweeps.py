"""Parameter sweeps for any system: one jitted `vmap` on one device, the same computation
sharded across devices with `jax.sharding`; and the Carpal Wrist's batches and grids.

A batch is any pytree whose array leaves carry a leading variant axis: a dict of parameter
arrays, a model or a wrist batched by `batch` or `grid`. `sweep(fn, params)` maps fn over that
axis in one compiled call; with `devices`, the variant axis is split over a one-axis mesh
(`NamedSharding(mesh, P("variants"))`) and XLA partitions the vmapped computation, so each
device runs its share. The same code runs on
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


def size(params) -> int:
    """The number of variants in a batch: the leading axis every array leaf shares."""
    leaves = jax.tree.leaves(params)
    shapes = {np.shape(x)[:1] for x in leaves}
    if not leaves or len(shapes) != 1 or shapes == {()}:
        raise ValueError("params must be a pytree whose array leaves all share a leading "
                         f"(variant) axis; got leading sizes {sorted(s for s in shapes)}")
    return shapes.pop()[0]


def sweep(fn, params, *, devices=None, trim: bool = True):
    """fn(p) for every variant p of params: any pytree whose array leaves share a leading
    variant axis (a dict of arrays, a batched model or wrist, a tuple), as jit(vmap(fn)).

    With `devices` (several, e.g. jax.devices()), the variants are split over them: padded with
    copies of the last one to a multiple of their number, and the outputs computed and returned
    sharded over the devices. `trim=True` returns the n variants given; where padding was
    needed that slice is gathered onto every device (JAX shards only axes the devices divide).
    `trim=False` keeps the padded outputs sharded, the first n rows the variants, for sharded
    work downstream."""
    params = jax.tree.map(jnp.asarray, params)
    n = size(params)
    mapped = jax.vmap(fn)
    if devices is None or len(devices) == 1:
        return jax.jit(mapped)(params)
    pad = -n % len(devices)
    if pad:
        params = jax.tree.map(lambda x: jnp.concatenate([x, jnp.repeat(x[-1:], pad, axis=0)]),
                              params)
    sharding = NamedSharding(Mesh(np.asarray(devices), ("variants",)), PartitionSpec("variants"))
    out = jax.jit(mapped, out_shardings=sharding)(jax.device_put(params, sharding))
    return jax.tree.map(lambda x: x[:n], out) if pad and trim else out


def peak_torque(wrist: CarpalWrist, path: ToolPath, samples: int = 64):
    """The largest |motor torque| (inverse dynamics) along a tool path, and where (time index):
    the actuator-sizing number of Canfield 1997 eq 6.16."""
    ts = jnp.linspace(0.0, path.duration, samples)
    q, q_dot, q_ddot, _ = jax.vmap(lambda t: path.joint_motion(wrist, t))(ts)
    tau = jax.vmap(wrist.inverse_dynamics)(q, q_dot, q_ddot)
    return jnp.max(jnp.abs(tau))
