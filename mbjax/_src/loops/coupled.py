"""Coupled free and constrained motion by Lagrange multipliers (`Coupled`, whose docstring gives
the equations)."""

import math

import equinox as eqx
import jax.numpy as jnp
from jax import Array

from mbjax._src.linalg import cho_solve, cholesky
from mbjax._src.loops.constraints import Loops
from mbjax._src.loops.kkt import implicit_kkt
from mbjax._src.loops.method import AbstractLoopMethod, require_symmetric
from mbjax._src.loops.multipliers import numerical_rank


def coupled_acceleration(loops: Loops, q: Array, v: Array, t=0.0,
                         baumgarte=(0.0, 0.0)) -> tuple[Array, Array, Array]:
    """(v_dot, K_c, rank) of Jerkovsky 1978 eqs 89-93 under the tree's forces; K_c are the multipliers
    of the rows of A, so A^t K_c is the generalized constraint force. The Baumgarte gains are
    Python floats. Differentiated through the factored KKT system (`mbjax._src.loops.kkt`)."""
    v_dot, K_c = coupled_solution(loops, q, v, t, baumgarte)
    return v_dot, K_c, _rank(loops, q, jnp.asarray(t, q.dtype))


def coupled_solution(loops: Loops, q: Array, v: Array, t=0.0,
                     baumgarte=(0.0, 0.0)) -> tuple[Array, Array]:
    """(v_dot, K_c) of `coupled_acceleration`, without the rank."""
    return implicit_kkt((loops, q, v, jnp.asarray(t, q.dtype)), _matrices,
                        _Residual(tuple(baumgarte)))


def _rank(loops: Loops, q: Array, t) -> Array:
    """The numerical rank of A M^-1 A^t (redundant closures, singular configurations)."""
    M, A = _matrices((loops, q, None, t))
    return numerical_rank(A @ cho_solve(cholesky(M), A.T))


def _matrices(theta) -> tuple[Array, Array]:
    loops, q, _, t = theta
    return loops.tree.mass_matrix(q), loops.jacobian(q, t)


class _Residual(eqx.Module):
    """The coupled equations as a residual of (v_dot, K_c) (`mbjax._src.loops.kkt`):
    (M v_dot + bias - A^t K_c, A v_dot + b + 2 alpha (A v + B) + beta^2 Phi)."""

    baumgarte: tuple = eqx.field(static=True)

    def __call__(self, theta, v_dot: Array, K_c: Array) -> tuple[Array, Array]:
        loops, q, v, t = theta
        drift = loops.drift(q, v, v_dot, t)
        if self.baumgarte != (0.0, 0.0):         # Python floats: no extra passes when unused
            alpha, beta = self.baumgarte
            drift = drift + 2.0 * alpha * loops.rate(q, v, t) + beta**2 * loops.phi(q, t)
        return loops.tree.inverse(t, q, v, v_dot) - loops.force(q, K_c, t), drift


def _gains(gains) -> tuple:
    """baumgarte as a tuple of floats, or a TypeError naming it."""
    try:
        return tuple(float(g) for g in gains)
    except TypeError as error:
        raise TypeError(f"baumgarte must be two gains (alpha, beta), got {gains!r}") from error


class Coupled(AbstractLoopMethod):
    """u = v; v_dot from the coupled Lagrange-multiplier equations (Jerkovsky 1978 eqs 89-93),
    with optional Baumgarte stabilization (see The method, below). Dense, O(n^3); needs a
    tree with a symmetric mass matrix (rigid trees).

    Args:
        baumgarte (tuple[float, float]): the gains (alpha [1/s], beta [1/s]), both >= 0: the
            constraint errors obey e_ddot + 2 alpha e_dot + beta^2 e = 0; (0, 0), the default, for
            none. Static.

    Raises:
        ValueError: not two non-negative gains.

    The method:
        Coupled free and constrained motion by Lagrange multipliers (Jerkovsky 1978 §VI, eqs 85-93,
        the velocity form), with optional Baumgarte stabilization.

        With nu = mu^-1 the inverse mass matrix, the unconstrained acceleration a_free = nu (K^a -
        Y) (= -nu bias, the tree's applied forces included) and the constraint rows A v_dot + b = 0
        (`mbjax/_src/loops/constraints.py`), eqs 89-92 give the multipliers K_c from (A nu A^t) K_c =
        -(A a_free + b) and eq 93 the motion v_dot = a_free + nu A^t K_c. Baumgarte's stabilization
        adds 2 alpha (A v + B) + beta^2 Phi to b, so the constraint errors obey e_ddot + 2 alpha
        e_dot + beta^2 e = 0 instead of drifting. The mass matrix is dense here (O(n^3));
        `mbjax/_src/loops/stabilized.py` is Anderson 1993's O(n + m^3) route.
    """

    baumgarte: tuple = eqx.field(static=True, default=(0.0, 0.0), converter=_gains)

    def __check_init__(self):
        if len(self.baumgarte) != 2 or not all(g >= 0 and math.isfinite(g)
                                               for g in self.baumgarte):
            raise ValueError(f"baumgarte must be two gains (alpha, beta) >= 0, finite, got "
                             f"{self.baumgarte}")

    def validate(self, tree):
        require_symmetric("Coupled", tree)

    def acceleration(self, loops, t, q, u):
        return coupled_solution(loops, q, u, t, self.baumgarte)[0]

    def loads(self, loops, t, q, u):
        """The multipliers K_c (Jerkovsky 1978 eq 92): A^t K_c is the generalized constraint force."""
        return coupled_solution(loops, q, u, t, self.baumgarte)[1]

    def solve(self, loops, t, q, u):
        return coupled_solution(loops, q, u, t, self.baumgarte)
