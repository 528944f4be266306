"""Closed loops (seed 001 §VI, seed 002 §2.4): cut joints and prescribed motions as constraints
on a tree (`CutJoint`, `Prescribed`, `Loops`), the coupled Lagrange-multiplier solution with
Baumgarte stabilization (`coupled_acceleration`, `LoopSystem`) and seed 002's O(n + m^3)
stabilization (`stabilized_acceleration`, `StabilizedLoopSystem`).

Seed 001's momentum form (`momentum_rate`, `MomentumLoopSystem`), projection onto the constraints
(`consistent_state` for initial conditions, `projection=True` after every step) and the status
flags of a run (`Status.CONSTRAINT_VIOLATED`, `Status.REDUNDANT`) complete the set.
"""

from mbjax.loops.closures import GROUND, CutJoint, Prescribed
from mbjax.loops.constraints import Loops
from mbjax.loops.coupled import coupled_acceleration, momentum_rate, multipliers, numerical_rank
from mbjax.loops.stabilized import eta_and_gamma, stabilized_acceleration
from mbjax.loops.projection import consistent_state, project_configuration, project_velocity
from mbjax.loops.system import LoopSystem, MomentumLoopSystem, StabilizedLoopSystem

__all__ = ["GROUND", "CutJoint", "LoopSystem", "Loops", "MomentumLoopSystem", "Prescribed",
           "StabilizedLoopSystem", "consistent_state", "coupled_acceleration", "eta_and_gamma", "momentum_rate",
           "multipliers", "numerical_rank", "project_configuration", "project_velocity",
           "stabilized_acceleration"]
