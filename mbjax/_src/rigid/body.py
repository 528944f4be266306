"""A single rigid body: free, or turning about a fixed point, under gravity.

Configuration q = (rotation coordinates, x) and velocity u = (Omega, v), angular before linear as
everywhere in mbjax; Omega is the body-frame angular velocity (R_dot = R (Omega x I)) and v the
velocity of the centre of mass. A body about a fixed point (a heavy top, or a torque-free body
turning about its centre of mass) has no translational part.

Rotation coordinates are either unit quaternions (w, x, y, z), q_dot = q * (0, Omega) / 2
(`mbjax.lie.Quaternion()`), or rotation vectors r (`mbjax.lie.RotationVector()`) with r_dot = Gamma(r)^-T Omega (Borri 1990 eqs 2.8, A.21: omega = R Omega =
Gamma r_dot and Gamma^-1 R = Gamma^-T by eq A.24), rescaled to |r| <= pi after each step
(eq A.29).
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src import lie
from mbjax._src.control import AbstractControl
from mbjax._src.lie.coordinates import AbstractRotation, Quaternion
from mbjax._src.system.driven import AbstractDrivenSystem, about_origins, drive
from mbjax._src.system.invariants import (ANGULAR, LINEAR, Invariants, along_gravity,
                                          energy_invariant, join)
from mbjax._src.spatial import check_inertia


class RigidBody(AbstractDrivenSystem):
    """A rigid body of `mass` and body-frame `inertia` under uniform `gravity`, free or turning
    about a fixed point, as a system for `mbjax.simulate`.

    fixed_point=False: a free body; q = (rot, x), u = (Omega, v) (nv = 6), `inertia` is about
    the centre of mass. fixed_point=True: the body turns about a fixed point at the origin;
    q = rot, u = Omega (nv = 3), `inertia` is about that point and `com` is the centre of mass
    in the body frame. rot has 4 entries (quaternion) or 3 (rotation vector).

    Args:
        mass (float): mass [kg], a positive scalar.
        inertia (Array): inertia in the body frame [kg m^2], shape (3, 3), symmetric
            positive-definite: about the centre of mass (free body) or about the fixed point.
        com (Array): centre of mass in the body frame [m], shape (3,); must be 0 for a free body.
        gravity (Array): gravitational acceleration in the world frame [m/s^2], shape (3,).
        fixed_point: whether the body turns about a fixed point at the origin; static.
        rotation: the rotation coordinates, `mbjax.lie.Quaternion()` (the default) or
            `mbjax.lie.RotationVector()`; static.
        control (Callable | Array | None): a callable (t, q, u) -> generalized forces on u = (Omega,
            v): a body-frame torque [N m] (and, for a free body, a world-frame force [N]), or on the
            `actuation` coordinates only; an `mbjax.control` module; a constant array (a constant
            control); or None.
        external (Callable | None): a callable (t, q, u) -> a world-frame wrench (torque [N m];
            force [N]), shape (1, 6), acting at the body's origin (its centre of mass; the fixed
            point) or at `external_point`; or None.
        external_point (Array | None): where the external force acts, body-frame coordinates from
            that origin [m], shape (1, 3) or (3,); None: the origin.
        actuation (Array | None): the indices of the velocity coordinates the control drives (or a
            boolean mask of length nv), or an (nv, nu) actuation matrix S of rank nu (generalized
            force S u: thrusters, tendons); None: all of them. Stored as the matrix.

    Raises:
        TypeError: `rotation` is not a rotation-coordinates instance.
        ValueError: a non-positive mass, an invalid inertia, a free body with com != 0, or
            malformed control, external or actuation arguments.
    """

    mass: Array
    inertia: Array
    com: Array
    gravity: Array
    control: AbstractControl | None
    external: AbstractControl | None
    external_point: Array | None
    actuation: Array | None
    fixed_point: bool = eqx.field(static=True)
    rotation: AbstractRotation = eqx.field(static=True)

    def __init__(self, mass, inertia, *, com=(0.0, 0.0, 0.0), gravity=(0.0, 0.0, -9.81),
                 fixed_point: bool = False, rotation: AbstractRotation = Quaternion(), control=None,
                 external=None, external_point=None, actuation=None):
        if not isinstance(rotation, AbstractRotation):
            raise TypeError(f"rotation must be mbjax.lie.Quaternion() or mbjax.lie.RotationVector(), "
                            f"got {rotation!r}")
        check_inertia(inertia, "RigidBody")
        if not isinstance(mass, jax.core.Tracer) and not float(mass) > 0:
            raise ValueError(f"mass must be positive, got {mass}")
        if not fixed_point and not isinstance(com, jax.core.Tracer) and np.any(np.asarray(com)):
            raise ValueError("a free body is described about its centre of mass: com must be 0")
        self.mass = jnp.asarray(mass, dtype=float)
        self.inertia = jnp.asarray(inertia, dtype=float)
        self.com = jnp.asarray(com, dtype=float)
        self.gravity = jnp.asarray(gravity, dtype=float)
        self.fixed_point = fixed_point
        self.rotation = rotation
        self.control, self.external, self.external_point, self.actuation = drive(
            control, external, external_point, actuation, nv=3 if fixed_point else 6, n=1)

    # -- coordinates ---------------------------------------------------------------------------

    @property
    def n(self) -> int:
        """One body."""
        return 1

    @property
    def nv(self) -> int:
        """3 velocity coordinates about a fixed point, 6 for a free body."""
        return 3 if self.fixed_point else 6

    @property
    def n_rot(self) -> int:
        """The number of rotation coordinates at the start of q (4 or 3)."""
        return self.rotation.size

    def quaternions(self):
        """q[:4] with quaternion coordinates; none with a rotation vector."""
        return ((0, 4, "the body's quaternion"),) if self.n_rot == 4 else ()

    def rotation_matrix(self, q: Array) -> Array:
        """R, body to space.

        Args:
            q: configuration, shape (nq,).

        Returns:
            R, shape (3, 3).
        """
        rot = q[: self.n_rot]
        return self.rotation.to_matrix(rot)

    def position(self, q: Array) -> Array:
        """Centre of mass in space.

        Args:
            q: configuration, shape (nq,).

        Returns:
            The centre of mass in the world frame [m], shape (3,).
        """
        if self.fixed_point:
            return self.rotation_matrix(q) @ self.com
        return q[self.n_rot:]

    def initial_state(self, R0, Omega0, x0=(0.0, 0.0, 0.0), v0=(0.0, 0.0, 0.0)):
        """(q0, u0) from a rotation matrix, body angular velocity and (free body) COM motion.

        Args:
            R0: rotation, body to world, shape (3, 3).
            Omega0: body-frame angular velocity [rad/s], shape (3,).
            x0: centre-of-mass position [m], shape (3,); free body only.
            v0: centre-of-mass velocity [m/s], shape (3,); free body only.

        Returns:
            (q0, u0): q0 = rot (fixed point) or (rot, x0) (free body) in the body's rotation
                coordinates, and u0 = Omega0 or (Omega0, v0).
        """
        R0 = jnp.asarray(R0, dtype=float)
        rot = self.rotation.from_matrix(R0)
        Omega0 = jnp.asarray(Omega0, dtype=float)
        if self.fixed_point:
            return rot, Omega0
        return (jnp.concatenate([rot, jnp.asarray(x0, dtype=float)]),
                jnp.concatenate([Omega0, jnp.asarray(v0, dtype=float)]))

    # -- AbstractSystem ------------------------------------------------------------------------

    def kinematics(self, q, u):
        rot, Omega = q[: self.n_rot], u[:3]
        rot_dot = self.rotation.rate(rot, Omega)
        return rot_dot if self.fixed_point else jnp.concatenate([rot_dot, u[3:]])

    def acceleration(self, t, q, u):
        """Euler's equations J Omega_dot = tau - Omega x J Omega, solved by Cholesky.

        The COM falls freely (free body) or gravity gives tau = com x (m R^T g) (fixed point).
        The control and the external wrench add to tau (and to the force on the COM).

        Args:
            t: time [s], a scalar.
            q: configuration, shape (nq,).
            u: velocity (Omega; v), shape (nv,).

        Returns:
            u_dot = (Omega_dot; v_dot), shape (nv,).
        """
        Omega = u[:3]
        R = self.rotation_matrix(q)
        tau = jnp.cross(self.com, self.mass * (R.T @ self.gravity))
        force = jnp.zeros(3, u.dtype)
        f = self.external_wrenches(t, q, u)
        if f is not None:
            f = about_origins(f, R[None], self.external_point)[0]
            tau, force = tau + R.T @ f[:3], force + f[3:]
        applied = self.applied(t, q, u)
        tau = tau + applied[:3]
        chol = jax.scipy.linalg.cho_factor(self.inertia)
        Omega_dot = jax.scipy.linalg.cho_solve(chol, tau - jnp.cross(Omega, self.inertia @ Omega))
        if self.fixed_point:
            return Omega_dot
        return jnp.concatenate([Omega_dot, self.gravity + (force + applied[3:]) / self.mass])

    def retract(self, q0, xi):
        """R = R0 exp(xi_rot) (body-frame increment), x = x0 + xi_x."""
        rot = self.rotation.retract(q0[: self.n_rot], xi[:3])
        return rot if self.fixed_point else jnp.concatenate([rot, q0[self.n_rot:] + xi[3:]])

    def local_rate(self, q0, xi, u):
        """xi_dot = Gamma(xi)^-T Omega, the body-frame dexp^-1 (Borri 1990 eq 2.8)."""
        xi_dot = lie.gamma_inv(xi[:3]).T @ u[:3]
        return xi_dot if self.fixed_point else jnp.concatenate([xi_dot, u[3:]])

    def tangent(self, q, u):
        """(Omega; v): the chart's rate at xi = 0."""
        return u[:3] if self.fixed_point else u

    def difference(self, q0, q1):
        """(log(R0^T R1); x1 - x0)."""
        rot = self.rotation.difference(q0[: self.n_rot], q1[: self.n_rot])
        return rot if self.fixed_point else jnp.concatenate([rot, q1[self.n_rot:] - q0[self.n_rot:]])

    def project(self, q):
        rot = q[: self.n_rot]
        rot = self.rotation.normalize(rot)
        return rot if self.fixed_point else jnp.concatenate([rot, q[self.n_rot:]])

    # -- invariants ----------------------------------------------------------------------------

    def kinetic_energy(self, q, u):
        """T = Omega . J Omega / 2 (+ m |v|^2 / 2 for a free body) [J], a scalar."""
        Omega = u[:3]
        T = 0.5 * Omega @ self.inertia @ Omega
        return T if self.fixed_point else T + 0.5 * self.mass * u[3:] @ u[3:]

    def potential_energy(self, q):
        """V = -m g . x_com [J], a scalar."""
        return -self.mass * self.gravity @ self.position(q)

    def energy(self, q, u):
        """T + V [J], a scalar; the work of the control and external load is not included.

        Args:
            q: configuration, shape (nq,).
            u: velocity, shape (nv,).
        """
        return self.kinetic_energy(q, u) + self.potential_energy(q)

    def angular_momentum(self, q, u):
        """Angular momentum about the world origin (the fixed point, if any), world frame.

        Args:
            q: configuration, shape (nq,).
            u: velocity, shape (nv,).

        Returns:
            H [kg m^2/s], shape (3,).
        """
        h = self.rotation_matrix(q) @ (self.inertia @ u[:3])
        return h if self.fixed_point else h + self.mass * jnp.cross(q[self.n_rot:], u[3:])

    def invariants(self, t, q, u):
        """Without control or external load: the energy (against the kinetic energy), the
        angular momentum about the origin along gravity (all of it without gravity: gravity's
        moment is normal to it) and, for a free body, the momentum less the weight's impulse,
        m (v - g t) (against the momenta's magnitudes). None otherwise."""
        if not self.passive:
            return None
        spin = self.rotation_matrix(q) @ (self.inertia @ u[:3])
        orbital = (jnp.zeros(3, u.dtype) if self.fixed_point
                   else self.mass * jnp.cross(q[self.n_rot:], u[3:]))
        g = self.gravity
        H = along_gravity(spin + orbital, g)
        parts = [energy_invariant(self.energy(q, u), self.kinetic_energy(q, u), False),
                 Invariants(H, jnp.full(3, jnp.linalg.norm(spin) + jnp.linalg.norm(orbital)),
                            jnp.ones(3, bool), jnp.zeros(3, bool), ANGULAR)]
        if not self.fixed_point:
            P = self.mass * (u[3:] - g * t)
            parts.append(Invariants(P, jnp.full(3, self.mass * jnp.linalg.norm(u[3:])),
                                    jnp.ones(3, bool), jnp.zeros(3, bool), LINEAR))
        return join(*parts)
