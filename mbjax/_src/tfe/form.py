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
    """A weak form of Hamilton's law for the rigid body on one time element."""

    name: eqx.AbstractClassVar[str]

    @abc.abstractmethod
    def n_unknowns(self, element: Element, nq: int) -> int:
        """Size of U."""

    @abc.abstractmethod
    def guess(self, body: Body, ref: Reference, element: Element, z1: Array) -> Array:
        """The Newton starting point: the reference motion."""

    @abc.abstractmethod
    def residual(self, body: Body, ref: Reference, element: Element, dt, U: Array,
                 z1: Array) -> Array:
        """The element's equations, flat, as many as U has entries."""

    @abc.abstractmethod
    def final(self, body: Body, ref: Reference, element: Element, dt, U: Array,
              z1: Array) -> Array:
        """z_2 = (p_2, q_2) at the element's end."""

    def to_form(self, body: Body, q: Array, p_hat: Array) -> Array:
        """The form's boundary momentum p from p_hat at coordinates q."""
        return p_hat

    def from_form(self, body: Body, q: Array, p: Array) -> Array:
        """p_hat from the form's boundary momentum p at coordinates q."""
        return p
