"""What `simulate` and the closed loops of `mbjax.loops` need from an open tree, rigid or flexible
(`AbstractTreeSystem`, whose docstring describes it)."""

import abc

import equinox as eqx
import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.control import Constant
from mbjax._src.system.driven import AbstractDrivenSystem, about_origins
from mbjax._src.system.invariants import energy_invariant


class AbstractTreeSystem(AbstractDrivenSystem):
    """An open tree of bodies as a system for `simulate` and `mbjax.loops.ClosedSystem`.

    Its `model` (a `mbjax.Model` or a `mbjax.flex.FlexibleModel`) gives the coordinates; the
    state is (q, v), q of shape (nq,) and v of shape (nv,). Final subclasses
    (`mbjax.rigid.TreeSystem`, `mbjax.flex.FlexibleSystem`) take the model, the control, the
    external load and the forward-dynamics method in their constructors; see The interface,
    below, for what they must provide.

    The interface:
        What `simulate` and the closed loops of `mbjax.loops` need from an open tree, rigid or
        flexible.

        An `AbstractTreeSystem` integrates (q, v): configuration coordinates q (nq) and velocity
        coordinates v (nv), with q_dot = q_dot(q, v) and a chart (`retract`, `local_rate`) about any
        q for quaternion joints. It gives the poses of its frames (bodies, then markers), its
        energy, its mass matrix M(q) = d^2 T / dv^2, and the O(n) response of the recursion to m
        unit generalized loads at once (Anderson 1993 eqs 101-107: one triangularization, m + 1
        force passes): what the O(n + m^3) loop route needs. Trees whose equations of motion are
        M(q) v_dot + bias(t, q, v) = 0 with that symmetric M (`symmetric_dynamics`; rigid trees, not
        flexible ones, whose geometric stiffening adds acceleration-dependent loads) also serve the
        dense loop routes.

        Applied forces live on the tree: `control` (t, q, v) -> generalized forces on the
        `actuation` coordinates, `external` (t, q, v) -> one world-frame wrench (torque; force) per
        body at its origin or at `external_point`. A closed loop wrapped around the tree inherits
        them.

        Final implementations: `mbjax.rigid.TreeSystem`, `mbjax.flex.FlexibleSystem`.
    """

    model: eqx.AbstractVar[object]
    symmetric_dynamics: eqx.AbstractClassVar[bool]

    # -- coordinates ----------------------------------------------------------------------------

    @property
    def n(self) -> int:
        """Number of bodies."""
        return self.model.n

    @property
    def nq(self) -> int:
        """Number of configuration coordinates."""
        return self.model.nq

    @property
    def nv(self) -> int:
        """Number of velocity coordinates."""
        return self.model.nv

    @property
    def n_frames(self) -> int:
        """Frames `frames` returns: the bodies, then any markers."""
        return self.model.n_frames

    def neutral(self) -> Array:
        """The reference configuration (zero angles, identity quaternions, undeformed).

        Returns:
            q, shape (nq,).
        """
        return self.model.neutral()

    def q_dot(self, q: Array, v: Array) -> Array:
        """dq/dt for velocity v.

        Args:
            q: configuration, shape (nq,).
            v: generalized velocity, shape (nv,).

        Returns:
            dq/dt, shape (nq,).
        """
        return self.model.q_dot(q, v)

    def retract(self, q0: Array, xi: Array) -> Array:
        return self.model.retract(q0, xi)

    def local_rate(self, q0: Array, xi: Array, u: Array) -> Array:
        return self.model.local_rate(q0, xi, u)

    def tangent(self, q: Array, u: Array) -> Array:
        return u

    def difference(self, q0: Array, q1: Array) -> Array:
        return self.model.difference(q0, q1, wrap=False)

    def normalize(self, q: Array) -> Array:
        """q with every quaternion scaled to unit length.

        Args:
            q: configuration, shape (nq,).

        Returns:
            The normalized configuration, shape (nq,).
        """
        return self.model.normalize(q)

    # -- kinematics, energy, dynamics -------------------------------------------------------------

    @abc.abstractmethod
    def frames(self, q: Array) -> tuple[Array, Array]:
        """World poses of every frame: the bodies, then any markers.

        Args:
            q: configuration, shape (nq,).

        Returns:
            (R, p): rotations (body to world), shape (n_frames, 3, 3), and origins [m], shape
                (n_frames, 3).
        """

    def body_motion(self, q: Array, v: Array, v_dot: Array | None = None):
        """The frames' motion written out, for closures differentiated without nested autodiff
        (`mbjax/_src/loops/constraints.py`): None where the tree does not offer it (closures then go
        through `frames`).

        Args:
            q: configuration, shape (nq,).
            v: generalized velocity, shape (nv,).
            v_dot: accelerations, shape (nv,), or None.

        Returns:
            (R, p, V, A) or None: the frames' poses as `frames`, their spatial velocities and
                accelerations (angular; linear) in world components at the world origin, shape
                (n_frames, 6) (A: None without v_dot; no gravity in it).
        """
        return None

    def body_forces(self, q: Array, wrenches: Array) -> Array:
        """The generalized force of wrenches on the frames, (torque about the world origin;
        force) in world components, shape (n_frames, 6): J^T w summed over the frames, where
        `body_motion` is offered.

        Args:
            q: configuration, shape (nq,).
            wrenches: shape (n_frames, 6).

        Returns:
            The generalized force, shape (nv,).
        """
        raise TypeError(f"{type(self).__name__} offers no body_motion")

    @abc.abstractmethod
    def energy(self, q: Array, v: Array) -> Array:
        """Kinetic plus gravitational (plus strain) energy.

        The work of the applied forces is not included.

        Args:
            q: configuration, shape (nq,).
            v: generalized velocity, shape (nv,).

        Returns:
            The energy [J], a scalar.
        """

    @abc.abstractmethod
    def kinetic_energy(self, q: Array, v: Array) -> Array:
        """The kinetic energy.

        Args:
            q: configuration, shape (nq,).
            v: generalized velocity, shape (nv,).

        Returns:
            T [J], a scalar.
        """

    @abc.abstractmethod
    def dissipative(self) -> Array:
        """Whether the tree has damping (joint or modal), so that its energy can only fall.

        Returns:
            A boolean scalar.
        """

    def invariants(self, t, q, u):
        """The energy of a passive tree (its drift relative to the kinetic energy); None otherwise."""
        if not self.passive:
            return None
        return energy_invariant(self.energy(q, u), self.kinetic_energy(q, u), self.dissipative())

    def holding_control(self, q: Array, nu: int, closures: Array | None = None) -> Array:
        """The least-norm (u, f) of B u + A^T f = g(q), its u: the actuation B, the Jacobian A
        (m, nv) of the closures that help hold q (a stance's feet; none by default), f their
        multipliers and g the generalized gravity force (Crocoddyl's `quasiStatic`,
        pseudo-inverse and all).

        Args:
            q: configuration, shape (nq,).
            nu: the number of controls.
            closures: A, shape (m, nv), or None.

        Returns:
            u, shape (nu,).
        """
        rest = jnp.zeros(self.nv, q.dtype)
        A = jnp.zeros((0, self.nv), q.dtype) if closures is None else closures
        M = self.mass_matrix(q)

        def force(u):              # the generalized force at rest under u: B u - g(q)
            return M @ self.with_control(Constant(u)).hold(0.0, q, rest).acceleration(0.0, q, rest)

        zero = jnp.zeros(nu, q.dtype)
        minus_g, B = force(zero), jax.jacfwd(force)(zero)
        return (jnp.linalg.pinv(jnp.concatenate([B, A.T], axis=1)) @ -minus_g)[:nu]

    @abc.abstractmethod
    def mass_matrix(self, q: Array) -> Array:
        """M(q) = d^2 T / dv^2.

        Args:
            q: configuration, shape (nq,).

        Returns:
            M, symmetric positive-definite, shape (nv, nv).
        """

    @abc.abstractmethod
    def responses(self, t: Array, q: Array, v: Array, loads: Array) -> tuple[Array, Array]:
        """The accelerations under every force, and those each of m unit loads alone produces.

        The second output is the unit constraint-load responses of Anderson 1993 eqs 101-107
        (no gravity, velocity or applied force), from the same triangularization as the first.

        Args:
            t: time [s], a scalar.
            q: configuration, shape (nq,).
            v: generalized velocity, shape (nv,).
            loads: generalized loads, one per row, shape (m, nv).

        Returns:
            (v_dot, responses): the accelerations under gravity, velocity terms, elasticity,
                the control and the external wrenches, shape (nv,); and the accelerations of each
                row of `loads`, shape (m, nv).
        """

    def bias(self, t: Array, q: Array, v: Array) -> Array:
        """The equations of motion as M(q) v_dot + bias(t, q, v) = 0.

        Only for trees with `symmetric_dynamics`: velocity terms and gravity less the applied
        forces.

        Args:
            t: time [s], a scalar.
            q: configuration, shape (nq,).
            v: generalized velocity, shape (nv,).

        Returns:
            bias, shape (nv,).

        Raises:
            TypeError: the tree's equations have no symmetric mass matrix (a flexible tree).
        """
        raise TypeError(f"{type(self).__name__} has no equations of the form M(q) v_dot + bias = 0 "
                        "with a symmetric M (symmetric_dynamics is False)")

    def inverse(self, t: Array, q: Array, v: Array, v_dot: Array) -> Array:
        """M(q) v_dot + bias(t, q, v): the generalized force the accelerations v_dot leave
        unbalanced, zero on the tree's own motion (trees with `symmetric_dynamics`).

        Args:
            t: time [s], a scalar.
            q: configuration, shape (nq,).
            v: generalized velocity, shape (nv,).
            v_dot: accelerations, shape (nv,).

        Returns:
            The force, shape (nv,).
        """
        return self.mass_matrix(q) @ v_dot + self.bias(t, q, v)

    # -- applied forces -------------------------------------------------------------------------

    def wrenches(self, t: Array, q: Array, v: Array) -> Array | None:
        """The external wrenches moved to the bodies' origins.

        Args:
            t: time [s], a scalar.
            q: configuration, shape (nq,).
            v: generalized velocity, shape (nv,).

        Returns:
            World-frame wrenches (torque about each body's origin [N m]; force [N]), shape
                (n, 6); or None without an external load.
        """
        f = self.external_wrenches(t, q, v)
        if f is None or self.external_point is None:
            return f
        return about_origins(f, self.frames(q)[0][:self.n], self.external_point)

    # -- AbstractSystem ---------------------------------------------------------------------------

    def kinematics(self, q, u):
        return self.q_dot(q, u)

    def acceleration(self, t, q, u):
        return self.responses(t, q, u, jnp.zeros((0, self.nv), u.dtype))[0]

    def project(self, q):
        return self.normalize(q)

    def state_sizes(self):
        return self.nq, self.nv

