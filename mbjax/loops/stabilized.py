"""Seed 002's constraint stabilization on top of the O(n) recursion (§2.4, eqs 89-108).

The unconstrained recursion gives eta, the accelerations with every constraint load removed
(eq 101); the same recursion driven by unit generalized constraint loads, the rows of A, with no
gravity and no velocity gives the columns of Gamma (eqs 102-107: zeta = -Gamma f_c), so

    u_dot + Gamma f_c = eta                                                   (eq 108)

costs one triangularization and m + 1 force passes of O(n) (`mbjax.rigid.aba.aba_responses`).
The constraint loads f_c follow from A u_dot + b = 0:

- epsilon = 0: (A Gamma) f_c = A eta + b, an m x m solve, O(m^3) (regularized and rank-checked
  as in `mbjax.loops.coupled.multipliers`);
- epsilon > 0, seed 002's epsilon-dynamics (eqs 89-93): f_c is a state with
  epsilon f_c_dot + A Gamma f_c = A eta + b, which relaxes onto the algebraic value on the time
  scale epsilon / eig(A Gamma); its integral keeps A u + B - epsilon f_c constant (zero when
  f_c starts from eq 89). The velocity error is then epsilon f_c: the paper's constraints are
  nonholonomic, and for holonomic ones the position error Phi grows like the integral of
  epsilon f_c (linearly under a steady load such as gravity).
- kappa > 0 (an addition to the paper, for holonomic constraints): eq 89 applied to the
  error A u + B + kappa Phi instead, so epsilon f_c_dot + A Gamma f_c = A eta + b + kappa (A u + B)
  and Phi_dot + kappa Phi = epsilon f_c: the position error stays bounded by
  epsilon |f_c| / kappa. The load equation keeps its fast time scale epsilon / eig(A Gamma)
  and gains a slow one, 1 / kappa.

Total cost O(n m + m^3) = O(n + m^3) for a fixed number of loops. Here f_c = -K_c of
`mbjax.loops.coupled` (seed 002 counts the loads with the opposite sign).
"""

from jax import Array

from mbjax.flex.aba import flexible_aba_responses
from mbjax.flex.model import FlexibleModel
from mbjax.loops.constraints import Loops
from mbjax.loops.coupled import multipliers, numerical_rank
from mbjax.rigid.aba import aba_responses


def eta_and_gamma(loops: Loops, q: Array, v: Array, tau: Array, t=0.0) -> tuple[Array, Array, Array]:
    """(eta, Gamma (nv, m), A): one triangularization of the O(n) recursion, then its force and
    back-substitution passes for tau (eta, eq 101) and for the m unit loads, the rows of A
    (Gamma, eqs 102-107)."""
    A = loops.jacobian(q, t)
    responses = (flexible_aba_responses if isinstance(loops.model, FlexibleModel)
                 else aba_responses)                  # flexible bodies: eqs 94-100 in the recursion
    eta, Gamma_t = responses(loops.model, q, v, tau, A)
    return eta, Gamma_t.T, A


def stabilized_acceleration(loops: Loops, q: Array, v: Array, tau: Array, t=0.0,
                            f_c=None, epsilon=0.0, kappa=0.0) -> tuple[Array, Array, Array]:
    """(u_dot, f_c_dot or f_c, rank): with epsilon = 0 the algebraic loads f_c and u_dot =
    eta - Gamma f_c; with epsilon > 0 and the current loads f_c, their rate of eq 93 (plus
    kappa (A u + B) when the position feedback kappa, a Python float, is set)."""
    eta, Gamma, A = eta_and_gamma(loops, q, v, tau, t)
    AG = A @ Gamma
    rhs = A @ eta + loops.acceleration_bias(q, v, t)
    if f_c is None:
        f_c, rank = multipliers(AG, rhs)
        return eta - Gamma @ f_c, f_c, rank
    if kappa != 0.0:
        rhs = rhs + kappa * loops.rate(q, v, t)
    return eta - Gamma @ f_c, (rhs - AG @ f_c) / epsilon, numerical_rank(AG)
