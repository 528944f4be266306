"""The interface every fixed-step integrator implements."""

import abc
from typing import ClassVar

import equinox as eqx
from jax import Array

from mbjax._src.system.system import AbstractSystem


class AbstractIntegrator(eqx.Module):
    """A fixed-step integrator: one step (q, u) at t -> (q, u) at t + dt of an `AbstractSystem`.

    Integrators are strategies passed to `mbjax.simulate` (and to `mbjax.trajopt.Problem`).
    Each has a class attribute `order` (its order of accuracy) and `name`.
    """

    order: ClassVar[int]
    name: ClassVar[str]

    @abc.abstractmethod
    def step(self, system: AbstractSystem, t: Array, q: Array, u: Array, dt: Array,
             a0: Array | None = None) -> tuple[Array, Array, Array]:
        """Advance the system one step.

        Args:
            system: the system whose `kinematics` and `acceleration` are integrated.
            t: time at the step's start [s], a scalar.
            q: configuration at t, shape (nq,).
            u: velocity coordinates at t, shape (nv,).
            dt: the step [s], a scalar.
            a0: the acceleration `system.acceleration(t, q, u)` where the caller has it already
                (a knot whose costs read the forces of the same solve), shape (nv,); None to
                evaluate it. Integrators whose first stage is not at (t, q, u) ignore it.

        Returns:
            q1: configuration at t + dt, projected (`system.project`), shape (nq,).
            u1: velocity coordinates at t + dt, shape (nv,).
            converged: a boolean scalar, False when an inner solve (an implicit step's Newton
                iteration) did not converge; `simulate` turns it into the solution's status.
        """

    def advance(self, system: AbstractSystem, t: Array, q: Array, u: Array, dt: Array,
                a0: Array | None = None) -> tuple[Array, Array, Array]:
        """One step of the system as `simulate` takes it: its controls held at their value at
        the step's start (`system.hold`), stepped (`step`), then put back on the system's
        constraints (`system.constrain`). `simulate`, its error estimate and the trajectory
        optimisers' knots all step this way.

        Args:
            system: the system, unheld.
            t: time at the step's start [s], a scalar.
            q: configuration at t, shape (nq,).
            u: velocity coordinates at t, shape (nv,).
            dt: the step [s], a scalar.
            a0: the acceleration of the held system at (t, q, u) where the caller has it
                (see `step`); None to evaluate it.

        Returns:
            (q1, u1, converged) at t + dt, as `step` returns them, constrained.
        """
        q1, u1, converged = self.step(system.hold(t, q, u), t, q, u, dt, a0=a0)
        return (*system.constrain(t + dt, q1, u1), converged)
