"""Trajectory optimisation for any system (`Problem`, `solve` with a solver strategy such as
`ILQR`, `MultipleShooting`, `Shooting`; `optimal_cost` for co-design), and the Carpal Wrist's synthesis, baseline, controller and sweeps (Canfield 1997 §6)."""

from mbjax.trajopt.codesign import optimal_cost
from mbjax.trajopt.ilqr import ILQR
from mbjax.trajopt.multiple_shooting import MultipleShooting
from mbjax.trajopt.problem import Problem
from mbjax.trajopt.result import AbstractSolver, Result
from mbjax.trajopt.shooting import Shooting
from mbjax.trajopt.solve import solve
from mbjax.trajopt.sweeps import grid, peak_torque, sweep

__all__ = ["AbstractSolver", "ILQR", "MultipleShooting", "Problem", "Result", "Shooting", "grid",
           "optimal_cost", "peak_torque", "solve", "sweep"]
