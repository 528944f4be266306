"""The rigid body as the weak forms see it (Borri 1990 §3).

Quantities are referred to a body point O' and ordered (angular; linear) as everywhere in mbjax,
so the paper's q = (x, r), p_hat = (l, h), f_hat = (b, m) are stored here as (r, x), (h, l),
(m, b). The generalized mass (eqs 3.8, 3.19) in space is

    M6(R) = [[J, S], [S^T, M I]],   J = R J_bar R^T,  S = M (R c_bar) x I,

with J_bar and c_bar the (constant, eq 3.9) second moment about O' and the centre of mass in the
body frame. A body about a fixed point (a top: O' is the suspension point) keeps only the
rotational coordinates; the paper's §7 "eliminating the translational degrees of freedom".
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src import lie
from mbjax._src.system.invariants import (ANGULAR, LINEAR, Invariants, along_gravity,
                                          energy_invariant, join)
from mbjax._src.rigid import RigidBody
from mbjax._src.spatial import check_inertia


class Body(eqx.Module):
    """A rigid body as the time finite elements see it (Borri 1990 §3), under uniform gravity.

    Quantities are referred to the body point O' and ordered (angular; linear). With
    fixed_point=True O' does not move and the coordinates are q = r_* (3 dof, a top about its
    suspension point); otherwise q = `(r_*, x_*)` (6 dof), O' anywhere in the body.

    Args:
        mass (float): mass [kg], positive.
        inertia (Array): second moment about O' in the body frame (J_bar of eq 3.9), shape (3, 3)
            [kg m^2]; symmetric, positive definite, satisfying the triangle inequality.
        com (Array): centre of mass relative to O' in the body frame (c_bar), shape (3,) [m].
        gravity (Array): acceleration of gravity in space, shape (3,) [m/s^2].
        fixed_point: whether O' is a fixed point (3 rotational dof) or free (6 dof).

    Raises:
        ValueError: mass is not positive, com is not a finite 3-vector, or inertia is not a
            valid inertia matrix.
    """

    mass: Array
    com: Array
    inertia: Array
    gravity: Array
    fixed_point: bool = eqx.field(static=True)

    def __init__(self, mass, inertia, *, com=(0.0, 0.0, 0.0), gravity=(0.0, 0.0, -9.81),
                 fixed_point: bool = False):
        check_inertia(inertia, "tfe.Body")
        if not isinstance(mass, jax.core.Tracer) and not float(mass) > 0:
            raise ValueError(f"mass must be positive, got {mass}")
        if not isinstance(com, jax.core.Tracer) and (
                np.shape(com) != (3,) or not np.all(np.isfinite(com))):
            raise ValueError(f"com must be a finite 3-vector, got {com!r}")
        if not isinstance(gravity, jax.core.Tracer) and (
                np.shape(gravity) != (3,) or not np.all(np.isfinite(gravity))):
            raise ValueError(f"gravity must be a finite 3-vector [m/s^2], got {gravity!r}")
        self.mass = jnp.asarray(mass, dtype=float)
        self.com = jnp.asarray(com, dtype=float)
        self.inertia = jnp.asarray(inertia, dtype=float)
        self.gravity = jnp.asarray(gravity, dtype=float)
        self.fixed_point = fixed_point

    @classmethod
    def from_rigid(cls, body: RigidBody) -> "Body":
        """The same body as a given `mbjax.rigid.RigidBody`.

        Args:
            body: the rigid body; O' becomes its fixed point or, for a free body, its
                reference point.

        Returns:
            The `Body` with the same mass, inertia, centre of mass, gravity and fixed point.
        """
        return cls(body.mass, body.inertia, com=body.com, gravity=body.gravity,
                   fixed_point=body.fixed_point)

    @property
    def nq(self) -> int:
        """Number of coordinates: 3 (rotation about a fixed point) or 6."""
        return 3 if self.fixed_point else 6

    def mass_matrix(self, R: Array) -> Array:
        """The generalized mass M6(R) in space (Borri 1990 eqs 3.8-3.9).

        M6(R) = [[J, S], [S^T, M I]] with J = R J_bar R^T and S = M (R c_bar) x I; only J
        about a fixed point.

        Args:
            R: rotation body to space, shape (3, 3).

        Returns:
            M6(R), shape (nq, nq).
        """
        J = R @ self.inertia @ R.T
        if self.fixed_point:
            return J
        S = self.mass * lie.hat(R @ self.com)
        return jnp.block([[J, S], [S.T, self.mass * jnp.eye(3)]])

    def momentum_to_velocity(self, R: Array, p_hat: Array) -> Array:
        """The velocity w_hat = M6^-1 p_hat of a momentum (Borri 1990 eq 3.19), in closed form.

        About a fixed point omega = R J_bar^-1 R^T h; for a free body, eliminating v from
        l = S^T omega + M v leaves J_c omega = h - S l / M with J_c = J - S S^T / M =
        R J_bar_c R^T, the inertia about the centre of mass (J_bar_c = J_bar + M c_bar x
        c_bar x), then v = (l - S^T omega) / M. Only 3x3 solves with constant matrices, so
        derivatives in R stay cheap (no factorization to differentiate).

        Args:
            R: rotation body to space, shape (3, 3).
            p_hat: spatial momentum (h, l) about O' (h only about a fixed point), shape (nq,).

        Returns:
            w_hat = (omega, v) (omega only about a fixed point), shape (nq,).
        """
        if self.fixed_point:
            return R @ jnp.linalg.solve(self.inertia, R.T @ p_hat)
        h, linear = p_hat[:3], p_hat[3:]
        c = R @ self.com
        c_hat = lie.hat(self.com)
        J_c = self.inertia + self.mass * c_hat @ c_hat
        omega = R @ jnp.linalg.solve(J_c, R.T @ (h - jnp.cross(c, linear)))
        return jnp.concatenate([omega, (linear - self.mass * jnp.cross(omega, c)) / self.mass])

    def applied(self, R: Array) -> Array:
        """The applied load f_hat = (m, b): gravity's moment about O' and its force (eq 3.16).

        Args:
            R: rotation body to space, shape (3, 3).

        Returns:
            f_hat, shape (nq,) (the moment m only about a fixed point) [N m, N].
        """
        b = self.mass * self.gravity
        m = jnp.cross(R @ self.com, b)
        return m if self.fixed_point else jnp.concatenate([m, b])

    def kinetic_energy(self, R: Array, p_hat: Array) -> Array:
        """The kinetic energy p_hat . M6^-1 p_hat / 2 (eq 3.25).

        Args:
            R: rotation body to space, shape (3, 3).
            p_hat: spatial momentum about O', shape (nq,).

        Returns:
            The kinetic energy [J], a scalar.
        """
        return 0.5 * p_hat @ self.momentum_to_velocity(R, p_hat)

    def energy(self, R: Array, x: Array, p_hat: Array) -> Array:
        """The total energy: kinetic (eq 3.25, p_hat . M6^-1 p_hat / 2) plus gravity's potential.

        Args:
            R: rotation body to space, shape (3, 3).
            x: position of O' in space, shape (3,) [m] (ignored about a fixed point).
            p_hat: spatial momentum about O', shape (nq,).

        Returns:
            The energy [J], a scalar.
        """
        centre = R @ self.com + (0.0 if self.fixed_point else x)
        return self.kinetic_energy(R, p_hat) - self.mass * self.gravity @ centre

    def invariants(self, t, R: Array, x: Array, p_hat: Array) -> Invariants:
        """What the motion conserves, for the drift check of `solve_tfe`.

        As `mbjax.rigid.RigidBody.invariants`: the energy, the angular momentum about the
        origin h + x x l along gravity (all of it without gravity) and, for a free body,
        l - M g t.

        Args:
            t: time [s], a scalar.
            R: rotation body to space, shape (3, 3).
            x: position of O' in space, shape (3,) [m].
            p_hat: spatial momentum about O', shape (nq,).

        Returns:
            The invariants with their scales (`Invariants` in `mbjax/_src/system/invariants.py`).
        """
        h = p_hat[:3]
        orbital = jnp.zeros(3, h.dtype) if self.fixed_point else jnp.cross(x, p_hat[3:])
        g = self.gravity
        H = along_gravity(h + orbital, g)
        parts = [energy_invariant(self.energy(R, x, p_hat), self.kinetic_energy(R, p_hat), False),
                 Invariants(H, jnp.full(3, jnp.linalg.norm(h) + jnp.linalg.norm(orbital)),
                            jnp.ones(3, bool), jnp.zeros(3, bool), ANGULAR)]
        if not self.fixed_point:
            parts.append(Invariants(p_hat[3:] - self.mass * g * t,
                                    jnp.full(3, jnp.linalg.norm(p_hat[3:])),
                                    jnp.ones(3, bool), jnp.zeros(3, bool), LINEAR))
        return join(*parts)
