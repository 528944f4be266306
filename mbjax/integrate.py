"""Time integration: fixed-step integrators (strategies passed to `simulate`; `INTEGRATORS`
names them), the `simulate` driver with its `Solution`, and diffrax's adaptive solvers as the
reference."""

from mbjax._src.integrate import INTEGRATORS as INTEGRATORS
from mbjax._src.integrate.base import AbstractIntegrator as AbstractIntegrator
from mbjax._src.integrate.explicit_euler import ExplicitEuler as ExplicitEuler
from mbjax._src.integrate.semi_implicit_euler import SemiImplicitEuler as SemiImplicitEuler
from mbjax._src.integrate.rk4 import RK4 as RK4
from mbjax._src.integrate.implicit_midpoint import ImplicitMidpoint as ImplicitMidpoint
from mbjax._src.integrate.rkmk4 import RKMK4 as RKMK4
from mbjax._src.integrate.simulate import simulate as simulate
from mbjax._src.integrate.solution import Solution as Solution
from mbjax._src.integrate.reference import solve_reference as solve_reference

__all__ = [
    "AbstractIntegrator", "ExplicitEuler", "SemiImplicitEuler", "RK4", "ImplicitMidpoint", "RKMK4",
    "INTEGRATORS", "simulate", "Solution", "solve_reference"
]
