"""Feedback laws: a PD servo and an MLP policy."""

import equinox as eqx
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.control.base import AbstractControl, saturate


def _index(index):
    return None if index is None else tuple(int(i) for i in np.atleast_1d(index))


class PD(AbstractControl):
    """tau = kp (q_ref - q[q_index]) + kd (v_ref - v[v_index]) + feedforward.

    q_index and v_index pick the coordinates the servo acts on (all of them by default); they
    differ where a joint's configuration and velocity coordinates do (after a floating base's
    7 and 6). The gains may be scalars or one per coordinate; every array is a differentiable
    leaf."""

    kp: Array
    kd: Array
    q_ref: Array
    v_ref: Array
    feedforward: Array
    q_index: tuple | None = eqx.field(static=True)
    v_index: tuple | None = eqx.field(static=True)

    def __init__(self, kp, kd, q_ref, v_ref=0.0, feedforward=0.0, *, q_index=None, v_index=None):
        self.kp, self.kd, self.q_ref, self.v_ref, self.feedforward = (
            jnp.asarray(x, dtype=float) for x in (kp, kd, q_ref, v_ref, feedforward))
        self.q_index, self.v_index = _index(q_index), _index(v_index)
        if (self.q_index is None) != (self.v_index is None) or (
                self.q_index is not None and len(self.q_index) != len(self.v_index)):
            raise ValueError("q_index and v_index must both be given, with one entry per servoed "
                             f"coordinate; got {self.q_index} and {self.v_index}")

    def __call__(self, t, q, v):
        if self.q_index is not None:
            q, v = q[jnp.array(self.q_index)], v[jnp.array(self.v_index)]
        return self.kp * (self.q_ref - q) + self.kd * (self.v_ref - v) + self.feedforward


class MLPPolicy(AbstractControl):
    """tau = scale MLP(q, v) (or of (t, q, v) with time=True), saturated at `limit` if given.

    The output layer starts at zero, so the untrained policy is no control at all and can be
    added to a servo (`PD(...) + MLPPolicy(...)`) without disturbing it."""

    mlp: eqx.nn.MLP
    scale: Array
    limit: Array | None
    time: bool = eqx.field(static=True)

    def __init__(self, n_in: int, n_out: int, *, key, width: int = 32, depth: int = 2, scale=1.0,
                 limit=None, time: bool = False, activation=jnp.tanh):
        mlp = eqx.nn.MLP(n_in + int(time), n_out, width, depth, activation=activation, key=key)
        last = mlp.layers[-1]
        self.mlp = eqx.tree_at(lambda m: (m.layers[-1].weight, m.layers[-1].bias), mlp,
                               (jnp.zeros_like(last.weight), jnp.zeros_like(last.bias)))
        self.scale = jnp.asarray(scale, dtype=float)
        self.limit = None if limit is None else jnp.asarray(limit, dtype=float)
        self.time = time

    def __call__(self, t, q, v):
        x = jnp.concatenate([jnp.atleast_1d(jnp.asarray(t, q.dtype))[:int(self.time)], q, v])
        if x.shape[0] != self.mlp.in_size:
            raise ValueError(f"MLPPolicy takes {self.mlp.in_size} inputs ((t,) q, v), got "
                             f"{x.shape[0]}: build it with n_in = nq + nv of the system")
        return saturate(self.scale * self.mlp(x), self.limit)
