"""The two tree passes every algorithm is written with: outward (base to tips) and inward.

Both run as one `lax.scan` over `Topology.schedule`, so the traced program has the same size for a
chain of 10 bodies and of 1000 (compile time flat in n), and all bodies of one step are handled
together by `vmap`. Per-body values live in arrays with one spare row: row n stands for the ground,
the parent of every base body. Padding in the schedule repeats a real body and its writes are
dropped, so it never computes on made-up data (no NaN to leak into gradients).

Seed 002 §2.3 runs exactly these passes: (i) outward kinematics, (ii) inward triangularization,
(iii) outward back-substitution.
"""

from collections.abc import Callable

import jax
import jax.numpy as jnp
import numpy as np

from mbjax.tree.topology import Topology


def _rows(tree, index):
    return jax.tree.map(lambda a: a[index], tree)


def _plan(topology: Topology, reverse: bool):
    """Per step: the bodies, where their results go (n + 1 = dropped) and their parents' rows."""
    n = topology.n
    order, mask = topology.schedule
    if reverse:
        order, mask = order[::-1], mask[::-1]
    parents = np.asarray(topology.parents)
    parent_row = np.where(parents < 0, n, parents)[order]
    write = np.where(mask, order, n + 1)
    return jnp.asarray(order), jnp.asarray(write), jnp.asarray(parent_row), mask


def _apply(f, *args):
    return jax.vmap(f)(*args) if args[-1] is not None else jax.vmap(lambda a: f(a, None))(args[0])


def forward_pass(topology: Topology, f: Callable, ground, inputs=None):
    """Outward pass: value[k] = f(value[parent(k)], inputs[k]); a base body sees `ground`.

    `ground` is a pytree of one value; `inputs` a pytree of per-body arrays (leading axis n) or
    None. Returns the per-body values, a pytree with leading axis n.
    """
    n = topology.n
    order, write, parent_row, _ = _plan(topology, reverse=False)
    step_inputs = None if inputs is None else _rows(inputs, order)
    values = jax.tree.map(lambda g: jnp.zeros((n + 1, *jnp.shape(g)), jnp.result_type(g))
                          .at[n].set(g), ground)

    def step(values, xs):
        dest, read, inp = xs
        new = _apply(f, _rows(values, read), inp)
        values = jax.tree.map(lambda a, b: a.at[dest].set(b.astype(a.dtype), mode="drop"),
                              values, new)
        return values, None

    values, _ = jax.lax.scan(step, values, (write, parent_row, step_inputs))
    return _rows(values, slice(0, n))


def backward_pass(topology: Topology, f: Callable, init, inputs=None):
    """Inward pass, tips first: each body k receives init[k] plus what its children sent,
    (out[k], to_parent) = f(received, inputs[k]), and to_parent is added to what its parent
    receives. Returns (out, ground): out has leading axis n, ground is the sum of what the base
    bodies sent.
    """
    n = topology.n
    order, write, parent_row, mask = _plan(topology, reverse=True)
    send = jnp.asarray(np.where(mask, np.asarray(parent_row), n + 1))
    step_inputs = None if inputs is None else _rows(inputs, order)
    received = jax.tree.map(lambda a: jnp.concatenate([a, jnp.zeros_like(a[:1])]), init)
    out_shape = jax.eval_shape(lambda r, x: f(r, x)[0], _rows(init, 0),
                               None if inputs is None else _rows(inputs, 0))
    outs = jax.tree.map(lambda s: jnp.zeros((n, *s.shape), s.dtype), out_shape)

    def step(carry, xs):
        received, outs = carry
        read, dest, up, inp = xs
        out, to_parent = _apply(f, _rows(received, read), inp)
        outs = jax.tree.map(lambda a, b: a.at[dest].set(b, mode="drop"), outs, out)
        received = jax.tree.map(lambda a, b: a.at[up].add(b, mode="drop"), received, to_parent)
        return (received, outs), None

    (received, outs), _ = jax.lax.scan(step, (received, outs), (order, write, send, step_inputs))
    return outs, _rows(received, n)
