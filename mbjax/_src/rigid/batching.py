"""How `jax.vmap` batches the recursive forward dynamics: onto `batch_aba`'s layout.

A user batches with `jax.vmap(mbjax.forward_dynamics)`. Left to itself, vmap puts the batch axis
in front of every 6x6 block of `aba` (mbjax._src.rigid.aba), many small batched matrix products per
body; `batch_aba` (mbjax._src.rigid.batched) runs the same recursion of Anderson 1993 §2.3 with the batch
last, as straight-line elementwise code, several times cheaper per state at large batches
(`mbjax bench speed`; the timings are in benchmarks/README.md). `aba_vmappable` is `aba` whose vmap rule
(`jax.custom_batching.custom_vmap`) takes that route when it can:

- the model itself is not batched (a sweep over model parameters keeps the plain vmap), its
  joints are all revolute or prismatic, and the batch has at least BATCH_CROSSOVER states (below
  that one vmapped call costs less one state after another, see BATCH_CROSSOVER);
- anything else (free, spherical or universal joints, a batched model, a small batch) runs one
  state after another where XLA compiles loops as one kernel (`mbjax._src.runtime.hoisting`): a
  `lax.map` of `aba`, each state costing what an evaluation costs in a rollout (for a free base
  such as the G1 humanoid's, a fraction of the plain vmap's cost; benchmarks/README.md), and the
  plain vmap of `aba` otherwise. The answer never depends on the route (the routes agree to
  rounding: tests/rigid/test_batching.py).

custom_vmap functions cannot be differentiated, so `forward_dynamics` wraps `aba_vmappable` in
the derivative rule of `mbjax._src.rigid.adjoint` (a `jax.custom_jvp`): a derivative of any order,
batched or not, comes from that rule; the batched route serves the values a vmapped program does
not differentiate.
"""

import jax
import jax.numpy as jnp
from jax import Array
from jax.custom_batching import custom_vmap

from mbjax._src import runtime
from mbjax._src.model import Model
from mbjax._src.rigid.aba import aba
from mbjax._src.rigid.batched import JOINTS, batch_aba

# Batch size from which jax.vmap runs batch_aba: below it one jitted vmapped call costs less one
# state after another (inside a rollout, where a call's fixed cost is paid once per loop,
# batch_aba wins at smaller batches too). The timings behind it are in benchmarks/README.md.
BATCH_CROSSOVER = 32


def _one_by_one(in_batched, *args) -> Array:
    """aba over the batch one state after another: a `lax.map` that XLA compiles as one loop of
    one kernel, each state costing what it costs in a rollout."""
    leaves, tree = jax.tree.flatten(args)
    flags = jax.tree.leaves(in_batched)

    def one(xs):
        rest = iter(xs)
        return aba(*jax.tree.unflatten(tree, [next(rest) if b else x
                                              for x, b in zip(leaves, flags, strict=True)]))
    return jax.lax.map(one, [x for x, b in zip(leaves, flags, strict=True) if b])


def batchable(model: Model) -> bool:
    """Whether `batch_aba` can run this model (revolute and prismatic joints only)."""
    return all(kind in JOINTS for kind in model.joint_types)


@custom_vmap
def aba_vmappable(model: Model, q: Array, v: Array, tau: Array) -> Array:
    """`aba(model, q, v, tau)` (no external wrenches), batched by `jax.vmap` onto `batch_aba`,
    or one state after another, where that is faster (see the module)."""
    return aba(model, q, v, tau)


@aba_vmappable.def_vmap
def _vmap_rule(axis_size, in_batched, model, q, v, tau):
    model_batched, *batched = in_batched
    if not any(jax.tree.leaves(in_batched)):     # e.g. jacrev's vmap over cotangents only
        return aba(model, q, v, tau), False
    fast = batchable(model) and not any(jax.tree.leaves(model_batched))
    if runtime.HOISTING and not (fast and axis_size >= BATCH_CROSSOVER):
        return _one_by_one(in_batched, model, q, v, tau), True
    if not fast or axis_size < BATCH_CROSSOVER:
        axes = (jax.tree.map(lambda b: 0 if b else None, model_batched),
                *(0 if b else None for b in batched))
        return jax.vmap(aba, in_axes=axes)(model, q, v, tau), True

    def columns(x, b):            # (B, nv) -> (nv, B); an unbatched (nv,) is broadcast
        return x.T if b else jnp.broadcast_to(x[:, None], (x.shape[0], axis_size))

    q, v, tau = (columns(x, b) for x, b in zip((q, v, tau), batched, strict=True))
    return batch_aba(model, q, v, tau).T, True
