"""Jerkovsky 1978's momentum formulation of a closed mechanism (`Momentum`, whose docstring gives
the equations)."""

import jax
from jax import Array

from mbjax._src.linalg import cho_solve, cholesky
from mbjax._src.loops.constraints import Loops
from mbjax._src.loops.method import AbstractLoopMethod, require_symmetric
from mbjax._src.loops.multipliers import multipliers


def loop_momentum_rate(loops: Loops, q: Array, G: Array, t=0.0) -> tuple[Array, Array, Array]:
    """(G_dot, K_c, rank) of the momentum formulation, Jerkovsky 1978 eqs 95-98, for momenta G = mu v,
    under the tree's forces."""
    tree = loops.tree
    factor = cholesky(tree.mass_matrix(q))
    v = cho_solve(factor, G)
    mu_dot_v = jax.jvp(tree.mass_matrix, (q,), (tree.q_dot(q, v),))[1] @ v
    free = mu_dot_v - tree.bias(t, q, v)                                 # K^a - X, eq 99
    A = loops.jacobian(q, t)
    nu_At = cho_solve(factor, A.T)
    nu_dot_G = -cho_solve(factor, mu_dot_v)
    rhs = -(nu_At.T @ free + loops.acceleration_bias(q, v, t) + A @ nu_dot_G)   # eq 98
    K_c, rank = multipliers(A @ nu_At, rhs)
    return free + A.T @ K_c, K_c, rank


class Momentum(AbstractLoopMethod):
    """u = G = mu v, the generalized momenta; G_dot = K^a - X + A^t K_c with the multipliers of
    Jerkovsky 1978 eq 98. Needs a tree with a symmetric mass matrix (rigid trees).

    Takes no arguments: `method=Momentum()`.

    The method:
        Jerkovsky 1978's momentum formulation of a closed mechanism (eqs 95-98).

        The state is the generalized momentum G = mu v: G_dot = K^a - X + A^t K_c (eq 87), with X =
        Y - mu_dot v (eq 99), so K^a - X = -bias + mu_dot v, and the multipliers of eq 98, (A nu
        A^t) K_c = -(A nu (K^a - X) + b + A nu_dot G), nu_dot G = -nu mu_dot v; eq 99 makes them
        equal to eq 92's (`mbjax/_src/loops/coupled.py`), which the tests check.
    """

    def validate(self, tree):
        require_symmetric("Momentum", tree)

    def velocity(self, loops, q, u):
        factor = cholesky(loops.tree.mass_matrix(q))
        return cho_solve(factor, u)

    def with_velocity(self, loops, q, u, v):
        return loops.tree.mass_matrix(q) @ v

    def initial_state(self, loops, q, v, t, consistent):
        return loops.tree.mass_matrix(q) @ v

    def acceleration(self, loops, t, q, u):
        return loop_momentum_rate(loops, q, u, t)[0]

    def loads(self, loops, t, q, u):
        return loop_momentum_rate(loops, q, u, t)[1]
