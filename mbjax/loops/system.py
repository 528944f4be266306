"""Closed mechanisms as `AbstractSystem`s for `mbjax.simulate`.

Every closed system takes the applied generalized forces as `tau` (a constant (nv,) array) plus
an optional `force(t, q, v) -> (nv,)` (springs, dampers, motors: any callable, an `eqx.Module`
if its parameters are to be differentiated or swept). After each step `simulate` calls
`constrain` (projection onto Phi = 0 and A v + B = 0 when `projection=True`), and at every
saved state `check`, which flags `Status.CONSTRAINT_VIOLATED` once |Phi| exceeds `tolerance`
and `Status.REDUNDANT` when the constraint Jacobian has lost rank (redundant closures, a
singular configuration; the least-squares loads of `mbjax.loops.coupled.multipliers` keep the
run finite).
"""

from collections.abc import Callable

import equinox as eqx
import jax
import jax.numpy as jnp
from jax import Array

from mbjax.flex.lagrange import energy as flexible_energy
from mbjax.flex.model import FlexibleModel
from mbjax.integrate.solution import Status
from mbjax.integrate.system import AbstractSystem
from mbjax.loops.constraints import Loops
from mbjax.loops.coupled import coupled_acceleration, momentum_rate, numerical_rank
from mbjax.loops.projection import project_configuration, project_velocity
from mbjax.loops.stabilized import stabilized_acceleration
from mbjax.rigid.dynamics import mass_matrix
from mbjax.rigid.energy import energy

TOLERANCE = 1e-6


class _Closed(AbstractSystem):
    """What every route shares: the tree's coordinates, chart and energy, the applied forces, the
    post-step projection and the status check; `velocity(q, u)` picks the joint velocities out of
    the route's u."""

    loops: Loops
    tau: Array
    force: Callable | None
    projection: bool = eqx.field(static=True)
    tolerance: float = eqx.field(static=True)

    def __init__(self, loops: Loops, tau=None, force: Callable | None = None,
                 projection: bool = False, tolerance: float = TOLERANCE):
        if not isinstance(loops, Loops):
            raise TypeError(f"loops must be a mbjax.loops.Loops, got {type(loops).__name__}")
        nv = loops.model.nv
        self.loops = loops
        self.tau = jnp.zeros(nv) if tau is None else jnp.asarray(tau, dtype=float)
        if self.tau.shape != (nv,):
            raise ValueError(f"tau must have shape ({nv},), got {self.tau.shape}")
        if force is not None and not callable(force):
            raise TypeError("force must be a callable force(t, q, v) -> (nv,) generalized force")
        if not tolerance > 0:
            raise ValueError(f"tolerance must be positive, got {tolerance}")
        self.force = force
        self.projection = bool(projection)
        self.tolerance = float(tolerance)

    def velocity(self, q: Array, u: Array) -> Array:
        return u

    def applied(self, t, q: Array, v: Array) -> Array:
        """K^a: tau plus force(t, q, v)."""
        return self.tau if self.force is None else self.tau + self.force(t, q, v)

    def kinematics(self, q, u):
        return self.loops.model.q_dot(q, self.velocity(q, u))

    def retract(self, q0, xi):
        return self.loops.model.retract(q0, xi)

    def local_rate(self, q0, xi, u):
        return self.loops.model.local_rate(q0, xi, self.velocity(self.retract(q0, xi), u))

    def project(self, q):
        return self.loops.model.normalize(q)

    def energy(self, q, u):
        """Kinetic plus gravitational (and, for flexible bodies, strain) energy; the work of
        `force` and `tau` is not included."""
        model = self.loops.model
        return (flexible_energy if isinstance(model, FlexibleModel) else energy)(
            model, q, self.velocity(q, u))

    def constrain(self, t, q, u):
        if not self.projection:
            return q, u
        q = project_configuration(self.loops, q, t)[0]
        v = self.velocity(q, u)
        return q, self.with_velocity(q, u, project_velocity(self.loops, q, v, t))

    def with_velocity(self, q, u, v):
        """u with its velocity part replaced by v."""
        return v

    def check(self, t, q, u):
        violated = jnp.linalg.norm(self.loops.phi(q, t)) > self.tolerance
        A = self.loops.jacobian(q, t)
        redundant = numerical_rank(A @ A.T) < self.loops.m
        return (jnp.where(violated, int(Status.CONSTRAINT_VIOLATED), 0)
                | jnp.where(redundant, int(Status.REDUNDANT), 0)).astype(jnp.int32)


def _rigid_only(loops: Loops, name: str) -> None:
    if isinstance(loops, Loops) and isinstance(loops.model, FlexibleModel):
        raise TypeError(f"{name} solves seed 001's multipliers with a symmetric mass matrix; "
                        "flexible bodies (whose stiffening makes it unsymmetric) close loops "
                        "through seed 002's route, StabilizedLoopSystem")


class LoopSystem(_Closed):
    """u = v; v_dot from the coupled Lagrange-multiplier equations (seed 001 eqs 89-93), with
    Baumgarte gains (alpha, beta) (0, 0: none)."""

    baumgarte: tuple = eqx.field(static=True)

    def __init__(self, loops: Loops, tau=None, baumgarte=(0.0, 0.0), projection: bool = False,
                 force: Callable | None = None, tolerance: float = TOLERANCE):
        _rigid_only(loops, "LoopSystem")
        super().__init__(loops, tau, force, projection, tolerance)
        self.baumgarte = tuple(float(g) for g in baumgarte)
        if len(self.baumgarte) != 2 or min(self.baumgarte) < 0:
            raise ValueError(f"baumgarte must be two gains (alpha, beta) >= 0, got {baumgarte}")

    def acceleration(self, t, q, u):
        return coupled_acceleration(self.loops, q, u, self.applied(t, q, u), t, self.baumgarte)[0]

    def loads(self, t, q, u) -> Array:
        """The multipliers K_c (seed 001 eq 92): A^t K_c is the generalized constraint force."""
        return coupled_acceleration(self.loops, q, u, self.applied(t, q, u), t, self.baumgarte)[1]


class MomentumLoopSystem(_Closed):
    """u = G = mu v, the generalized momenta; G_dot = K^a - X + A^t K_c with the multipliers of
    seed 001 eq 98 (the momentum formulation, eqs 95-98). `momenta(q, v)` makes u from v."""

    def __init__(self, loops: Loops, tau=None, projection: bool = False,
                 force: Callable | None = None, tolerance: float = TOLERANCE):
        _rigid_only(loops, "MomentumLoopSystem")
        super().__init__(loops, tau, force, projection, tolerance)

    def acceleration(self, t, q, u):
        return momentum_rate(self.loops, q, u, self.applied(t, q, self.velocity(q, u)), t)[0]

    def velocity(self, q, u):
        factor = jax.scipy.linalg.cho_factor(mass_matrix(self.loops.model, q))
        return jax.scipy.linalg.cho_solve(factor, u)

    def momenta(self, q, v) -> Array:
        return mass_matrix(self.loops.model, q) @ v

    def with_velocity(self, q, u, v):
        return self.momenta(q, v)

    def loads(self, t, q, u) -> Array:
        return momentum_rate(self.loops, q, u, self.applied(t, q, self.velocity(q, u)), t)[1]


class StabilizedLoopSystem(_Closed):
    """Seed 002's O(n + m^3) route (`mbjax.loops.stabilized`). epsilon = 0: u = v and algebraic
    loads; epsilon > 0: u = (v, f_c), the loads integrated by eq 93 from `initial_loads`, so that
    A v + B - epsilon f_c keeps its initial value all along: the velocity constraint holds to
    O(epsilon |f_c|), at the price of a stiff load equation (time constant epsilon /
    eig(A Gamma): explicit steps need dt < 2.8 epsilon / max eig(A Gamma), an A-stable implicit
    integrator such as `ImplicitMidpoint` takes any epsilon)."""

    epsilon: float = eqx.field(static=True)
    kappa: float = eqx.field(static=True)

    def __init__(self, loops: Loops, tau=None, epsilon: float = 0.0, kappa: float = 0.0,
                 projection: bool = False, force: Callable | None = None,
                 tolerance: float = TOLERANCE):
        super().__init__(loops, tau, force, projection, tolerance)
        if not epsilon >= 0 or not kappa >= 0:
            raise ValueError(f"epsilon and kappa must be >= 0, got {epsilon} and {kappa}")
        if kappa and not epsilon:
            raise ValueError("kappa is the position feedback of the epsilon-dynamics: "
                             "set epsilon > 0 too")
        self.epsilon = float(epsilon)
        self.kappa = float(kappa)

    def velocity(self, q, u):
        return u[:self.loops.model.nv]

    def with_velocity(self, q, u, v):
        return v if self.epsilon == 0.0 else jnp.concatenate([v, u[self.loops.model.nv:]])

    def initial_loads(self, q, v, t=0.0, *, consistent: bool = False) -> Array:
        """The load state at (q, v): eq 89, f_c = (A v + B + kappa Phi) / epsilon (zero on the
        constraints),
        or with consistent=True the algebraic loads of eq 93 at epsilon = 0, so that the error
        A v + B stays epsilon times the change of the loads rather than epsilon times the loads."""
        if self.epsilon == 0.0:
            raise ValueError("epsilon = 0 has no load state: the loads are algebraic")
        if consistent:
            return stabilized_acceleration(self.loops, q, v, self.applied(t, q, v), t)[1]
        error = self.loops.rate(q, v, t)
        if self.kappa:
            error = error + self.kappa * self.loops.phi(q, t)
        return error / self.epsilon

    def acceleration(self, t, q, u):
        v = self.velocity(q, u)
        tau = self.applied(t, q, v)
        if self.epsilon == 0.0:
            return stabilized_acceleration(self.loops, q, v, tau, t)[0]
        v_dot, f_c_dot, _ = stabilized_acceleration(self.loops, q, v, tau, t,
                                                    f_c=u[self.loops.model.nv:],
                                                    epsilon=self.epsilon, kappa=self.kappa)
        return jnp.concatenate([v_dot, f_c_dot])

    def loads(self, t, q, u) -> Array:
        """f_c = -K_c: the algebraic loads (epsilon = 0) or the load state."""
        if self.epsilon == 0.0:
            v = self.velocity(q, u)
            return stabilized_acceleration(self.loops, q, v, self.applied(t, q, v), t)[1]
        return u[self.loops.model.nv:]
