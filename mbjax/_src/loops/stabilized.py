"""Anderson 1993's constraint stabilization on top of the O(n) recursion (`Stabilized`, whose
docstring gives the equations)."""

import equinox as eqx
import jax.numpy as jnp
from jax import Array

from mbjax._src.loops.constraints import Loops
from mbjax._src.loops.method import AbstractLoopMethod
from mbjax._src.loops.multipliers import multipliers, numerical_rank


def eta_and_gamma(loops: Loops, q: Array, v: Array, t=0.0) -> tuple[Array, Array, Array]:
    """(eta, Gamma (nv, m), A): one triangularization of the O(n) recursion, then its force and
    back-substitution passes for the tree's forces (eta, eq 101) and for the m unit loads, the
    rows of A (Gamma, eqs 102-107)."""
    A = loops.jacobian(q, t)
    eta, Gamma_t = loops.tree.responses(t, q, v, A)
    return eta, Gamma_t.T, A


def stabilized_acceleration(loops: Loops, q: Array, v: Array, t=0.0, f_c=None, epsilon=0.0,
                            kappa=0.0) -> tuple[Array, Array, Array]:
    """(u_dot, f_c_dot or f_c, rank): with epsilon = 0 the algebraic loads f_c and u_dot =
    eta - Gamma f_c; with epsilon > 0 and the current loads f_c, their rate of eq 93 (plus
    kappa (A u + B) when the position feedback kappa, a Python float, is set)."""
    eta, Gamma, A = eta_and_gamma(loops, q, v, t)
    AG = A @ Gamma
    rhs = A @ eta + loops.acceleration_bias(q, v, t)
    if f_c is None:
        f_c, rank = multipliers(AG, rhs)
        return eta - Gamma @ f_c, f_c, rank
    if kappa != 0.0:
        rhs = rhs + kappa * loops.rate(q, v, t)
    return eta - Gamma @ f_c, (rhs - AG @ f_c) / epsilon, numerical_rank(AG)


class Stabilized(AbstractLoopMethod):
    """Anderson 1993's O(n + m^3) route, for rigid and flexible trees.

    epsilon = 0: u = v and algebraic loads. epsilon > 0: u = (v, f_c), the loads integrated by
    eq 93, so that A v + B - epsilon f_c keeps its initial value all along: the velocity
    constraint holds to O(epsilon |f_c|), at the price of a stiff load equation (time constant
    epsilon / eig(A Gamma): explicit steps need dt < 2.8 epsilon / max eig(A Gamma), an
    A-stable implicit integrator such as `ImplicitMidpoint` takes any epsilon).

    Args:
        epsilon (float): the epsilon-dynamics' parameter (>= 0; 0: algebraic loads); static.
        kappa (float): position feedback (>= 0, needs epsilon > 0): the position error then stays
            below epsilon |f_c| / kappa (see The method in docs/details.md); static.

    Raises:
        ValueError: a negative epsilon or kappa, or kappa without epsilon.

    More on the method: the documentation site's Details page (docs/details.md).
    """

    epsilon: float = eqx.field(static=True, default=0.0)
    kappa: float = eqx.field(static=True, default=0.0)

    def __check_init__(self):
        if not self.epsilon >= 0 or not self.kappa >= 0:
            raise ValueError(f"epsilon and kappa must be >= 0, got {self.epsilon} and {self.kappa}")
        if self.kappa and not self.epsilon:
            raise ValueError("kappa is the position feedback of the epsilon-dynamics: "
                             "set epsilon > 0 too")

    def velocity(self, loops, q, u):
        return u[:loops.tree.nv]

    def with_velocity(self, loops, q, u, v):
        return v if self.epsilon == 0.0 else jnp.concatenate([v, u[loops.tree.nv:]])

    def state_size(self, loops) -> int | None:
        """nv, and the m loads for epsilon > 0."""
        nv = super().state_size(loops)
        return nv if self.epsilon == 0.0 or nv is None else nv + loops.m

    def initial_state(self, loops, q, v, t, consistent):
        """v, and for epsilon > 0 the load state: with consistent=True the algebraic loads of
        eq 93 at epsilon = 0, so that the error A v + B stays epsilon times the change of the
        loads rather than epsilon times the loads; else eq 89, f_c = (A v + B + kappa Phi) /
        epsilon (zero on the constraints)."""
        if self.epsilon == 0.0:
            return v
        if consistent:
            f_c = stabilized_acceleration(loops, q, v, t)[1]
        else:
            error = loops.rate(q, v, t)
            if self.kappa:
                error = error + self.kappa * loops.phi(q, t)
            f_c = error / self.epsilon
        return jnp.concatenate([v, f_c])

    def acceleration(self, loops, t, q, u):
        v = self.velocity(loops, q, u)
        if self.epsilon == 0.0:
            return stabilized_acceleration(loops, q, v, t)[0]
        v_dot, f_c_dot, _ = stabilized_acceleration(loops, q, v, t, f_c=u[loops.tree.nv:],
                                                    epsilon=self.epsilon, kappa=self.kappa)
        return jnp.concatenate([v_dot, f_c_dot])

    def loads(self, loops, t, q, u):
        """f_c = -K_c: the algebraic loads (epsilon = 0) or the load state."""
        if self.epsilon == 0.0:
            return stabilized_acceleration(loops, q, self.velocity(loops, q, u), t)[1]
        return u[loops.tree.nv:]

    def multipliers(self, loops, t, q, u):
        """K_c = -f_c."""
        return -self.loads(loops, t, q, u)
