"""Time integration: fixed-step integrators, the `simulate` driver and diffrax references."""

from mbjax.integrate.base import AbstractIntegrator
from mbjax.integrate.explicit_euler import ExplicitEuler
from mbjax.integrate.implicit_midpoint import ImplicitMidpoint
from mbjax.integrate.reference import solve_reference
from mbjax.integrate.rk4 import RK4
from mbjax.integrate.rkmk4 import RKMK4
from mbjax.integrate.semi_implicit_euler import SemiImplicitEuler
from mbjax.integrate.simulate import simulate
from mbjax.integrate.solution import Solution, Status
from mbjax.integrate.system import AbstractSystem

INTEGRATORS = {cls.name: cls for cls in
               (ExplicitEuler, SemiImplicitEuler, RK4, ImplicitMidpoint, RKMK4)}

__all__ = ["AbstractIntegrator", "AbstractSystem", "ExplicitEuler", "ImplicitMidpoint",
           "INTEGRATORS", "RK4", "RKMK4", "SemiImplicitEuler", "Solution", "Status", "simulate",
           "solve_reference"]
