"""`jax.vmap(forward_dynamics)` runs `batch_aba` (mbjax._src.rigid.batching) and agrees with the
one-state recursion, in value and in every derivative, and falls back where it must."""

from functools import partial

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from mbjax import Recursive
from mbjax.model import random_tree
from mbjax.rigid import forward_dynamics
from mbjax._src.rigid import batch_aba
from mbjax._src.rigid.aba import aba
from mbjax._src.rigid.batching import BATCH_CROSSOVER, batchable

B = BATCH_CROSSOVER
MODEL = random_tree(5, seed=4, joint_types=("revolute", "prismatic"))
forward_dynamics = partial(forward_dynamics, method=Recursive())     # not the dense form at nv = 5


def _states(model, batch, seed=0):
    rng = np.random.default_rng(seed)
    return tuple(jnp.asarray(x) for x in (rng.uniform(-np.pi, np.pi, (batch, model.nq)),
                                          rng.normal(size=(batch, model.nv)),
                                          rng.normal(size=(batch, model.nv))))


def _relative(a, ref):
    return float(jnp.max(jnp.abs(a - ref)) / jnp.max(jnp.abs(ref)))


def _products(f, *args) -> int:
    return str(jax.make_jaxpr(f)(*args)).count("dot_general")


def _one_by_one(model, q, v, tau):
    """The reference: the one-state recursion, state after state (lax.map does not batch)."""
    return jax.lax.map(lambda x: aba(model, *x), (q, v, tau))


def test_vmap_takes_the_batched_route_and_agrees():
    q, v, tau = _states(MODEL, B)
    batched = jax.vmap(forward_dynamics, in_axes=(None, 0, 0, 0))
    # the batched route's program is batch_aba's: it has only its few matrix products (of
    # per-body constants), far fewer than the plain vmap of the recursion
    assert (_products(batched, MODEL, q, v, tau)
            == _products(lambda *x: batch_aba(*x).T, MODEL, q.T, v.T, tau.T)
            < _products(jax.vmap(aba, in_axes=(None, 0, 0, 0)), MODEL, q, v, tau))
    reference = _one_by_one(MODEL, q, v, tau)
    assert _relative(jax.jit(batched)(MODEL, q, v, tau), reference) < 1e-12
    # a torque shared by every state is broadcast
    shared = jax.vmap(forward_dynamics, in_axes=(None, 0, 0, None))(MODEL, q, v, tau[0])
    assert _relative(shared, _one_by_one(MODEL, q, v, jnp.broadcast_to(tau[0], q.shape))) < 1e-12


def test_batched_models_small_batches_and_free_joints_fall_back():
    q, v, tau = _states(MODEL, 3)
    models = jax.vmap(lambda s: eqx.tree_at(lambda m: m.mass, MODEL, MODEL.mass * s))(
        jnp.array([1.0, 2.0, 3.0]))
    swept = eqx.filter_vmap(forward_dynamics)(models, q, v, tau)
    assert _relative(swept, eqx.filter_vmap(aba)(models, q, v, tau)) < 1e-12
    small = jax.vmap(forward_dynamics, in_axes=(None, 0, 0, 0))
    assert (_products(small, MODEL, q, v, tau)
            == _products(jax.vmap(aba, in_axes=(None, 0, 0, 0)), MODEL, q, v, tau))
    floating = random_tree(3, seed=1, joint_types=("free", "revolute", "spherical"))
    assert not batchable(floating) and batchable(MODEL)
    qf, vf, tf = _states(floating, B)
    qf = jax.vmap(floating.normalize)(qf)
    out = jax.vmap(forward_dynamics, in_axes=(None, 0, 0, 0))(floating, qf, vf, tf)
    assert _relative(out, _one_by_one(floating, qf, vf, tf)) < 1e-12


def test_derivatives_are_those_of_the_recursion():
    """Reverse mode through vmap, vmap of reverse mode, forward mode. (Second order is left
    out: jit(hessian) of the plain recursion on this tree aborts in XLA 0.10.2's CPU dot
    emitter, a layout check, with or without mbjax.batching.)"""
    model = MODEL
    q, v, tau = _states(model, B, seed=1)

    def loss(f):
        return lambda q: jnp.sum(jax.vmap(f, in_axes=(None, 0, 0, 0))(model, q, v, tau) ** 2)

    assert _relative(jax.jit(jax.grad(loss(forward_dynamics)))(q),
                     jax.jit(jax.grad(loss(aba)))(q)) < 1e-12

    def per_state(f):
        return jax.vmap(jax.grad(lambda q, v, t: jnp.sum(f(model, q, v, t) ** 2)))

    assert _relative(jax.jit(per_state(forward_dynamics))(q, v, tau),
                     jax.jit(per_state(aba))(q, v, tau)) < 1e-12
    for transform in (jax.jacfwd, jax.jacrev):
        ours = jax.jit(transform(lambda q: forward_dynamics(model, q, v[0], tau[0])))(q[0])
        reference = jax.jit(transform(lambda q: aba(model, q, v[0], tau[0])))(q[0])
        assert _relative(ours, reference) < 1e-12
