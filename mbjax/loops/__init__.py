"""Closed loops (seed 001 §VI, seed 002 §2.4): cut joints and prescribed motions as constraints
on a tree (`CutJoint`, `Prescribed`, `Loops`), the coupled Lagrange-multiplier solution with
Baumgarte stabilization (`coupled_acceleration`, `LoopSystem`) and seed 002's O(n + m^3)
stabilization (`stabilized_acceleration`, `StabilizedLoopSystem`).

Work in progress (issue 5): projection, the momentum form and the mechanisms of the issue are
still to come.
"""

from mbjax.loops.closures import GROUND, CutJoint, Prescribed
from mbjax.loops.constraints import Loops
from mbjax.loops.coupled import coupled_acceleration, momentum_rate, multipliers, numerical_rank
from mbjax.loops.stabilized import eta_and_gamma, stabilized_acceleration
from mbjax.loops.projection import project_configuration, project_velocity
from mbjax.loops.system import LoopSystem, MomentumLoopSystem, StabilizedLoopSystem

__all__ = ["GROUND", "CutJoint", "LoopSystem", "Loops", "MomentumLoopSystem", "Prescribed",
           "StabilizedLoopSystem", "coupled_acceleration", "eta_and_gamma", "momentum_rate",
           "multipliers", "numerical_rank", "project_configuration", "project_velocity",
           "stabilized_acceleration"]
