"""Trajectory optimisation for any system: a `Problem` (one system, or `Knot`s and `Impulse`s
through contact phases), `solve` with a solver strategy (`ILQR`, `MultipleShooting`,
`Shooting`, whose steps an optax optimizer takes: `optax.lbfgs()`, or Adam by `cosine_adam`),
its `Result`, residuals for the common costs (contact forces and friction cones too), a
`quasi_static` first guess, the contact wrenches along a solution (`knot_wrenches`),
`optimal_cost` for co-design, and `sweep` for batches of problems or parameters; and
model-predictive control: `MPC`, a receding-horizon controller whose `Plan` is carried
explicitly, run against a plant by `closed_loop` (one jitted, vmappable, differentiable program)
or tick by tick (`MPC.tick`, `follow`)."""

from mbjax._src.trajopt.problem import Problem as Problem
from mbjax._src.trajopt.solve import solve as solve
from mbjax._src.trajopt.result import AbstractSolver as AbstractSolver
from mbjax._src.trajopt.result import Result as Result
from mbjax._src.trajopt.ilqr import ILQR as ILQR
from mbjax._src.trajopt.ilqr import CROCODDYL_SCHEDULE as CROCODDYL_SCHEDULE
from mbjax._src.trajopt.multiple_shooting import MultipleShooting as MultipleShooting
from mbjax._src.trajopt.shooting import Shooting as Shooting
from mbjax._src.trajopt.shooting import cosine_adam as cosine_adam
from mbjax._src.trajopt.codesign import optimal_cost as optimal_cost
from mbjax._src.trajopt.sweep import sweep as sweep
from mbjax._src.trajopt.residuals import state_residual as state_residual
from mbjax._src.trajopt.residuals import frame_residual as frame_residual
from mbjax._src.trajopt.residuals import control_residual as control_residual
from mbjax._src.trajopt.residuals import com_residual as com_residual
from mbjax._src.trajopt.residuals import friction_cone_residual as friction_cone_residual
from mbjax._src.trajopt.residuals import contact_force_residual as contact_force_residual
from mbjax._src.trajopt.residuals import barrier_residual as barrier_residual
from mbjax._src.trajopt.residuals import wrench_cone_residual as wrench_cone_residual
from mbjax._src.trajopt.knots import Knot as Knot
from mbjax._src.trajopt.knots import Impulse as Impulse
from mbjax._src.trajopt.quasi_static import quasi_static as quasi_static
from mbjax._src.trajopt.wrenches import knot_wrenches as knot_wrenches
from mbjax._src.trajopt.mpc import MPC as MPC
from mbjax._src.trajopt.mpc import Plan as Plan
from mbjax._src.trajopt.mpc import Cycle as Cycle
from mbjax._src.trajopt.mpc import Tick as Tick
from mbjax._src.trajopt.mpc import ClosedLoop as ClosedLoop
from mbjax._src.trajopt.mpc import closed_loop as closed_loop
from mbjax._src.trajopt.mpc import follow as follow

__all__ = [
    "Problem", "solve", "AbstractSolver", "Result", "ILQR", "CROCODDYL_SCHEDULE",
    "MultipleShooting", "Shooting", "cosine_adam",
    "optimal_cost", "sweep", "state_residual", "frame_residual", "control_residual",
    "com_residual", "friction_cone_residual", "contact_force_residual", "barrier_residual",
    "wrench_cone_residual",
    "Knot", "Impulse", "quasi_static", "knot_wrenches",
    "MPC", "Plan", "Cycle", "Tick", "ClosedLoop", "closed_loop", "follow",
]
