"""Tangent matrices by autodiff, and the one hand formula they are checked against (Borri 1990
§4, App. A-B).

The paper derives the tangents of every weak form by hand over Appendix B; here each is one
`jax.jacfwd` of the residual it linearizes:

* `pointwise_tangent`: T_p_hat (eq 4.4, B.5-B.6) or T_p (eq 4.8, B.12-B.17) of a primal form,
  the derivative of (P1, P2) with respect to (q_dot, q) at one time;
* `element_tangent`: the integrated tangent K of an element (eq 5.4 / 5.9a).

`H` is eq A.47, d(Gamma^T b)/dr, written out for comparison with autodiff.
"""

import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src import lie
from mbjax._src.tfe.body import Body
from mbjax._src.tfe.elements import Element
from mbjax._src.tfe.form import AbstractForm
from mbjax._src.tfe.primal import AbstractPrimal
from mbjax._src.tfe.reference import Reference


def H(r: Array, b: Array) -> Array:
    """H(r, b) = d(Gamma^T(r) b)/dr (eqs A.46-A.48), for r != 0:

        H = a_1 (b x I) + b_1 [(b x r) x I - (r x I)(b x I)] + c_1 (b x r) r^T
            + d_1 (r x (r x b)) r^T,

    with a_1, b_1 of eq A.23 and c_1 = (da_1/dphi) / phi, d_1 = (db_1/dphi) / phi (eq A.48).
    The printed eq A.47 has the same terms but signs that do not match d(Gamma^T b)/dr (the
    a_1 and d_1 terms, and (b x I)(r x I) for -(r x I)(b x I)); this form matches autodiff to
    round-off and satisfies eq A.49, H = H^T + Gamma^T (b x I) Gamma.
    """
    phi2 = r @ r
    phi = jnp.sqrt(phi2)
    a1 = (1.0 - jnp.cos(phi)) / phi2
    b1 = (1.0 - jnp.sin(phi) / phi) / phi2
    c1 = (jnp.sin(phi) / phi - 2.0 * a1) / phi2
    d1 = (a1 - 3.0 * b1) / phi2
    b_x_r = jnp.cross(b, r)
    return (a1 * lie.hat(b) + b1 * (lie.hat(b_x_r) - lie.hat(r) @ lie.hat(b))
            + c1 * jnp.outer(b_x_r, r) + d1 * jnp.outer(jnp.cross(r, jnp.cross(r, b)), r))


def pointwise_tangent(form: AbstractPrimal, body: Body, ref: Reference, q: Array, q_dot: Array,
                      t) -> Array:
    """[[dP1/dq_dot, dP1/dq], [dP2/dq_dot, dP2/dq]] (eqs 4.4, 4.8), (2 nq, 2 nq)."""
    def P(q_dot, q):
        return jnp.concatenate(form.pointwise(body, ref, q, q_dot, t))
    return jnp.concatenate(jax.jacfwd(P, argnums=(0, 1))(q_dot, q), axis=1)


def element_tangent(form: AbstractForm, body: Body, ref: Reference, element: Element, dt,
                    U: Array, z1: Array) -> Array:
    """K = d residual / dU of one element (eqs 5.4, 5.9a), the matrix Newton solves with."""
    return jax.jacfwd(lambda U: form.residual(body, ref, element, dt, U, z1))(U)
