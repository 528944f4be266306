"""Flexible trees as `AbstractSystem`s for `mbjax.simulate`.

`FlexibleSystem` integrates (q, v) = (joint and modal coordinates, their rates) with seed 002's
O(n) recursion ("recursive", `mbjax.flex.aba`) or the dense Lagrangian route ("dense",
`mbjax.flex.lagrange`). Closed loops and prescribed motions go through
`mbjax.loops.StabilizedLoopSystem` with a `FlexibleModel` in the `Loops`.
"""

import equinox as eqx
import jax.numpy as jnp
from jax import Array

from mbjax.flex.aba import flexible_aba
from mbjax.flex.lagrange import dense_forward_dynamics, energy
from mbjax.flex.model import FlexibleModel
from mbjax.integrate.system import AbstractSystem

METHODS = ("recursive", "dense")


class FlexibleSystem(AbstractSystem):
    """u = v; u_dot from the flexible tree's forward dynamics under constant tau (nv,)."""

    model: FlexibleModel
    tau: Array
    method: str = eqx.field(static=True)

    def __init__(self, model: FlexibleModel, tau=None, method: str = "recursive"):
        if not isinstance(model, FlexibleModel):
            raise TypeError(f"model must be a FlexibleModel, got {type(model).__name__}")
        if method not in METHODS:
            raise ValueError(f"method must be one of {METHODS}, got {method!r}")
        self.model = model
        self.tau = jnp.zeros(model.nv) if tau is None else jnp.asarray(tau, dtype=float)
        if self.tau.shape != (model.nv,):
            raise ValueError(f"tau must have shape ({model.nv},), got {self.tau.shape}")
        self.method = method

    def kinematics(self, q, u):
        return self.model.q_dot(q, u)

    def acceleration(self, t, q, u):
        if self.method == "dense":
            return dense_forward_dynamics(self.model, q, u, self.tau)
        return flexible_aba(self.model, q, u, self.tau)

    def retract(self, q0, xi):
        return self.model.retract(q0, xi)

    def local_rate(self, q0, xi, u):
        return self.model.local_rate(q0, xi, u)

    def project(self, q):
        return self.model.normalize(q)

    def energy(self, q, u):
        """Kinetic, gravitational and modal strain energy."""
        return energy(self.model, q, u)
