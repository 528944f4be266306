"""What every weak form provides on one time element (Borri 1990 §5).

A form turns the element's weak form into a square nonlinear system in its unknowns U, given the
state at the element's start z_1 = (p_1, q_1):

    residual(U; z_1) = 0    (the test rows of the initial and interior nodes, eqs 5.3, 5.8),
    z_2 = final(U; z_1)     (the end state from the last test row, once converged).

p is the momentum conjugate to the form's test function: p_hat = (h, l) for the forms tested by
the virtual rotation theta_delta, p = X^T p_hat (eq 3.17) for the symmetric primal form tested by
delta q. `to_form`/`from_form` convert. Integrals over the element are Gauss sums.
"""

import abc

import equinox as eqx
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.tfe.body import Body
from mbjax._src.tfe.elements import Element
from mbjax._src.tfe.reference import Reference


def quadrature(element: Element, dt) -> tuple[Array, Array, np.ndarray, Array]:
    """Element times t_g and weights h w_g of its Gauss points, the shape functions s (points,
    nodes) and their time derivatives s_dot = ds / h, for node spacing dt."""
    h = element.length(dt)
    return element.tau * h, element.weights * h, element.s, element.ds / h


def I_S(z: Array) -> Array:
    """I_S (p, q) = (-q, p), I_S = [[0, -I], [I, 0]] (eq 5.10); I_S^-1 = -I_S."""
    p, q = jnp.split(z, 2, axis=-1)
    return jnp.concatenate([-q, p], axis=-1)


def S1(body: Body, z: Array, y: Array) -> Array:
    """S_1(z) . y = (z_L x y_L, 0) (eq B.8, angular row first); zero about a fixed point."""
    if body.fixed_point:
        return jnp.zeros_like(y)
    return jnp.concatenate([jnp.cross(z[3:], y[3:]), jnp.zeros(3, y.dtype)])


class AbstractForm(eqx.Module):
    """A weak form of Hamilton's law for the rigid body on one time element (Borri 1990 §5).

    A strategy passed to `solve_tfe` (`Mixed()`, `PrimalUnsymmetric()`, ...). It turns the
    element's weak form into a square nonlinear system residual(U; z_1) = 0 in its unknowns U,
    given the state at the element's start z_1 = (p_1, q_1), and gives the end state
    z_2 = final(U; z_1) once converged (the system below). The concrete forms take no
    arguments.

    The system:
        In the unknowns U, given the state at the element's start z_1 = (p_1, q_1):

            residual(U; z_1) = 0    (the test rows of the initial and interior nodes, eqs 5.3,
                                     5.8),
            z_2 = final(U; z_1)     (the end state from the last test row, once converged).

        p is the momentum conjugate to the form's test function: p_hat = (h, l) for the forms
        tested by the virtual rotation theta_delta, p = X^T p_hat (eq 3.17) for the symmetric
        primal form tested by delta q. `to_form`/`from_form` convert. Integrals over the
        element are Gauss sums.
    """

    name: eqx.AbstractClassVar[str]

    @abc.abstractmethod
    def n_unknowns(self, element: Element, nq: int) -> int:
        """The number of unknowns U of one element.

        Args:
            element: the time element.
            nq: the body's number of coordinates (3 or 6).

        Returns:
            The size of U.
        """

    @abc.abstractmethod
    def guess(self, body: Body, ref: Reference, element: Element, z1: Array) -> Array:
        """The Newton starting point: the reference motion.

        Args:
            body: the body.
            ref: the element's reference motion.
            element: the time element.
            z1: the start state (p_1, q_1) in the form's variables, shape (2 nq,).

        Returns:
            The initial U, shape (n_unknowns,).
        """

    @abc.abstractmethod
    def residual(self, body: Body, ref: Reference, element: Element, dt, U: Array,
                 z1: Array) -> Array:
        """The element's equations (the test rows of the initial and interior nodes).

        Args:
            body: the body.
            ref: the element's reference motion.
            element: the time element.
            dt: the node spacing [s].
            U: the unknowns, shape (n_unknowns,).
            z1: the start state (p_1, q_1) in the form's variables, shape (2 nq,).

        Returns:
            The residual, flat, as many entries as U.
        """

    @abc.abstractmethod
    def final(self, body: Body, ref: Reference, element: Element, dt, U: Array,
              z1: Array) -> Array:
        """The end state z_2 = (p_2, q_2) from the last test row.

        Args:
            body: the body.
            ref: the element's reference motion.
            element: the time element.
            dt: the node spacing [s].
            U: the converged unknowns, shape (n_unknowns,).
            z1: the start state (p_1, q_1) in the form's variables, shape (2 nq,).

        Returns:
            z_2 in the form's variables, shape (2 nq,).
        """

    def to_form(self, body: Body, q: Array, p_hat: Array) -> Array:
        """The form's boundary momentum p from the spatial momentum p_hat.

        p_hat itself for the forms tested by the virtual rotation; p = X^T p_hat (eq 3.17) for
        those tested by delta q.

        Args:
            body: the body.
            q: incremental coordinates, shape (nq,).
            p_hat: spatial momentum about O', shape (nq,).

        Returns:
            p, shape (nq,).
        """
        return p_hat

    def from_form(self, body: Body, q: Array, p: Array) -> Array:
        """The spatial momentum p_hat from the form's boundary momentum p (inverse of `to_form`).

        Args:
            body: the body.
            q: incremental coordinates, shape (nq,).
            p: the form's momentum, shape (nq,).

        Returns:
            p_hat, shape (nq,).
        """
        return p
