"""Closed mechanisms as `AbstractSystem`s for `mbjax.simulate`."""

import jax.numpy as jnp
from jax import Array

from mbjax.integrate.system import AbstractSystem
from mbjax.loops.constraints import Loops
from mbjax.loops.coupled import coupled_acceleration
from mbjax.rigid.energy import energy


class LoopSystem(AbstractSystem):
    """u = v; v_dot from the coupled Lagrange-multiplier equations (seed 001 eqs 89-93), with
    Baumgarte gains (alpha, beta) (0, 0: none). tau is a constant (nv,) applied force."""

    loops: Loops
    tau: Array
    baumgarte: tuple

    def __init__(self, loops: Loops, tau=None, baumgarte=(0.0, 0.0)):
        self.loops = loops
        self.tau = jnp.zeros(loops.model.nv) if tau is None else jnp.asarray(tau, dtype=float)
        self.baumgarte = tuple(float(g) for g in baumgarte)

    def kinematics(self, q, u):
        return self.loops.model.q_dot(q, u)

    def acceleration(self, t, q, u):
        return coupled_acceleration(self.loops, q, u, self.tau, t, self.baumgarte)[0]

    def retract(self, q0, xi):
        return self.loops.model.retract(q0, xi)

    def local_rate(self, q0, xi, u):
        return self.loops.model.local_rate(q0, xi, u)

    def project(self, q):
        return self.loops.model.normalize(q)

    def energy(self, q, u):
        return energy(self.loops.model, q, u)
