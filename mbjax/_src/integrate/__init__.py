"""Time integration: fixed-step integrators, the `simulate` driver and diffrax references."""

from mbjax._src.integrate.base import AbstractIntegrator
from mbjax._src.integrate.explicit_euler import ExplicitEuler
from mbjax._src.integrate.implicit_midpoint import ImplicitMidpoint
from mbjax._src.integrate.reference import solve_reference
from mbjax._src.integrate.rk4 import RK4
from mbjax._src.integrate.rkmk4 import RKMK4
from mbjax._src.integrate.semi_implicit_euler import SemiImplicitEuler
from mbjax._src.integrate.simulate import simulate
from mbjax._src.integrate.solution import Solution
from mbjax._src.system.status import Status
from mbjax._src.system.system import AbstractSystem

INTEGRATORS = {cls.name: cls for cls in
               (ExplicitEuler, SemiImplicitEuler, RK4, ImplicitMidpoint, RKMK4)}

__all__ = ["AbstractIntegrator", "AbstractSystem", "ExplicitEuler", "ImplicitMidpoint",
           "INTEGRATORS", "RK4", "RKMK4", "SemiImplicitEuler", "Solution", "Status", "simulate",
           "solve_reference"]
