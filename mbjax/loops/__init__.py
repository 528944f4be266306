"""Closed loops (seed 001 §VI, seed 002 §2.4): cut joints and prescribed motions as constraints
on a tree (`CutJoint`, `Prescribed`, `Loops`), the coupled Lagrange-multiplier solution with
Baumgarte stabilization (`coupled_acceleration`) and `LoopSystem` for `mbjax.simulate`.

Work in progress (issue 5): seed 002's O(n + m^3) stabilization, projection and the mechanisms
of the issue are still to come.
"""

from mbjax.loops.closures import GROUND, CutJoint, Prescribed
from mbjax.loops.constraints import Loops
from mbjax.loops.coupled import coupled_acceleration, multipliers
from mbjax.loops.system import LoopSystem

__all__ = ["GROUND", "CutJoint", "LoopSystem", "Loops", "Prescribed", "coupled_acceleration",
           "multipliers"]
