"""The three-field form of Hamilton's law (Borri 1990 eqs 3.34, B.42-B.45): coordinates q,
velocity w and momentum p_hat all independent (the Hu-Washizu form of rigid-body dynamics).

    int [ dq_hat . (f_hat - S_1(w) M6 w) + d*w . (M6 w - p_hat) - d*p . X^-1 (w - w_n)
          + d/dt(d*p, dq_hat) . I_S (p_hat, q) ] dt = (d*p, dq_hat) . I_S (p_b, q_b) |_t1^t2

(dL/dw = M6 w for the kinetic Lagrangian, eq B.47). The fields (p_hat, q, w) share the n - 1
trial functions of the mixed form (eq 5.7); (d*p, dq_hat) take the n test functions and the
virtual velocity d*w the trial functions, so that the constitutive law is a Galerkin projection.
The (d*p, dq_hat) rows are those of the mixed form with w in place of M6^-1 p_hat; the d*w rows
are interior equations. Eighteen unknowns per trial node for a free body, as the paper notes.
"""

import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.tfe.body import Body
from mbjax._src.tfe.form import I_S, S1, AbstractForm, quadrature
from mbjax._src.tfe.mixed import test_rows
from mbjax._src.tfe.reference import Reference, X_inverse, configuration, w_n


class ThreeField(AbstractForm):
    """The three-field form (Borri 1990 eqs 3.34, B.42-B.45): q, w and p_hat independent.

    The Hu-Washizu form of rigid-body dynamics: coordinates q, velocity w and momentum p_hat
    all independent. The unknowns are the n - 1 trial nodes of (p_hat, q, w) (the form below).
    Takes no arguments.

    The form:
            int [ dq_hat . (f_hat - S_1(w) M6 w) + d*w . (M6 w - p_hat) - d*p . X^-1 (w - w_n)
                  + d/dt(d*p, dq_hat) . I_S (p_hat, q) ] dt
                = (d*p, dq_hat) . I_S (p_b, q_b) |_t1^t2

        (dL/dw = M6 w for the kinetic Lagrangian, eq B.47). The fields (p_hat, q, w) share the
        n - 1 trial functions of the mixed form (eq 5.7); (d*p, dq_hat) take the n test
        functions and the virtual velocity d*w the trial functions, so that the constitutive
        law is a Galerkin projection. The (d*p, dq_hat) rows are those of the mixed form with w
        in place of M6^-1 p_hat; the d*w rows are interior equations. Eighteen unknowns per
        trial node for a free body, as the paper notes.
    """

    name = "three_field"

    def pointwise(self, body: Body, ref: Reference, y: Array, t) -> tuple[Array, Array]:
        """The `(d*p, dq_hat)` rows and the `d*w` row of eq B.45 at one time.

        Args:
            body: the body.
            ref: the element's reference motion.
            y: the fields (p_hat, q, w) at that time, shape (3 nq,).
            t: element time [s], a scalar.

        Returns:
            rows: the (d*p, dq_hat) rows, shape (2 nq,).
            constitutive: the d*w row M6 w - p_hat, shape (nq,).
        """
        p_hat, q, w = jnp.split(y, 3)
        R, _ = configuration(body, ref, q, t)
        p_w = body.mass_matrix(R) @ w
        rows = jnp.concatenate([-X_inverse(body, q, w - w_n(body, ref, q)),
                                body.applied(R) - S1(body, w, p_w)])
        return rows, p_w - p_hat

    def nodal_residual(self, body, ref, element, dt, U: Array) -> tuple[Array, Array]:
        """The element's test rows for given trial nodes.

        Args:
            body: the body.
            ref: the element's reference motion.
            element: the time element.
            dt: the node spacing [s].
            U: the trial nodes, shape (nodes - 1, 3 nq).

        Returns:
            E: the (d*p, dq_hat) rows per test node, shape (nodes, 2 nq).
            W: the constitutive rows per trial node, shape (nodes - 1, nq).
        """
        t, wh, *_ = quadrature(element, dt)
        Y = element.s_trial @ U
        rows, constitutive = jax.vmap(lambda y, tg: self.pointwise(body, ref, y, tg))(Y, t)
        E = test_rows(element, dt, Y[:, : 2 * body.nq], rows)
        W = element.s_trial.T @ (wh[:, None] * constitutive)
        return E, W

    def n_unknowns(self, element, nq):
        return (element.nodes - 1) * 3 * nq

    def guess(self, body, ref, element, z1):
        w1 = body.momentum_to_velocity(ref.R1, z1[: body.nq])
        return jnp.tile(jnp.concatenate([z1, w1]), element.nodes - 1)

    def residual(self, body, ref, element, dt, U, z1):
        E, W = self.nodal_residual(body, ref, element, dt, U.reshape(element.nodes - 1, -1))
        return jnp.concatenate([E[:-1].at[0].add(I_S(z1)).ravel(), W.ravel()])

    def final(self, body, ref, element, dt, U, z1):
        E, _ = self.nodal_residual(body, ref, element, dt, U.reshape(element.nodes - 1, -1))
        return -I_S(E[-1])
