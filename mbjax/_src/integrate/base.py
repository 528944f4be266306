"""The interface every fixed-step integrator implements."""

import abc
from typing import ClassVar

import equinox as eqx
from jax import Array

from mbjax._src.system.system import AbstractSystem


class AbstractIntegrator(eqx.Module):
    """One step (q, u) at t -> (q, u) at t + dt of an `AbstractSystem`.

    `step` also returns a boolean scalar that is False when an inner solve did not converge;
    `simulate` turns it into the solution's status.
    """

    order: ClassVar[int]
    name: ClassVar[str]

    @abc.abstractmethod
    def step(self, system: AbstractSystem, t: Array, q: Array, u: Array,
             dt: Array) -> tuple[Array, Array, Array]:
        """Advance one step; return (q, u, converged)."""
