"""Trees as `AbstractSystem`s, so they run through `mbjax.simulate` with every integrator.

`TreeSystem` integrates (q, v) with the velocity form (seed 002's recursion or seed 001 eq 74);
`MomentumSystem` integrates (q, p) with seed 001's momentum form (eqs 72-73).

Systems are equinox modules (their model and tau are array leaves), so compile their bound
methods with `eqx.filter_jit(system.energy)`, or pass the system as an argument:
`jax.jit(TreeSystem.energy)(system, q, u)`. (`jax.jit(system.energy)` fails: a bound method
holding arrays is not hashable.)
"""

import equinox as eqx
import jax
import jax.numpy as jnp
from jax import Array

from mbjax.integrate.system import AbstractSystem
from mbjax.model import Model
from mbjax.rigid.batched import batch_aba
from mbjax.rigid.dynamics import METHODS, forward_dynamics
from mbjax.rigid.energy import energy
from mbjax.rigid.momentum import momentum_rate, velocity_from_momentum


class _Tree(AbstractSystem):
    model: Model
    tau: Array

    def retract(self, q0, xi):
        return self.model.retract(q0, xi)

    def project(self, q):
        return self.model.normalize(q)


class TreeSystem(_Tree):
    """u = v; u_dot = forward_dynamics(model, q, v, tau, method). tau is constant (nv,)."""

    method: str = eqx.field(static=True)

    def __init__(self, model: Model, tau=None, method: str = "auto"):
        if method not in METHODS:
            raise ValueError(f"method must be one of {METHODS}, got {method!r}")
        self.model = model
        self.tau = jnp.zeros(model.nv) if tau is None else jnp.asarray(tau, dtype=float)
        self.method = method

    def kinematics(self, q, u):
        return self.model.q_dot(q, u)

    def acceleration(self, t, q, u):
        return forward_dynamics(self.model, q, u, self.tau, self.method)

    def local_rate(self, q0, xi, u):
        return self.model.local_rate(q0, xi, u)

    def energy(self, q, u):
        return energy(self.model, q, u)

    def relative_energy_error(self, qs, us):
        """(E(t) - E(0)) / |E(0)| along a saved trajectory."""
        E = jax.vmap(self.energy)(qs, us)
        return (E - E[0]) / jnp.abs(E[0])


class BatchTreeSystem(AbstractSystem):
    """B copies of a tree of revolute and prismatic joints in one system, batch last: q and u are
    (nv, B) and u_dot = `batch_aba(model, q, u, tau)`. `simulate` integrates all of them in one
    scan, with the throughput layout of `mbjax.rigid.batched` (the same trajectories as
    `jax.vmap` of a `TreeSystem` simulation). tau is (nv,) for every copy or (nv, B)."""

    model: Model
    tau: Array

    def __init__(self, model: Model, tau=None):
        self.model = model
        self.tau = jnp.zeros(model.nv) if tau is None else jnp.asarray(tau)

    def kinematics(self, q, u):
        return u

    def acceleration(self, t, q, u):
        return batch_aba(self.model, q, u, self.tau)


class MomentumSystem(_Tree):
    """u = p = M(q) v, the free momenta (seed 001 eq 73); u_dot from eq 72."""

    def __init__(self, model: Model, tau=None):
        self.model = model
        self.tau = jnp.zeros(model.nv) if tau is None else jnp.asarray(tau, dtype=float)

    def velocity(self, q, p):
        return velocity_from_momentum(self.model, q, p)

    def kinematics(self, q, u):
        return self.model.q_dot(q, self.velocity(q, u))

    def acceleration(self, t, q, u):
        return momentum_rate(self.model, q, self.velocity(q, u), self.tau)

    def local_rate(self, q0, xi, u):
        return self.model.local_rate(q0, xi, self.velocity(self.model.retract(q0, xi), u))

    def energy(self, q, u):
        return energy(self.model, q, self.velocity(q, u))
