"""Closed loops (Jerkovsky 1978 §VI, Anderson 1993 §2.4): a tree closed by cut joints, couplings and
prescribed motions, as a system for `simulate`, with the loop method a strategy passed in:

    ClosedSystem(tree, closures, method=Coupled() | Momentum() | Stabilized())
"""

from mbjax._src.loops.system import ClosedSystem as ClosedSystem
from mbjax._src.loops.method import AbstractLoopMethod as AbstractLoopMethod
from mbjax._src.loops.coupled import Coupled as Coupled
from mbjax._src.loops.momentum import Momentum as Momentum
from mbjax._src.loops.stabilized import Stabilized as Stabilized
from mbjax._src.model.closures import CutJoint as CutJoint
from mbjax._src.model.closures import AbstractCutKind as AbstractCutKind
from mbjax._src.model.closures import Spherical as Spherical
from mbjax._src.model.closures import Revolute as Revolute
from mbjax._src.model.closures import Universal as Universal
from mbjax._src.model.closures import Weld as Weld
from mbjax._src.model.closures import SpatialWeld as SpatialWeld
from mbjax._src.model.closures import Prismatic as Prismatic
from mbjax._src.model.closures import PointOnLine as PointOnLine
from mbjax._src.model.closures import PointOnPlane as PointOnPlane
from mbjax._src.model.closures import Coupling as Coupling
from mbjax._src.model.closures import Prescribed as Prescribed
from mbjax._src.loops.constraints import Loops as Loops
from mbjax._src.loops.projection import consistent_state as consistent_state
from mbjax._src.loops.projection import project_configuration as project_configuration
from mbjax._src.loops.projection import project_velocity as project_velocity

__all__ = [
    "ClosedSystem", "AbstractLoopMethod", "Coupled", "Momentum", "Stabilized", "CutJoint",
    "AbstractCutKind", "Spherical", "Revolute", "Universal", "Weld", "SpatialWeld", "Prismatic",
    "PointOnLine", "PointOnPlane",
    "Coupling", "Prescribed", "Loops", "consistent_state", "project_configuration",
    "project_velocity"
]
