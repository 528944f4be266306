"""Legged robots' gaits as trajectory-optimisation problems: Crocoddyl's gait builders
(`SimpleQuadrupedalGaitProblem`, `SimpleBipedGaitProblem`) written on `mbjax.trajopt`'s knots."""
