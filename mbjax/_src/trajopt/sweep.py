"""Parameter sweeps for any system: one jitted `vmap` on one device, the same computation
sharded across devices with `jax.sharding`.

A batch is any pytree whose array leaves carry a leading variant axis: a dict of parameter
arrays, a model or a wrist batched by `batch` or `grid`. `sweep(fn, params)` maps fn over that
axis in one compiled call; with `devices`, the variant axis is split over a one-axis mesh
(`NamedSharding(mesh, P("variants"))`) and XLA partitions the vmapped computation, so each
device runs its share. The same code runs on
the GPUs of a host, or, after `jax.distributed.initialize()`, over the devices of several hosts
(`jax.devices()` then lists them all; only one host is tested here, with forced CPU devices).
"""

import functools

import jax
import jax.numpy as jnp
import numpy as np
from jax.sharding import Mesh, NamedSharding, PartitionSpec


def size(params) -> int:
    """The number of variants in a batch: the leading axis every array leaf shares.

    Args:
        params: the batch, a pytree of arrays.

    Returns:
        The shared leading size.

    Raises:
        ValueError: params has no array leaves or they do not share a leading axis.
    """
    leaves = jax.tree.leaves(params)
    shapes = {np.shape(x)[:1] for x in leaves}
    if not leaves or len(shapes) != 1 or shapes == {()}:
        raise ValueError("params must be a pytree whose array leaves all share a leading "
                         f"(variant) axis; got leading sizes {sorted(s for s in shapes)}")
    return shapes.pop()[0]


def padded(params, multiple: int):
    """(params padded with copies of its last variant to a multiple of `multiple`, the number of
    copies added)."""
    pad = -size(params) % multiple
    if pad:
        params = jax.tree.map(lambda x: jnp.concatenate([x, jnp.repeat(x[-1:], pad, axis=0)]),
                              params)
    return params, pad


def sweep(fn, params, *, devices=None, trim: bool = True):
    """fn(p) for every variant p of a batch, as jit(vmap(fn)), optionally sharded over devices.

    Args:
        fn (Callable): the function of one variant.
        params (PyTree): the batch, any pytree whose array leaves share a leading variant axis of n
            (a dict of arrays, a batched model or wrist, a tuple).
        devices (Sequence[jax.Device] | None): None (one device), or several devices (e.g.
            `jax.devices()`) to split the variants over: they are padded with copies of the last one
            to a multiple of their number, and the outputs computed and returned sharded over the
            devices.
        trim: with devices, return the n variants given (where padding was needed that slice
            is gathered onto every device: JAX shards only axes the devices divide); False
            keeps the padded outputs sharded, the first n rows the variants, for sharded work
            downstream.

    Returns:
        fn's outputs stacked along a leading variant axis (n rows, or the padded count with
            trim=False).

    Raises:
        ValueError: params has no array leaves or they do not share a leading axis, or
            devices is an empty sequence.
        TypeError: devices is not a sequence of JAX devices.
    """
    if devices is not None:
        try:
            devices = list(devices)
        except TypeError as error:
            raise TypeError(f"devices must be None or a sequence of JAX devices (jax.devices()), "
                            f"got {type(devices).__name__}") from error
        if not devices:
            raise ValueError("devices must be None (one device) or a non-empty sequence of JAX "
                             "devices (jax.devices()), got an empty one")
        if not all(isinstance(d, jax.Device) for d in devices):
            raise TypeError(f"devices must be JAX devices (jax.devices()), got "
                            f"{sorted({type(d).__name__ for d in devices})}")
    params = jax.tree.map(jnp.asarray, params)
    n = size(params)
    if devices is None or len(devices) == 1:
        return _compiled(fn, None)(params)
    params, pad = padded(params, len(devices))
    sharding = NamedSharding(Mesh(np.asarray(devices), ("variants",)), PartitionSpec("variants"))
    out = _compiled(fn, sharding)(jax.device_put(params, sharding))
    return jax.tree.map(lambda x: x[:n], out) if pad and trim else out


def _compiled(fn, sharding):
    """jit(vmap(fn)), made once per function and sharding where fn can be a cache key: a fresh
    `jax.vmap(fn)` each call would be a new function to `jax.jit`, traced and compiled again.
    A function that cannot be hashed (a module holding arrays) is wrapped anew."""
    try:
        return _cached(fn, sharding)
    except TypeError:                              # unhashable
        return _wrapped(fn, sharding)


def _wrapped(fn, sharding):
    mapped = jax.vmap(fn)
    return jax.jit(mapped) if sharding is None else jax.jit(mapped, out_shardings=sharding)


_cached = functools.lru_cache(maxsize=64)(_wrapped)
