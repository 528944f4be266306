"""The mixed (two-field) forms of Hamilton's law on an n-node element (Borri 1990 eqs 3.28, 3.30,
4.9, B.20, §5.2, §6).

Momentum and coordinates z = (p, q) are independent fields:

    int [ d/dt(dp, dq) . I_S (p, q) + (dp, dq) . R_m ] dt = (dp, dq) . I_S (p_b, q_b) |_t1^t2,

with R_m = (-dH/dp, -dH/dq + f) in the canonical pair p = X^T p_hat (eq 4.9, `Mixed`) or
R_m = (X^-1 (w_n - w_hat), f_hat + S_1(p_hat) w_hat), w_hat = M6^-1 p_hat, tested by the virtual
rotation (eq B.20-B.22, `MixedUnsymmetric`).

Trial and test spaces differ (eq 5.7): z is spanned by n - 1 functions s_a, possibly
discontinuous at the element ends, the test state by the n Lagrange functions s_b. With
E_k = int (s_b_dot_k I_S z + s_b_k R_m) dt the equations (eq 5.8 with B of eq 5.10) are
E_1 + I_S z_1 = 0 and E_k = 0 for the interior test nodes, which fix the n - 1 trial nodes; the
end state follows from the last row, z_2 = -I_S E_n (eqs 6.9-6.11).
"""

import abc

import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.tfe.body import Body
from mbjax._src.tfe.elements import Element
from mbjax._src.tfe.form import I_S, S1, AbstractForm, quadrature
from mbjax._src.tfe.reference import (Reference, X_inverse, X_inverse_transpose, X_matrix,
                                   configuration, w_n)


def test_rows(element: Element, dt, Z: Array, R_rows: Array) -> Array:
    """E_k = int (s_b_dot_k I_S z + s_b_k R) dt for trial values Z and pointwise rows R at the
    Gauss points, (nodes, 2 nq)."""
    _, wh, s, s_dot = quadrature(element, dt)
    return s_dot.T @ (wh[:, None] * I_S(Z)) + s.T @ (wh[:, None] * R_rows)


class AbstractMixed(AbstractForm):
    """The element machinery shared by the two mixed forms: unknowns are the n - 1 trial nodes
    of z = (p, q)."""

    @abc.abstractmethod
    def pointwise(self, body: Body, ref: Reference, z: Array, t) -> Array:
        """R_m at one time."""

    def nodal_residual(self, body, ref, element, dt, U: Array) -> Array:
        """E (nodes, 2 nq) for trial nodes U (nodes - 1, 2 nq)."""
        t, *_ = quadrature(element, dt)
        Z = element.s_trial @ U
        return test_rows(element, dt, Z, jax.vmap(lambda z, tg: self.pointwise(body, ref, z, tg))(Z, t))

    def n_unknowns(self, element, nq):
        return (element.nodes - 1) * 2 * nq

    def guess(self, body, ref, element, z1):
        return jnp.tile(z1, element.nodes - 1)

    def residual(self, body, ref, element, dt, U, z1):
        E = self.nodal_residual(body, ref, element, dt, U.reshape(element.nodes - 1, -1))
        return E[:-1].at[0].add(I_S(z1)).ravel()

    def final(self, body, ref, element, dt, U, z1):
        E = self.nodal_residual(body, ref, element, dt, U.reshape(element.nodes - 1, -1))
        return -I_S(E[-1])


class MixedUnsymmetric(AbstractMixed):
    """The unsymmetric mixed form (Borri 1990 eq 3.28 / B.20) in (p_hat, q), tested by (d*p, dq_hat).

    R_m = (X^-1 (w_n - w_hat), f_hat + S_1(p_hat) w_hat) of eq B.22, w_hat = M6^-1 p_hat. The
    unknowns are the n - 1 trial nodes of (p_hat, q). Takes no arguments.
    """

    name = "mixed_unsymmetric"

    def pointwise(self, body, ref, z, t):
        p_hat, q = jnp.split(z, 2)
        R, _ = configuration(body, ref, q, t)
        w_hat = body.momentum_to_velocity(R, p_hat)
        return jnp.concatenate([X_inverse(body, q, w_n(body, ref, q) - w_hat),
                                body.applied(R) + S1(body, p_hat, w_hat)])


class Mixed(AbstractMixed):
    """The mixed form (Borri 1990 eq 3.30 / 4.9) in the canonical pair (p, q), p = X^T p_hat.

    R_m = (-dH/dp, -dH/dq + f) (eq 4.11) with the Hamiltonian of eq B.27,
    H(p, q, t) = p_hat . M6^-1 p_hat / 2 - p_hat . w_n, p_hat = X^-T p (eq 3.17),
    differentiated by autodiff (its tangent, eq 4.12 / B.32, is symmetric in the Hamiltonian
    part). This is the mixed form the paper discretizes (§5.2) and the one its figures
    compare; `solve_tfe`'s default. Takes no arguments.
    """

    name = "mixed"

    def hamiltonian(self, body: Body, ref: Reference, p: Array, q: Array, t) -> Array:
        """The Hamiltonian H(p, q, t) of eq B.27.

        Args:
            body: the body.
            ref: the element's reference motion.
            p: canonical momentum X^T p_hat, shape (nq,).
            q: incremental coordinates, shape (nq,).
            t: element time [s], a scalar.

        Returns:
            H [J], a scalar.
        """
        R, _ = configuration(body, ref, q, t)
        p_hat = X_inverse_transpose(body, q, p)
        return 0.5 * p_hat @ body.momentum_to_velocity(R, p_hat) - p_hat @ w_n(body, ref, q)

    def pointwise(self, body, ref, z, t):
        p, q = jnp.split(z, 2)
        H_p, H_q = jax.grad(self.hamiltonian, argnums=(2, 3))(body, ref, p, q, t)
        R, _ = configuration(body, ref, q, t)
        return jnp.concatenate([-H_p, -H_q + X_matrix(body, q).T @ body.applied(R)])

    def to_form(self, body, q, p_hat):
        return X_matrix(body, q).T @ p_hat

    def from_form(self, body, q, p):
        return X_inverse_transpose(body, q, p)
