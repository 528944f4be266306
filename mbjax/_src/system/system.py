"""What a time integrator needs from a mechanical system (`AbstractSystem`, whose docstring
describes it)."""

import abc

import equinox as eqx
import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.system.invariants import Invariants


class AbstractSystem(eqx.Module):
    """A first-order mechanical system in (q, u): what `mbjax.simulate` and every integrator
    integrate.

    Subclasses implement `kinematics` (q_dot) and `acceleration` (u_dot); a system whose
    configuration lives on a manifold also overrides the chart (`retract`, `local_rate`) and
    `project` (see The interface, below). The other methods have defaults that suit an
    unconstrained, uncontrolled system. The abstract class takes no constructor arguments.

    The interface:
        What a time integrator needs from a mechanical system.

        A system has configuration coordinates q and velocities u (Kane's generalized speeds, as
        the papers write them; what users pass and read names them v, `simulate`'s v0 and
        `Solution.vs`, since u names controls in `mbjax.trajopt`) with

        ```text
        q_dot = kinematics(q, u),        u_dot = acceleration(t, q, u).
        ```

        q may live on a manifold (a quaternion, a rotation vector), so a system also gives a local
        chart about any configuration q0: q = retract(q0, xi) with xi in R^dim(u), xi = 0 at q0, and
        the rate xi_dot = local_rate(q0, xi, u). For rotations this is Borri 1990's incremental
        rotation vector about a reference configuration (§2): R = R0 exp(xi), xi_dot = Gamma(xi)^-T
        Omega. Euclidean systems keep the defaults (retract(q0, xi) = q0 + xi). `difference` is the
        chart's inverse and `tangent` its rate at xi = 0, along which the Euler methods step.
    """

    @abc.abstractmethod
    def kinematics(self, q: Array, u: Array) -> Array:
        """q_dot as a function of the configuration and the velocity.

        Args:
            q: configuration, shape (nq,).
            u: velocity state, shape (nu,).

        Returns:
            dq/dt, shape (nq,).
        """

    @abc.abstractmethod
    def acceleration(self, t: Array, q: Array, u: Array) -> Array:
        """u_dot: the equations of motion solved for the accelerations.

        Args:
            t: time [s], a scalar.
            q: configuration, shape (nq,).
            u: velocity state, shape (nu,).

        Returns:
            du/dt, shape (nu,).
        """

    def retract(self, q0: Array, xi: Array) -> Array:
        """The configuration at chart point xi about q0 (q0 + xi by default).

        Args:
            q0: the chart's base configuration, shape (nq,).
            xi: chart coordinates, shape (nu,); xi = 0 is q0.

        Returns:
            The configuration, shape (nq,).
        """
        return q0 + xi

    def local_rate(self, q0: Array, xi: Array, u: Array) -> Array:
        """xi_dot at chart point xi about q0 for velocity u.

        Args:
            q0: the chart's base configuration, shape (nq,).
            xi: chart coordinates, shape (nu,).
            u: velocity state, shape (nu,).

        Returns:
            dxi/dt, shape (nu,) (for rotations, Borri 1990's Gamma(xi)^-T Omega).
        """
        return self.kinematics(self.retract(q0, xi), u)

    def tangent(self, q: Array, u: Array) -> Array:
        """The configuration's rate in the chart about q itself: local_rate(q, 0, u).

        What the Euler methods step along: q1 = retract(q, dt tangent(q, u)), on the group for
        quaternion joints (Crocoddyl's and Pinocchio's `integrate`).

        Args:
            q: configuration, shape (nq,).
            u: velocity state, shape (nu,).

        Returns:
            xi_dot at xi = 0, shape of the chart (the velocity's for a tree); kinematics(q, u)
                by default.
        """
        return self.kinematics(q, u)

    def difference(self, q0: Array, q1: Array) -> Array:
        """The chart point xi about q0 at which retract(q0, xi) = q1 (q1 - q0 by default).

        What trajectory optimisation measures deviations with: for a tree, Pinocchio's
        `difference` on quaternions, and q1 - q0 on angles, which count turns (the exact inverse
        of `retract`, continuous along a path: `Model.difference(..., wrap=False)`).

        Args:
            q0: the chart's base configuration, shape (nq,).
            q1: a configuration, shape (nq,).

        Returns:
            xi, shape of the chart.
        """
        return q1 - q0

    def project(self, q: Array) -> Array:
        """Map coordinates back to their canonical form (unit quaternion, principal rotation vector).

        Args:
            q: configuration, shape (nq,).

        Returns:
            The same configuration in canonical coordinates, shape (nq,); q itself by default.
        """
        return q

    def hold(self, t: Array, q: Array, u: Array) -> "AbstractSystem":
        """The system as it acts over one step of `simulate` that starts at (t, q, u).

        Sampled controls (`mbjax.control.ZeroOrderHold`, `SampleAndHold`) are frozen at their
        values there.

        Args:
            t: time at the step's start [s], a scalar.
            q: configuration at the step's start, shape (nq,).
            u: velocity state at the step's start, shape (nu,).

        Returns:
            The system with its sampled controls held; the system itself by default.
        """
        return self

    def constrain(self, t: Array, q: Array, u: Array) -> tuple[Array, Array]:
        """After each step of `simulate`: put (q, u) back on the system's constraints.

        A closed loop projects onto its closures here (`mbjax.loops`).

        Args:
            t: time [s], a scalar.
            q: configuration, shape (nq,).
            u: velocity state, shape (nu,).

        Returns:
            (q, u) on the constraints; unchanged by default.
        """
        return q, u

    # whether the state holds a batch of copies along its last axis (`BatchTreeSystem`), each
    # with a status of its own
    batched = False

    def quaternions(self) -> tuple[tuple[int, int, str], ...]:
        """Where the configuration holds unit quaternions, which `simulate` checks in q0.

        Returns:
            (start, stop, what) for each, q[start:stop] a quaternion; none by default.
        """
        return ()

    def check(self, t: Array, q: Array, u: Array) -> Array:
        """`Status` flags for a state `simulate` saves.

        A closed loop reports a violated or redundant constraint here (`mbjax.loops`), a tree a
        joint limit exceeded, the Carpal Wrist a singular configuration.

        Args:
            t: time [s], a scalar.
            q: configuration, shape (nq,).
            u: velocity state, shape (nu,).

        Returns:
            An int32 scalar of OR-ed `Status` flags; 0 by default.
        """
        return jnp.array(0, jnp.int32)

    def culprit(self, t: Array, q: Array, u: Array) -> Array:
        """What made `check` flag a state, for the status's words.

        Args:
            t: time [s], a scalar.
            q: configuration, shape (nq,).
            u: velocity state, shape (nu,).

        Returns:
            An int32 index into `culprit_names()`, -1 for none; -1 by default.
        """
        return jnp.array(-1, jnp.int32)

    def culprit_names(self) -> tuple[str, ...]:
        """The names `culprit` indexes (a joint's position limit, a singularity); none by
        default."""
        return ()

    def invariants(self, t: Array, q: Array, u: Array) -> Invariants | None:
        """The quantities the exact motion conserves at a state.

        The energy of a passive system, a free tree's momentum (`mbjax/_src/system/invariants.py`):
        their drift is what `simulate` holds to rtol, or by default to 1 %. `simulate` evaluates
        them at every saved state, so they should be cheap to compile and to run.

        Args:
            t: time [s], a scalar.
            q: configuration, shape (nq,).
            u: velocity state, shape (nu,).

        Returns:
            The invariants at the state, or None where none is known (the default).
        """
        return None

    def state_sizes(self) -> tuple[int | None, int | None]:
        """The lengths of q and u a state of this system must have.

        `simulate` and `mbjax.trajopt.Problem` check states against them.

        Returns:
            (nq, nu), each None where the system does not say; (None, None) by default.
        """
        return None, None

    @property
    def n_controls(self) -> int:
        """The number of forces its control returns (its actuated coordinates).

        Raises:
            TypeError: the system has no control.
        """
        raise TypeError(f"{type(self).__name__} has no control")

    def with_control(self, control) -> "AbstractSystem":
        """The system driven by `control` instead of its own (what trajectory optimisation varies).

        Args:
            control: a callable (t, q, u) -> forces, an `mbjax.control` module or a constant
                array.

        Returns:
            A copy of the system with the new control.

        Raises:
            TypeError: the system has no control.
        """
        raise TypeError(f"{type(self).__name__} has no control to optimise: a problem needs a "
                        "system with a `control` (TreeSystem, FlexibleSystem, WristSystem, "
                        "RigidBody, a ClosedSystem of a tree, ...)")

    @eqx.filter_jit
    def holding_control(self, q: Array, nu: int) -> Array:
        """The control that holds configuration q at rest (`mbjax.trajopt.quasi_static`'s first
        guess; Crocoddyl's `quasiStatic`).

        Args:
            q: configuration, shape (nq,).
            nu: the number of controls.

        Returns:
            u, shape (nu,): the least-squares answer where no control holds q.

        Raises:
            TypeError: the system has no quasi-static hold (trees and their closed systems
                have one).
        """
        raise TypeError(f"{type(self).__name__} has no quasi-static hold: give solve a first "
                        "guess us0 instead of quasi_static's")

    def relative_energy_error(self, qs: Array, us: Array) -> Array:
        """(E(t) - E(0)) / |E(0)| along a saved trajectory, for systems with an `energy(q, u)`.

        One compiled program, not one per array operation when called outside `jit`.

        Args:
            qs: saved configurations, shape (n_saves, nq).
            us: saved velocity states, shape (n_saves, nu).

        Returns:
            The relative energy error at every saved state, shape (n_saves,).
        """
        E = jax.vmap(self.energy)(qs, us)
        return (E - E[0]) / jnp.abs(E[0])
