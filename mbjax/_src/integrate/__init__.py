"""Time integration: fixed-step integrators, the `simulate` driver and diffrax references."""

from mbjax._src.integrate.base import AbstractIntegrator as AbstractIntegrator
from mbjax._src.integrate.explicit_euler import ExplicitEuler as ExplicitEuler
from mbjax._src.integrate.implicit_midpoint import ImplicitMidpoint as ImplicitMidpoint
from mbjax._src.integrate.reference import solve_reference as solve_reference
from mbjax._src.integrate.rk4 import RK4 as RK4
from mbjax._src.integrate.rkmk4 import RKMK4 as RKMK4
from mbjax._src.integrate.semi_implicit_euler import SemiImplicitEuler as SemiImplicitEuler
from mbjax._src.integrate.simulate import simulate as simulate
from mbjax._src.integrate.solution import Solution as Solution
from mbjax._src.system.status import Status as Status
from mbjax._src.system.system import AbstractSystem as AbstractSystem

INTEGRATORS = {cls.name: cls for cls in
               (ExplicitEuler, SemiImplicitEuler, RK4, ImplicitMidpoint, RKMK4)}
"""The fixed-step integrators by name ("explicit_euler", "semi_implicit_euler", "rk4",
"implicit_midpoint", "rkmk4"): `INTEGRATORS["rk4"]()` is `RK4()`, for choosing one from a
string (a command line, a sweep's table)."""
