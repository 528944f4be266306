"""Trajectory optimisation for any system (`Problem`, `solve` with a solver strategy such as
`ILQR`, `MultipleShooting`, `Shooting`; `optimal_cost` for co-design); `sweep` for batches)."""

from mbjax._src.trajopt.codesign import optimal_cost
from mbjax._src.trajopt.ilqr import ILQR
from mbjax._src.trajopt.multiple_shooting import MultipleShooting
from mbjax._src.trajopt.problem import Problem
from mbjax._src.trajopt.result import AbstractSolver, Result
from mbjax._src.trajopt.shooting import Shooting
from mbjax._src.trajopt.solve import solve
from mbjax._src.trajopt.sweep import sweep
from mbjax._src.trajopt.residuals import control_residual, frame_residual, state_residual

__all__ = ["AbstractSolver", "ILQR", "MultipleShooting", "Problem", "Result", "Shooting",
           "optimal_cost", "solve", "sweep", "control_residual", "frame_residual", "state_residual"]
