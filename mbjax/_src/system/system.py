"""What a time integrator needs from a mechanical system.

A system has configuration coordinates q and velocities u with

    q_dot = kinematics(q, u),        u_dot = acceleration(t, q, u).

q may live on a manifold (a quaternion, a rotation vector), so a system also gives a local chart
about any configuration q0: q = retract(q0, xi) with xi in R^dim(u), xi = 0 at q0, and the rate
xi_dot = local_rate(q0, xi, u). For rotations this is Borri 1990's incremental rotation vector about a
reference configuration (§2): R = R0 exp(xi), xi_dot = Gamma(xi)^-T Omega. Euclidean systems keep the
defaults (retract(q0, xi) = q0 + xi).
"""

import abc

import equinox as eqx
import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.system.invariants import Invariants


class AbstractSystem(eqx.Module):
    """A first-order mechanical system in (q, u); see the module docstring."""

    @abc.abstractmethod
    def kinematics(self, q: Array, u: Array) -> Array:
        """q_dot as a function of the configuration and the velocity."""

    @abc.abstractmethod
    def acceleration(self, t: Array, q: Array, u: Array) -> Array:
        """u_dot, the equations of motion solved for the accelerations."""

    def retract(self, q0: Array, xi: Array) -> Array:
        """The configuration at chart point xi about q0."""
        return q0 + xi

    def local_rate(self, q0: Array, xi: Array, u: Array) -> Array:
        """xi_dot at chart point xi about q0 for velocity u."""
        return self.kinematics(self.retract(q0, xi), u)

    def project(self, q: Array) -> Array:
        """Map coordinates back to their canonical form (unit quaternion, principal rotation vector)."""
        return q

    def hold(self, t: Array, q: Array, u: Array) -> "AbstractSystem":
        """The system as it acts over one step of `simulate` that starts at (t, q, u): sampled
        controls (`mbjax.control.ZeroOrderHold`, `SampleAndHold`) frozen at their values there.
        The system itself here."""
        return self

    def constrain(self, t: Array, q: Array, u: Array) -> tuple[Array, Array]:
        """After each step of `simulate`: put (q, u) back on the system's constraints (a closed
        loop's projection, `mbjax.loops`). The identity here."""
        return q, u

    def check(self, t: Array, q: Array, u: Array) -> Array:
        """`Status` flags for a state `simulate` saves (a violated or redundant constraint,
        `mbjax.loops`); 0 here."""
        return jnp.array(0, jnp.int32)

    def invariants(self, t: Array, q: Array, u: Array) -> Invariants | None:
        """The quantities the exact motion conserves at a state (`mbjax._src.system.invariants`:
        the energy of a passive system, a free tree's momentum), whose drift `simulate(...,
        rtol=)` holds to rtol; None here: none known."""
        return None

    def state_sizes(self) -> tuple[int | None, int | None]:
        """The lengths of q and u a state of this system must have, None where the system does
        not say (`simulate` and `mbjax.trajopt.Problem` check states against them)."""
        return None, None

    @property
    def n_controls(self) -> int:
        """The number of forces its control returns (its actuated coordinates)."""
        raise TypeError(f"{type(self).__name__} has no control")

    def with_control(self, control) -> "AbstractSystem":
        """The system driven by `control` instead of its own (what trajectory optimisation
        varies); systems without a control raise TypeError."""
        raise TypeError(f"{type(self).__name__} has no control to optimise: a problem needs a "
                        "system with a `control` (TreeSystem, FlexibleSystem, WristSystem, "
                        "RigidBody, a ClosedSystem of a tree, ...)")

    @eqx.filter_jit
    def relative_energy_error(self, qs: Array, us: Array) -> Array:
        """(E(t) - E(0)) / |E(0)| along a saved trajectory, for systems with an `energy(q, u)`
        (one compiled program, not one per array operation when called outside `jit`)."""
        E = jax.vmap(self.energy)(qs, us)
        return (E - E[0]) / jnp.abs(E[0])
