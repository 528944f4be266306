"""Primal (kinematic) forms of Hamilton's law on an n-node element (Borri 1990 §3, §4, §5.1).

The trial q and the test function are both Lagrange-interpolated from nodal values (eq 5.1).
Each form supplies a pointwise pair (P1, P2) multiplying (d/dt test, test) (eqs 4.3, 4.7), and
the element residual at node k is

    G_k(Q) = int (s_dot_k P1 + s_k P2) dt.

With q_1 and p_1 prescribed (initial value problem, §5.1) the unknowns are q_2 ... q_n and the
equations are G_1 + p_1 = 0 and G_k = 0 for the interior nodes (the rows of eq 5.3 with
B (p_1, p_2) of eq 5.6); the end momentum is p_n = G_n at the converged solution.

Tangents (eqs 4.4, 4.8, 5.4) are never written by hand: `jax.jacfwd` of these residuals gives
them (see `mbjax._src.tfe.tangents`).
"""

import abc

import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.tfe.body import Body
from mbjax._src.tfe.elements import Element
from mbjax._src.tfe.form import S1, AbstractForm, quadrature
from mbjax._src.tfe.reference import (Reference, X_inverse_transpose, X_matrix, configuration,
                                   velocity)


class AbstractPrimal(AbstractForm):
    """The element machinery shared by the two primal forms."""

    @abc.abstractmethod
    def pointwise(self, body: Body, ref: Reference, q: Array, q_dot: Array, t) -> tuple[Array, Array]:
        """(P1, P2) at one time."""

    def nodal_residual(self, body: Body, ref: Reference, element: Element, dt, Q: Array) -> Array:
        """G (nodes, nq) for nodal coordinates Q (nodes, nq) (eqs 4.1/4.5 with 5.1)."""
        t, wh, s, s_dot = quadrature(element, dt)
        P1, P2 = jax.vmap(lambda q, q_dot, tg: self.pointwise(body, ref, q, q_dot, tg))(
            s @ Q, s_dot @ Q, t)
        return s_dot.T @ (wh[:, None] * P1) + s.T @ (wh[:, None] * P2)

    def n_unknowns(self, element, nq):
        return (element.nodes - 1) * nq

    def guess(self, body, ref, element, z1):
        return jnp.zeros(self.n_unknowns(element, body.nq), z1.dtype)

    def _nodes(self, body, U, z1):
        return jnp.concatenate([z1[None, body.nq:], U.reshape(-1, body.nq)])

    def residual(self, body, ref, element, dt, U, z1):
        G = self.nodal_residual(body, ref, element, dt, self._nodes(body, U, z1))
        return G[:-1].at[0].add(z1[: body.nq]).ravel()

    def final(self, body, ref, element, dt, U, z1):
        Q = self._nodes(body, U, z1)
        return jnp.concatenate([self.nodal_residual(body, ref, element, dt, Q)[-1], Q[-1]])


class PrimalUnsymmetric(AbstractPrimal):
    """The unsymmetric primal form (Borri 1990 eq 3.23 / 4.1), tested by the virtual rotation.

    P1 = p_hat, P2 = f_hat - S_1(w) p_hat (eq 4.3, B.3), with p_hat = M6 w (eq 3.19) and
    w = X q_dot + w_n (eq 3.20). Its tangent (eq 4.4, B.5) is unsymmetric. The unknowns are
    the nodal coordinates q_2 ... q_n. Takes no arguments.
    """

    name = "primal"

    def pointwise(self, body, ref, q, q_dot, t):
        R, _ = configuration(body, ref, q, t)
        w = velocity(body, ref, q, q_dot)
        p_hat = body.mass_matrix(R) @ w
        return p_hat, body.applied(R) - S1(body, w, p_hat)


class PrimalSymmetric(AbstractPrimal):
    """The symmetric primal form (Borri 1990 eq 3.24 / 4.5), tested by delta q.

    P1 = dT/dq_dot, P2 = dT/dq + X^T f_hat (eq 4.7), with T(q_dot, q, t) = w . M6 w / 2
    differentiated by autodiff. Its kinetic tangent (eq 4.8, B.16) is symmetric; the boundary
    momentum is p = X^T p_hat (eq 3.17). Takes no arguments.
    """

    name = "primal_symmetric"

    def kinetic_energy(self, body, ref, q, q_dot, t):
        R, _ = configuration(body, ref, q, t)
        w = velocity(body, ref, q, q_dot)
        return 0.5 * w @ body.mass_matrix(R) @ w

    def pointwise(self, body, ref, q, q_dot, t):
        dT_dq_dot, dT_dq = jax.grad(self.kinetic_energy, argnums=(3, 2))(body, ref, q, q_dot, t)
        R, _ = configuration(body, ref, q, t)
        return dT_dq_dot, dT_dq + X_matrix(body, q).T @ body.applied(R)

    def to_form(self, body, q, p_hat):
        return X_matrix(body, q).T @ p_hat

    def from_form(self, body, q, p):
        return X_inverse_transpose(body, q, p)
