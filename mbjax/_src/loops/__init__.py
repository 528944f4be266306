"""Closed loops (Jerkovsky 1978 §VI, Anderson 1993 §2.4): any tree closed by cut joints and prescribed
motions (`CutJoint`, `Coupling`, `Prescribed`), as a system for `simulate`:

    ClosedSystem(tree, closures, method=..., projection=False)

with the loop method a strategy passed in: Jerkovsky 1978's coupled Lagrange multipliers with Baumgarte
stabilization (`Coupled`), its momentum form (`Momentum`), or Anderson 1993's O(n + m^3) route from one
triangularization with its epsilon-dynamics (`Stabilized`). Projection onto the constraints
after every step (differentiable, by the implicit function theorem) and of initial conditions
(`consistent_state`), and the status flags of a run (`Status.CONSTRAINT_VIOLATED`,
`Status.REDUNDANT`) complete the set. The algorithms are also plain functions of a `Loops`
(the tree with its closures): `coupled_acceleration`, `loop_momentum_rate`, `eta_and_gamma`,
`stabilized_acceleration`.
"""

from mbjax._src.model.closures import (
    GROUND as GROUND,
    Coupling as Coupling,
    CutJoint as CutJoint,
    Prescribed as Prescribed,
)
from mbjax._src.loops.constraints import Loops as Loops
from mbjax._src.loops.coupled import (
    Coupled as Coupled,
    coupled_acceleration as coupled_acceleration,
)
from mbjax._src.loops.method import AbstractLoopMethod as AbstractLoopMethod
from mbjax._src.loops.momentum import (
    Momentum as Momentum,
    loop_momentum_rate as loop_momentum_rate,
)
from mbjax._src.loops.multipliers import (
    multipliers as multipliers,
    numerical_rank as numerical_rank,
)
from mbjax._src.loops.projection import (
    consistent_state as consistent_state,
    gauss_newton as gauss_newton,
    project_configuration as project_configuration,
    project_velocity as project_velocity,
)
from mbjax._src.loops.stabilized import (
    Stabilized as Stabilized,
    eta_and_gamma as eta_and_gamma,
    stabilized_acceleration as stabilized_acceleration,
)
from mbjax._src.loops.system import ClosedSystem as ClosedSystem
