"""What `simulate` and the closed loops of `mbjax.loops` need from an open tree, rigid or flexible.

An `AbstractTreeSystem` integrates (q, v): configuration coordinates q (nq) and velocity
coordinates v (nv), with q_dot = q_dot(q, v) and a chart (`retract`, `local_rate`) about any q
for quaternion joints. It gives the poses of its frames (bodies, then markers), its energy, its
mass matrix M(q) = d^2 T / dv^2, and the O(n) response of the recursion to m unit generalized
loads at once (Anderson 1993 eqs 101-107: one triangularization, m + 1 force passes): what the
O(n + m^3) loop route needs. Trees whose equations of motion are M(q) v_dot + bias(t, q, v) = 0
with that symmetric M (`symmetric_dynamics`; rigid trees, not flexible ones, whose geometric
stiffening adds acceleration-dependent loads) also serve the dense loop routes.

Applied forces live on the tree: `control` (t, q, v) -> generalized forces on the `actuation`
coordinates, `external` (t, q, v) -> one world-frame wrench (torque; force) per body at its
origin or at `external_point`. A closed loop wrapped around the tree inherits them.

Final implementations: `mbjax.rigid.TreeSystem`, `mbjax.flex.FlexibleSystem`.
"""

import abc

import equinox as eqx
import jax.numpy as jnp
from jax import Array

from mbjax._src.control import AbstractControl
from mbjax._src.system.driven import about_origins, body_wrenches, generalized_control, hold
from mbjax._src.system.invariants import energy_invariant
from mbjax._src.system.system import AbstractSystem


class AbstractTreeSystem(AbstractSystem):
    """An open tree of bodies as a system for `simulate` and `mbjax.loops.ClosedSystem`. Its
    `model` (a `mbjax.Model` or a `mbjax.flex.FlexibleModel`) gives the coordinates."""

    model: eqx.AbstractVar[object]
    control: eqx.AbstractVar[AbstractControl | None]
    external: eqx.AbstractVar[AbstractControl | None]
    external_point: eqx.AbstractVar[Array | None]
    actuation: eqx.AbstractVar[tuple[int, ...] | None]
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
        """The reference configuration (zero angles, identity quaternions, undeformed)."""
        return self.model.neutral()

    def q_dot(self, q: Array, v: Array) -> Array:
        """dq/dt for velocity v."""
        return self.model.q_dot(q, v)

    def retract(self, q0: Array, xi: Array) -> Array:
        return self.model.retract(q0, xi)

    def local_rate(self, q0: Array, xi: Array, u: Array) -> Array:
        return self.model.local_rate(q0, xi, u)

    def normalize(self, q: Array) -> Array:
        """q with every quaternion scaled to unit length."""
        return self.model.normalize(q)

    # -- kinematics, energy, dynamics -------------------------------------------------------------

    @abc.abstractmethod
    def frames(self, q: Array) -> tuple[Array, Array]:
        """World rotation (n_frames, 3, 3) and origin (n_frames, 3) of every frame."""

    @abc.abstractmethod
    def energy(self, q: Array, v: Array) -> Array:
        """Kinetic plus gravitational (plus strain) energy; the work of the applied forces is
        not included."""

    @abc.abstractmethod
    def kinetic_energy(self, q: Array, v: Array) -> Array:
        """The kinetic energy."""

    @abc.abstractmethod
    def dissipative(self) -> Array:
        """True where the tree has damping (joint or modal), so that its energy can only fall."""

    @property
    def passive(self) -> bool:
        """No control and no external load: the energy is conserved (or falls, with damping)."""
        return self.control is None and self.external is None

    def invariants(self, t, q, u):
        """The energy of a passive tree (measured against its kinetic energy); None otherwise."""
        if not self.passive:
            return None
        return energy_invariant(self.energy(q, u), self.kinetic_energy(q, u), self.dissipative())

    @abc.abstractmethod
    def mass_matrix(self, q: Array) -> Array:
        """M(q) = d^2 T / dv^2, symmetric positive-definite (nv, nv)."""

    @abc.abstractmethod
    def responses(self, t: Array, q: Array, v: Array, loads: Array) -> tuple[Array, Array]:
        """(v_dot (nv,), responses (m, nv)): the accelerations under every force (gravity,
        velocity terms, elasticity, control, external wrenches), and those each row of `loads`
        (m, nv) alone produces (no gravity, velocity or applied force): the unit constraint-load
        responses of Anderson 1993 eqs 101-107, from one triangularization."""

    def bias(self, t: Array, q: Array, v: Array) -> Array:
        """The equations of motion as M(q) v_dot + bias(t, q, v) = 0 (`symmetric_dynamics`
        trees only): velocity terms and gravity less the applied forces."""
        raise TypeError(f"{type(self).__name__} has no equations of the form M(q) v_dot + bias = 0 "
                        "with a symmetric M (symmetric_dynamics is False)")

    # -- applied forces -------------------------------------------------------------------------

    def applied(self, t: Array, q: Array, v: Array) -> Array:
        """The control's generalized forces on all nv coordinates."""
        return generalized_control(self.control, self.actuation, self.nv, t, q, v)

    def wrenches(self, t: Array, q: Array, v: Array) -> Array | None:
        """The external wrenches (n, 6), world frame, torque about each body's origin; or None."""
        f = body_wrenches(self.external, self.n, t, q, v)
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

    def hold(self, t, q, u):
        return hold(self, t, q, u)


def state_sizes(system: AbstractSystem) -> tuple[int | None, int | None]:
    """The lengths (of q, of u) a system's state must have, None where it is the system's own
    affair: (nq, nv) for a tree system; (nq, None) for a closed loop of one (its method may add
    to u, as the epsilon-dynamics add the constraint loads); (None, None) for the others (a
    batch, a momentum form)."""
    if isinstance(system, AbstractTreeSystem):
        return system.nq, system.nv
    tree = getattr(system, "tree", None)
    if isinstance(tree, AbstractTreeSystem):
        return tree.nq, None
    return None, None
