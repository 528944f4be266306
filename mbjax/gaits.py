"""Legged robots' gaits as trajectory-optimisation problems, as Crocoddyl's gait builders write
them (`SimpleQuadrupedalGaitProblem`, `SimpleBipedGaitProblem`): a `Gait` from a floating-base
model, its standing configuration and its feet makes the knots (stances, impulses, their costs),
and `walk`, `trot` and `jump` the problems:

    gait = Gait(model, q0, ("LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT"))
    problem = trot(gait, step_length=0.25, step_height=0.15)
    result = trajopt.solve(problem, ILQR(**CROCODDYL_SCHEDULE), trajopt.quasi_static(problem))

Every knot is written over all the feet, so a whole gait compiles as two phases (the stances
and the impulses). The legged-robots guide writes such a gait by hand."""

from mbjax._src.gaits.gait import BIPED as BIPED
from mbjax._src.gaits.gait import QUADRUPED as QUADRUPED
from mbjax._src.gaits.gait import Gait as Gait
from mbjax._src.gaits.gait import Weights as Weights
from mbjax._src.gaits.schedules import jump as jump
from mbjax._src.gaits.schedules import trot as trot
from mbjax._src.gaits.schedules import walk as walk

__all__ = ["Gait", "Weights", "QUADRUPED", "BIPED", "walk", "trot", "jump"]
