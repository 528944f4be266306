"""Seed 002's constraint stabilization on top of the O(n) recursion (§2.4, eqs 89-108).

The unconstrained recursion gives eta, the accelerations with every constraint load removed
(eq 101); the same recursion driven by unit generalized constraint loads, the rows of A, with no
gravity and no velocity gives the columns of Gamma (eqs 102-107: zeta = -Gamma f_c), so

    u_dot + Gamma f_c = eta                                                   (eq 108)

costs m + 1 passes of O(n). The constraint loads f_c follow from A u_dot + b = 0:

- epsilon = 0: (A Gamma) f_c = A eta + b, an m x m solve, O(m^3) (regularized and rank-checked
  as in `mbjax.loops.coupled.multipliers`);
- epsilon > 0, seed 002's epsilon-dynamics (eqs 89-93): f_c is a state with
  epsilon f_c_dot + A Gamma f_c = A eta + b, which relaxes onto the algebraic value on the time
  scale epsilon / eig(A Gamma); its integral keeps A u + B = epsilon f_c + const, so the
  velocity constraint error stays bounded instead of drifting.

Total cost O(n m + m^3) = O(n + m^3) for a fixed number of loops. Here f_c = -K_c of
`mbjax.loops.coupled` (seed 002 counts the loads with the opposite sign).
"""

import equinox as eqx
import jax
import jax.numpy as jnp
from jax import Array

from mbjax.loops.constraints import Loops
from mbjax.loops.coupled import multipliers, numerical_rank
from mbjax.rigid.dynamics import forward_dynamics


def eta_and_gamma(loops: Loops, q: Array, v: Array, tau: Array, t=0.0) -> tuple[Array, Array, Array]:
    """(eta, Gamma (nv, m), A) by m + 1 passes of the O(n) recursion."""
    model = loops.model
    eta = forward_dynamics(model, q, v, tau, method="recursive")
    A = loops.jacobian(q, t)
    unloaded = eqx.tree_at(lambda m: m.gravity, model, jnp.zeros_like(model.gravity))
    zero = jnp.zeros_like(v)
    Gamma = jax.vmap(lambda load: forward_dynamics(unloaded, q, zero, load, method="recursive"))(A).T
    return eta, Gamma, A


def stabilized_acceleration(loops: Loops, q: Array, v: Array, tau: Array, t=0.0,
                            f_c=None, epsilon=0.0) -> tuple[Array, Array, Array]:
    """(u_dot, f_c_dot or f_c, rank): with epsilon = 0 the algebraic loads f_c and u_dot =
    eta - Gamma f_c; with epsilon > 0 and the current loads f_c, their rate of eq 93."""
    eta, Gamma, A = eta_and_gamma(loops, q, v, tau, t)
    AG = A @ Gamma
    rhs = A @ eta + loops.acceleration_bias(q, v, t)
    if f_c is None:
        f_c, rank = multipliers(AG, rhs)
        return eta - Gamma @ f_c, f_c, rank
    return eta - Gamma @ f_c, (rhs - AG @ f_c) / epsilon, numerical_rank(AG)
