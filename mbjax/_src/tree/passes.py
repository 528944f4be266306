"""The two tree passes every algorithm is written with: outward (base to tips) and inward.

Both run as one `lax.scan`, so the traced program has the same size for a chain of 10 bodies and
of 1000 (compile time flat in n). The kind of scan follows the tree's shape
(`Topology.schedule`):

- a chain (body k hangs from body k - 1) carries just the previous body's value, with no indexing;
- a tree visited one body per step carries per-body arrays and reads and writes single rows;
- a bushy tree is visited a depth level per step, all bodies of a level together by `vmap`,
  with gathers and scatters. Short levels are padded with a repeat of a real body whose writes
  are dropped, so padding never computes on made-up data (no NaN to leak into gradients).

Per-body arrays carry one spare row, row n, for the ground (the parent of every base body).
Anderson 1993 §2.3 runs exactly these passes: (i) outward kinematics, (ii) inward triangularization,
(iii) outward back-substitution.
"""

from collections.abc import Callable

import jax
import jax.numpy as jnp
import numpy as np

from mbjax._src.tree.take import take
from mbjax._src.tree.topology import Topology


def _rows(tree, index):
    if isinstance(index, np.ndarray):               # a static order: slices where it can be
        return jax.tree.map(lambda a: take(a, index), tree)
    return jax.tree.map(lambda a: a[index], tree)


def _is_chain(topology: Topology) -> bool:
    return topology.parents == tuple(range(-1, topology.n - 1))


def _call(f, value, inp):
    return f(value, None) if inp is None else f(value, inp)


def forward_pass(topology: Topology, f: Callable, ground, inputs=None):
    """Outward pass: value[k] = f(value[parent(k)], inputs[k]); a base body sees `ground`.

    `ground` is a pytree of one value; `inputs` a pytree of per-body arrays (leading axis n) or
    None. Returns the per-body values, a pytree with leading axis n.
    """
    n = topology.n
    if _is_chain(topology):
        def link(previous, inp):
            value = _call(f, previous, inp)
            return value, value
        return jax.lax.scan(link, ground, inputs, length=n)[1]

    order, mask = topology.schedule
    parents = np.asarray(topology.parents)
    parent_row = np.where(parents < 0, n, parents)[order]
    values = jax.tree.map(lambda g: jnp.concatenate(
        [jnp.zeros((n, *jnp.shape(g)), jnp.result_type(g)), jnp.asarray(g)[None]]), ground)
    step_inputs = None if inputs is None else _rows(inputs, order)

    if order.shape[1] == 1:                       # one body per step: single-row reads and writes
        def body(values, xs):
            k, parent, inp = xs
            parent_value = jax.tree.map(lambda a: jax.lax.dynamic_index_in_dim(a, parent, 0, False),
                                        values)
            new = _call(f, parent_value, _rows(inp, 0) if inp is not None else None)
            values = jax.tree.map(lambda a, b: jax.lax.dynamic_update_index_in_dim(
                a, b.astype(a.dtype), k, 0), values, new)
            return values, None
        values = jax.lax.scan(body, values, (order[:, 0], parent_row[:, 0], step_inputs))[0]
        return _rows(values, slice(0, n))

    write = np.where(mask, order, n + 1)          # padding writes are dropped

    def level(values, xs):
        dest, read, inp = xs
        parent_values = _rows(values, read)
        new = (jax.vmap(lambda pv: f(pv, None))(parent_values) if inp is None
               else jax.vmap(f)(parent_values, inp))
        values = jax.tree.map(lambda a, b: a.at[dest].set(b.astype(a.dtype), mode="drop"),
                              values, new)
        return values, None

    values = jax.lax.scan(level, values, (write, parent_row, step_inputs))[0]
    return _rows(values, slice(0, n))


def backward_pass(topology: Topology, f: Callable, init, inputs=None):
    """Inward pass, tips first: each body k receives init[k] plus what its children sent,
    (out[k], to_parent) = f(received, inputs[k]), and to_parent is added to what its parent
    receives. Returns (out, ground): out has leading axis n, ground is the sum of what the base
    bodies sent.
    """
    n = topology.n
    first = _rows(init, 0)
    out_shape, up_shape = jax.eval_shape(lambda r, x: f(r, x), first,
                                         None if inputs is None else _rows(inputs, 0))
    if _is_chain(topology):
        def link(from_child, xs):
            own, inp = xs
            out, to_parent = _call(f, jax.tree.map(jnp.add, own, from_child), inp)
            return to_parent, out
        zero = jax.tree.map(lambda s: jnp.zeros(s.shape, s.dtype), up_shape)
        ground, outs = jax.lax.scan(link, zero, (init, inputs), length=n, reverse=True)
        return outs, ground

    order, mask = topology.schedule
    order, mask = order[::-1], mask[::-1]
    parents = np.asarray(topology.parents)
    parent_row = np.where(parents < 0, n, parents)[order]
    step_inputs = None if inputs is None else _rows(inputs, order)
    received = jax.tree.map(lambda a: jnp.concatenate([a, jnp.zeros_like(a[:1])]), init)
    outs = jax.tree.map(lambda s: jnp.zeros((n, *s.shape), s.dtype), out_shape)

    if order.shape[1] == 1:
        def body(carry, xs):
            received, outs = carry
            k, parent, inp = xs
            mine = jax.tree.map(lambda a: jax.lax.dynamic_index_in_dim(a, k, 0, False), received)
            out, to_parent = _call(f, mine, _rows(inp, 0) if inp is not None else None)
            outs = jax.tree.map(lambda a, b: jax.lax.dynamic_update_index_in_dim(a, b, k, 0),
                                outs, out)
            received = jax.tree.map(
                lambda a, b: jax.lax.dynamic_update_index_in_dim(
                    a, jax.lax.dynamic_index_in_dim(a, parent, 0, False) + b, parent, 0),
                received, to_parent)
            return (received, outs), None
        received, outs = jax.lax.scan(body, (received, outs),
                                      (order[:, 0], parent_row[:, 0], step_inputs))[0]
        return outs, _rows(received, n)

    write = np.where(mask, order, n + 1)
    send = np.where(mask, parent_row, n + 1)

    def level(carry, xs):
        received, outs = carry
        read, dest, up, inp = xs
        mine = _rows(received, read)
        out, to_parent = (jax.vmap(lambda r: f(r, None))(mine) if inp is None
                          else jax.vmap(f)(mine, inp))
        outs = jax.tree.map(lambda a, b: a.at[dest].set(b, mode="drop"), outs, out)
        received = jax.tree.map(lambda a, b: a.at[up].add(b, mode="drop"), received, to_parent)
        return (received, outs), None

    received, outs = jax.lax.scan(level, (received, outs), (order, write, send, step_inputs))[0]
    return outs, _rows(received, n)


def path_sum(topology: Topology, x):
    """pi x (Jerkovsky 1978 eq 1): for each body, the sum of x (n, ...) over its path from the
    ground, itself included (x a pytree of such arrays).

    An outward pass for a chain (a carry-only scan), a product with the path matrix for a
    branched tree. Under `jax.vmap` (a horizon's knots, a Jacobian's directions) the product
    first transposes x body-major, which costs a chain more than the pass; the pass's indexed
    rows cost a tree more than the product (benchmarks/README.md, trajopt)."""
    if _is_chain(topology):
        return forward_pass(topology, lambda parent, own: jax.tree.map(jnp.add, parent, own),
                            jax.tree.map(lambda a: jnp.zeros(a.shape[1:], a.dtype), x), x)
    pi = topology.path_matrix()
    return jax.tree.map(lambda a: jnp.tensordot(pi.astype(a.dtype), a, 1), x)


def outward_sum(topology: Topology, x):
    """pi^T x: for each body, the sum of x (n, ...) over its outward set, itself included (an
    inward pass for a chain, a product with the path matrix for a branched tree; see
    `path_sum`)."""
    if _is_chain(topology):
        return backward_pass(topology, lambda received, _: (received, received), x)[0]
    pi = topology.path_matrix()
    return jax.tree.map(lambda a: jnp.tensordot(pi.T.astype(a.dtype), a, 1), x)
