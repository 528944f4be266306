"""Trajectory optimisation for any system (`Problem`, `solve` with a solver strategy such as
`ILQR`, `MultipleShooting`, `Shooting`; `optimal_cost` for co-design); `sweep` for batches)."""

from mbjax._src.trajopt.codesign import optimal_cost as optimal_cost
from mbjax._src.trajopt.ilqr import ILQR as ILQR
from mbjax._src.trajopt.multiple_shooting import MultipleShooting as MultipleShooting
from mbjax._src.trajopt.problem import Problem as Problem
from mbjax._src.trajopt.result import AbstractSolver as AbstractSolver, Result as Result
from mbjax._src.trajopt.shooting import Shooting as Shooting
from mbjax._src.trajopt.solve import solve as solve
from mbjax._src.trajopt.sweep import sweep as sweep
from mbjax._src.trajopt.residuals import (
    control_residual as control_residual,
    frame_residual as frame_residual,
    state_residual as state_residual,
)
