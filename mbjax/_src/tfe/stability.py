"""Linearized stability of time elements by transition matrices (Borri 1990 §6-7).

About a known motion (here a reference that solves the equations exactly, such as the steadily
spinning top of §7), the element maps a perturbation of its initial state to one of its final
state, (dp_2, dq_2) = T (dp_1, dq_1) (eqs 6.7, 6.13). T is built here exactly as the paper does,
from the element tangent K = jacfwd of the full 3-D residual (no hand-reduced model):

* primal forms: the interior nodes are condensed out (eqs 6.1-6.4) and T follows from the
  boundary blocks of K_BB~ (eq 6.8);
* mixed and three-field forms: the initial and interior test rows are solved for the trial
  increments and substituted into the final row (eqs 6.9-6.12), T = I_S K_f K_i^-1 I_S.

The eigenvalues lambda of T give the exponents ln(lambda) / h of the discrete motion over an
element of length h, to compare with the exact ones.
"""

import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.tfe.body import Body
from mbjax._src.tfe.elements import Element
from mbjax._src.tfe.form import I_S, AbstractForm
from mbjax._src.tfe.primal import AbstractPrimal
from mbjax._src.tfe.reference import Reference


def condensed_tangent(K: Array, nodes: int, nq: int) -> Array:
    """The primal element tangent with its interior nodes condensed out (eq 6.3).

    K_BB~ = K_BB - K_BI K_II^-1 K_IB, the boundary nodes being the first and the last.

    Args:
        K: the element tangent over all nodal coordinates, shape (nodes nq, nodes nq).
        nodes: the element's number of nodes.
        nq: the body's number of coordinates.

    Returns:
        K_BB~, shape (2 nq, 2 nq).
    """
    blocks = K.reshape(nodes, nq, nodes, nq)
    boundary = jnp.array([0, nodes - 1])
    interior = jnp.arange(1, nodes - 1)
    K_BB = blocks[boundary][:, :, boundary].reshape(2 * nq, 2 * nq)
    if nodes == 2:
        return K_BB
    K_BI = blocks[boundary][:, :, interior].reshape(2 * nq, -1)
    K_IB = blocks[interior][:, :, boundary].reshape(-1, 2 * nq)
    K_II = blocks[interior][:, :, interior].reshape(K_IB.shape[0], -1)
    return K_BB - K_BI @ jnp.linalg.solve(K_II, K_IB)


def primal_transition(K_tilde: Array) -> Array:
    """The transition matrix T of eq 6.8 from the condensed tangent.

    Args:
        K_tilde: the condensed tangent K_BB~ (`condensed_tangent`), shape (2 nq, 2 nq).

    Returns:
        T, mapping (dp_1, dq_1) to (dp_2, dq_2), shape (2 nq, 2 nq).
    """
    nq = K_tilde.shape[0] // 2
    K11, K12 = K_tilde[:nq, :nq], K_tilde[:nq, nq:]
    K21, K22 = K_tilde[nq:, :nq], K_tilde[nq:, nq:]
    K12_inv_K11 = jnp.linalg.solve(K12, K11)
    K22_K12_inv = jnp.linalg.solve(K12.T, K22.T).T
    return jnp.block([[-K22_K12_inv, K21 - K22_K12_inv @ K11],
                      [-jnp.linalg.inv(K12), -K12_inv_K11]])


def transition_matrix(form: AbstractForm, body: Body, ref: Reference, element: Element, dt,
                      z1: Array, U: Array | None = None) -> Array:
    """The element's transition matrix T about a known motion: (dp_2, dq_2) = T (dp_1, dq_1).

    Eq 6.8 for the primal forms, eq 6.12 otherwise, from the element tangent by `jax.jacfwd`.

    Args:
        form: the weak form.
        body: the body.
        ref: the reference motion the element is written about.
        element: the time element.
        dt: the node spacing [s].
        z1: the start state (p_1, q_1) in the form's variables, shape (2 nq,).
        U: the element's solution to linearize about; None (default) for the reference itself
            (U = form.guess), exact where the reference solves the equations (a steady spin).

    Returns:
        T, shape (2 nq, 2 nq).
    """
    if U is None:
        U = form.guess(body, ref, element, z1)
    nq = body.nq
    if isinstance(form, AbstractPrimal):
        Q = jnp.concatenate([z1[None, nq:], U.reshape(-1, nq)])
        K = jax.jacfwd(lambda Q: form.nodal_residual(body, ref, element, dt, Q).ravel())(Q)
        return primal_transition(condensed_tangent(K.reshape(Q.size, Q.size), element.nodes, nq))
    # eq 6.9: rows = (initial, middle) test rows + I_S z_1 (initial only); z_2 = -I_S (final row)
    K_im = jax.jacfwd(lambda U: form.residual(body, ref, element, dt, U, z1))(U)
    K_f = jax.jacfwd(lambda U: form.final(body, ref, element, dt, U, z1))(U)   # -I_S K_f
    lift = jnp.zeros((U.size, 2 * nq)).at[: 2 * nq].set(jax.vmap(I_S)(jnp.eye(2 * nq)).T)
    return K_f @ -jnp.linalg.solve(K_im, lift)


def exponents(T: Array, h) -> Array:
    """The discrete motion's exponents ln(lambda) / h, lambda the eigenvalues of T.

    Args:
        T: a transition matrix, shape (2 nq, 2 nq).
        h: the element length [s].

    Returns:
        The exponents [1/s], complex, shape (2 nq,), to compare with the exact ones.
    """
    return jnp.log(jnp.linalg.eigvals(T).astype(complex)) / h


def spectral_radius(T: Array) -> Array:
    """The largest |lambda| over the eigenvalues of T (above 1: the discrete motion grows).

    Args:
        T: a transition matrix, shape (2 nq, 2 nq).

    Returns:
        The spectral radius, a scalar.
    """
    return jnp.max(jnp.abs(jnp.linalg.eigvals(T)))
