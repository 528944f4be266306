"""Reference configurations and incremental coordinates (Borri 1990 §2).

Over an element starting at t_1 the motion is written about a prescribed reference (x_o(t),
R_o(t)) as x = x_o + x_* and R = R_* R_o with R_* = exp(r_* x I); the unknowns are the incremental
coordinates q = (r_*, x_*), zero at t_1 when the reference starts from the initial state.
What each element is written about is a strategy (`AbstractReference`) `solve_tfe` takes. Two
references (§2) are built afresh for every element from its initial state: `ConstantReference()`
(held at the initial configuration) and `ConstantVelocityReference()` (moving with the initial
linear and angular velocity, R_o = exp((t - t_1) omega_o x I) R_1). A march can instead follow one
prescribed `Reference` throughout, the steady rotation of eq 7.1 say; the incremental coordinates
then carry over from element to element, as in the linearized analysis of §6 (eq 6.7).
"""

import abc

import equinox as eqx
import jax.numpy as jnp
from jax import Array

from mbjax._src import lie
from mbjax._src.tfe.body import Body


class AbstractReference(eqx.Module):
    """What each element of `solve_tfe` is written about (Borri 1990 §2), passed as `reference=`:
    `ConstantReference()` or `ConstantVelocityReference()`, built afresh from each element's
    initial state, or one prescribed `Reference` motion followed by the whole march.

    A subclass implements `start`.
    """

    @abc.abstractmethod
    def start(self, body: Body, t, R1: Array, x1: Array, p_hat1: Array) -> tuple["Reference", Array]:
        """The reference of the element starting at time t in the state (R1, x1, p_hat1), and
        that state's incremental coordinates about it.

        Args:
            body: the body.
            t: the element's start [s], a scalar.
            R1: initial rotation, shape (3, 3).
            x1: initial position of O', shape (3,) [m].
            p_hat1: initial spatial momentum about O', shape (nq,).

        Returns:
            ref: the element's `Reference`, its time counted from t.
            q1: the incremental coordinates (r_*, x_*) of (R1, x1) about it, shape (nq,).
        """


def _afresh(body: Body, R1: Array, x1: Array, p_hat1: Array, moving: bool) -> tuple["Reference", Array]:
    """A reference from (R1, x1), held there or moving with the velocities of p_hat1 (eqs
    2.2-2.3), and q1 = 0."""
    w1 = body.momentum_to_velocity(R1, p_hat1)
    if not moving:
        w1 = jnp.zeros_like(w1)
    v = jnp.zeros(3, w1.dtype) if body.fixed_point else w1[3:]
    return Reference(R1, x1, w1[:3], v), jnp.zeros(body.nq, p_hat1.dtype)


class ConstantReference(AbstractReference):
    """Each element about a reference held at its initial configuration ("simply held constant",
    Borri 1990 §2): x_o = x_1, R_o = R_1."""

    def start(self, body: Body, t, R1: Array, x1: Array, p_hat1: Array) -> tuple["Reference", Array]:
        """The reference (R1, x1) at rest, and q1 = 0 (as `AbstractReference.start`)."""
        return _afresh(body, R1, x1, p_hat1, moving=False)


class ConstantVelocityReference(AbstractReference):
    """Each element about a reference moving with its initial velocities (Borri 1990 eqs
    2.2-2.3): x_o = x_1 + (t - t_1) v_1, R_o = exp((t - t_1) omega_1 x I) R_1; `solve_tfe`'s
    default."""

    def start(self, body: Body, t, R1: Array, x1: Array, p_hat1: Array) -> tuple["Reference", Array]:
        """The reference from (R1, x1) at the velocities of p_hat1, and q1 = 0 (as
        `AbstractReference.start`)."""
        return _afresh(body, R1, x1, p_hat1, moving=True)


class Reference(AbstractReference):
    """A reference motion x_o(t) = x_1 + t v_o, R_o(t) = exp(t omega_o x I) R_1 (Borri 1990 §2).

    t counts from the reference's start; the reference velocities v_o, omega_o (eqs 2.2-2.3)
    are constant in space. Given to `solve_tfe` as `reference=`, it is followed by the whole
    march (the steady rotation of eq 7.1, say).

    Args:
        R1: rotation at t = 0, body to space, shape (3, 3).
        x1: position of O' at t = 0, shape (3,) [m].
        omega: spatial angular velocity omega_o, shape (3,) [rad/s].
        v: velocity v_o of O', shape (3,) [m/s].
    """

    R1: Array
    x1: Array
    omega: Array
    v: Array

    def at(self, t) -> tuple[Array, Array]:
        """The reference configuration at time t.

        Args:
            t: time from the reference's start [s], a scalar.

        Returns:
            R_o: rotation, shape (3, 3).
            x_o: position of O', shape (3,) [m].
        """
        return lie.exp(t * self.omega) @ self.R1, self.x1 + t * self.v

    def shifted(self, t) -> "Reference":
        """The same motion, its time counted from t.

        Args:
            t: the new origin of time [s], a scalar.

        Returns:
            The `Reference` starting at (R_o(t), x_o(t)) with the same velocities.
        """
        R, x = self.at(t)
        return Reference(R, x, self.omega, self.v)

    def start(self, body: Body, t, R1: Array, x1: Array, p_hat1: Array) -> tuple["Reference", Array]:
        """This motion from time t, and the increments of (R1, x1) about it (they carry over from
        the previous element).

        Args:
            body: the body.
            t: the element's start [s], a scalar.
            R1: initial rotation, shape (3, 3).
            x1: initial position of O', shape (3,) [m].
            p_hat1: initial spatial momentum about O', shape (nq,) (unused).

        Returns:
            ref: the motion shifted to t (`shifted`).
            q1: the incremental coordinates of (R1, x1) about it, shape (nq,).
        """
        ref = self.shifted(t)
        return ref, increment(body, ref, R1, x1)


def check_reference(reference) -> None:
    """Refuse what is not a reference strategy (the strings "constant" and "constant_velocity"
    of old).

    Args:
        reference: what was passed as `reference=`.

    Raises:
        TypeError: reference is not an `AbstractReference` instance.
    """
    if not isinstance(reference, AbstractReference):
        hint = (" (an instance: ConstantReference(), not ConstantReference)"
                if isinstance(reference, type) else "")
        raise TypeError(f"reference must be a reference strategy, ConstantReference(), "
                        f"ConstantVelocityReference() or a tfe.Reference motion{hint}, got "
                        f"{reference!r}")


def configuration(body: Body, ref: Reference, q: Array, t) -> tuple[Array, Array]:
    """Absolute (R, x) from the incremental coordinates q at element time t."""
    R_o, x_o = ref.at(t)
    R = lie.exp(q[:3]) @ R_o
    return R, (x_o if body.fixed_point else x_o + q[3:])


def increment(body: Body, ref: Reference, R: Array, x: Array) -> Array:
    """The incremental coordinates q = (r_*, x_*) of (R, x) at the reference's start, the inverse
    of `configuration` at t = 0 (principal rotation vector, |r_*| <= pi)."""
    r = lie.log(R @ ref.R1.T, check=False)
    return r if body.fixed_point else jnp.concatenate([r, x - ref.x1])


def X_matrix(body: Body, q: Array) -> Array:
    """X = diag(Gamma(r_*), I) of eq 3.18 (angular block first)."""
    G = lie.gamma(q[:3])
    return G if body.fixed_point else jnp.block([[G, jnp.zeros((3, 3))], [jnp.zeros((3, 3)), jnp.eye(3)]])


def X_inverse(body: Body, q: Array, w: Array) -> Array:
    """X^-1 w = (Gamma^-1(r_*) omega, v) (eq 3.18)."""
    omega = lie.gamma_inv(q[:3]) @ w[:3]
    return omega if body.fixed_point else jnp.concatenate([omega, w[3:]])


def X_inverse_transpose(body: Body, q: Array, p: Array) -> Array:
    """X^-T p = (Gamma^-T(r_*) p_r, p_x): p_hat from p = X^T p_hat (eq 3.17)."""
    h = lie.gamma_inv(q[:3]).T @ p[:3]
    return h if body.fixed_point else jnp.concatenate([h, p[3:]])


def w_n(body: Body, ref: Reference, q: Array) -> Array:
    """w_n = (R_* omega_o, v_o) of eq 3.21: the reference's velocity carried by the increment."""
    omega = lie.exp(q[:3]) @ ref.omega
    return omega if body.fixed_point else jnp.concatenate([omega, ref.v])


def velocity(body: Body, ref: Reference, q: Array, q_dot: Array) -> Array:
    """w = X q_dot + w_n (eq 3.20): omega = Gamma(r_*) r_*_dot + R_* omega_o (eq 2.7)."""
    return X_matrix(body, q) @ q_dot + w_n(body, ref, q)
