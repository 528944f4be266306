"""Everything Crocoddyl: the same problems built in mbjax and in Crocoddyl, and Crocoddyl's side
of each comparison (`mbjax bench trajopt`, `mbjax bench mpc`, the tour's legged gait, the
cross-engine tests).

    terms       whether Crocoddyl works here (`crocoddyl_working`), frames, cost sums, shooting
                problems; the shipped arm's reach and the acrobot's swing-up in its terms
    examples    its contact-free examples (`EXAMPLES`, `Example`: Kinova arm, double pendulum,
                quadrotor, bounded quadrotor)
    gaits       its legged gaits through contact (`GAITS`: ANYmal's walk, trot and jump, Talos's
                step)
    solver      its solvers from a fixed first guess (`CrocoddylSolver`) and the check that the
                two problems are one (`agreement`)

The package itself imports only `terms` (NumPy; Crocoddyl and Pinocchio when called), so asking
`crocoddyl_working()` loads no trajectory optimisation.
"""

from mbjax_harness.crocoddyl.terms import crocoddyl_reach, crocoddyl_swingup, crocoddyl_working

__all__ = ["crocoddyl_reach", "crocoddyl_swingup", "crocoddyl_working"]
