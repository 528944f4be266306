"""Closed mechanisms as `AbstractSystem`s for `mbjax.simulate`."""

import equinox as eqx
import jax.numpy as jnp
from jax import Array

from mbjax.integrate.system import AbstractSystem
from mbjax.loops.closures import Prescribed
from mbjax.loops.constraints import Loops
from mbjax.loops.coupled import coupled_acceleration
from mbjax.loops.projection import project_configuration
from mbjax.loops.stabilized import stabilized_acceleration
from mbjax.rigid.energy import energy


class _Closed(AbstractSystem):
    """What both routes share: the tree's coordinates, chart and energy; `velocity(u)` picks the
    joint velocities out of u."""

    loops: Loops
    tau: Array

    def velocity(self, u: Array) -> Array:
        return u

    def kinematics(self, q, u):
        return self.loops.model.q_dot(q, self.velocity(u))

    def retract(self, q0, xi):
        return self.loops.model.retract(q0, xi)

    def local_rate(self, q0, xi, u):
        return self.loops.model.local_rate(q0, xi, self.velocity(u))

    def project(self, q):
        return self.loops.model.normalize(q)

    def energy(self, q, u):
        return energy(self.loops.model, q, self.velocity(u))


def _tau(loops: Loops, tau) -> Array:
    return jnp.zeros(loops.model.nv) if tau is None else jnp.asarray(tau, dtype=float)


class LoopSystem(_Closed):
    """u = v; v_dot from the coupled Lagrange-multiplier equations (seed 001 eqs 89-93), with
    Baumgarte gains (alpha, beta) (0, 0: none). tau is a constant (nv,) applied force.
    projection=True puts the configuration back on Phi = 0 after every step
    (`mbjax.loops.projection`; time-independent closures only)."""

    baumgarte: tuple = eqx.field(static=True)
    projection: bool = eqx.field(static=True)

    def __init__(self, loops: Loops, tau=None, baumgarte=(0.0, 0.0), projection: bool = False):
        if projection and any(isinstance(c, Prescribed) for c in loops.closures):
            raise ValueError("projection=True needs time-independent closures (no Prescribed)")
        self.loops = loops
        self.tau = _tau(loops, tau)
        self.baumgarte = tuple(float(g) for g in baumgarte)
        self.projection = projection

    def acceleration(self, t, q, u):
        return coupled_acceleration(self.loops, q, u, self.tau, t, self.baumgarte)[0]

    def project(self, q):
        q = self.loops.model.normalize(q)
        return project_configuration(self.loops, q)[0] if self.projection else q


class StabilizedLoopSystem(_Closed):
    """Seed 002's O(n + m^3) route (`mbjax.loops.stabilized`). epsilon = 0: u = v and algebraic
    loads; epsilon > 0: u = (v, f_c), the loads integrated by eq 93 from `initial_loads` (eq 89),
    so that A v + B = epsilon f_c all along: the velocity constraint holds to O(epsilon), at the
    price of a stiff load equation (time constant epsilon / eig(A Gamma))."""

    epsilon: float = eqx.field(static=True)

    def __init__(self, loops: Loops, tau=None, epsilon: float = 0.0):
        if not epsilon >= 0:
            raise ValueError(f"epsilon must be >= 0, got {epsilon}")
        self.loops = loops
        self.tau = _tau(loops, tau)
        self.epsilon = float(epsilon)

    def velocity(self, u):
        return u[:self.loops.model.nv]

    def initial_loads(self, q, v, t=0.0) -> Array:
        """f_c = (A v + B) / epsilon (eq 89): zero for a state that meets the constraints."""
        if self.epsilon == 0.0:
            raise ValueError("epsilon = 0 has no load state: the loads are algebraic")
        return self.loops.rate(q, v, t) / self.epsilon

    def acceleration(self, t, q, u):
        if self.epsilon == 0.0:
            return stabilized_acceleration(self.loops, q, u, self.tau, t)[0]
        nv = self.loops.model.nv
        v_dot, f_c_dot, _ = stabilized_acceleration(self.loops, q, u[:nv], self.tau, t, f_c=u[nv:],
                                                    epsilon=self.epsilon)
        return jnp.concatenate([v_dot, f_c_dot])
