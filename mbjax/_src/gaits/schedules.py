"""Crocoddyl's gaits as problems: its quadruped's walk, trot and jump
(`SimpleQuadrupedalGaitProblem.createWalkingProblem`, `createTrottingProblem`,
`createJumpingProblem`) and its biped's walk (`SimpleBipedGaitProblem.createWalkingProblem`),
from a `Gait`."""

import numpy as np

from mbjax._src.gaits.gait import Gait
from mbjax._src.trajopt.problem import Problem
from mbjax._src.trajopt.residuals import com_residual


def _cycle(gait: Gait, first, second, length, height, step_knots, support_knots):
    """A gait cycle's knots: a double support, each group of feet in `first` stepping half of
    `length` in turn, a double support, each group in `second` stepping the whole of it."""
    com, feet = gait.com, dict(gait.positions)
    knots = []
    for groups, fraction in ((first, 0.5), (second, 1.0)):
        knots += gait.support(support_knots)
        for swing in groups:
            step, com, feet = gait.steps(com, feet, swing, fraction * length, height,
                                         step_knots)
            knots += step
    return knots


def walk(gait: Gait, step_length: float = 0.25, step_height: float = 0.15, dt: float = 1e-2,
         step_knots: int = 25, support_knots: int = 2) -> Problem:
    """One cycle of walking: each foot steps in turn, the first half of the feet half a step.

    A quadruped (feet LF, RF, LH, RH) steps RH, RF (half steps), then after a double support
    LH, LF (Crocoddyl's walk); a biped (right, left) steps right (half), then left, its last
    impulse the terminal cost (Crocoddyl's biped walk). Every step ends in an impulse, and the
    double support of `support_knots` knots starts the gait and parts its halves.

    Args:
        gait: the robot's gait builder.
        step_length, step_height: a full step's length (forward, x) and its arc's height [m].
        dt: the step of the problem [s].
        step_knots: knots in the air per step.
        support_knots: knots of each double support.

    Returns:
        The problem, from the standing state at rest.
    """
    order = _order(gait, {4: (3, 1, 2, 0), 2: (0, 1)}, "walk")
    half = len(order) // 2
    knots = _cycle(gait, [[f] for f in order[:half]], [[f] for f in order[half:]], step_length,
                   step_height, step_knots, support_knots)
    if len(order) == 2:         # the biped's last impulse is its terminal cost
        return gait.problem(knots[:-1], dt, knots[-1].running)
    return gait.problem(knots, dt)


def trot(gait: Gait, step_length: float = 0.25, step_height: float = 0.15, dt: float = 1e-2,
         step_knots: int = 25, support_knots: int = 2) -> Problem:
    """One cycle of trotting (Crocoddyl's trot): a quadruped's diagonal pairs step in turn, RF-LH
    half a step, then after a double support LF-RH a full step.

    Args:
        gait: a quadruped's gait builder (feet LF, RF, LH, RH).
        step_length, step_height: a full step's length (forward, x) and its arc's height [m].
        dt: the step of the problem [s].
        step_knots: knots in the air per step.
        support_knots: knots of each double support.

    Returns:
        The problem, from the standing state at rest.
    """
    lf, rf, lh, rh = _order(gait, {4: (0, 1, 2, 3)}, "trot")
    return gait.problem(_cycle(gait, [[rf, lh]], [[lf, rh]], step_length, step_height,
                               step_knots, support_knots), dt)


def jump(gait: Gait, jump_height: float = 0.15, jump_length=(0.0, 0.3, 0.0),
         dt: float = 1e-2, ground_knots: int = 10, flying_knots: int = 20) -> Problem:
    """A jump (Crocoddyl's `createJumpingProblem`): every foot on the ground for
    `ground_knots`, a flight of 2 `flying_knots` (the centre of mass driven up `jump_height`
    and along half the jump in the first half), the feet landing `jump_length` further (an
    impulse), and `ground_knots` more on the ground there, the last one the terminal cost's.

    Args:
        gait: the robot's gait builder.
        jump_height: the centre of mass's rise [m].
        jump_length: the jump's displacement (x, y, z) [m].
        dt: the step of the problem [s].
        ground_knots: knots on the ground before the jump and after it.
        flying_knots: knots of each half of the flight.

    Returns:
        The problem, from the standing state at rest.
    """
    length = np.asarray(jump_length, float)
    if length.shape != (3,):
        raise ValueError(f"jump_length must be (x, y, z), got shape {length.shape}")
    feet, com = gait.feet, gait.com
    ground = {f: p * np.array([1.0, 1.0, 0.0]) for f, p in gait.positions.items()}
    rise = np.r_[length[:2] / 2, length[2] / 2 + jump_height]
    # Crocoddyl's landing: the CoM moved by the jump, less a foot's height above the ground
    landed = com + np.r_[length[:2], length[2] - gait.positions[feet[1 % len(feet)]][2]]
    knots = (gait.support(ground_knots)
             + [gait.knot([], com + rise * (k + 1) / flying_knots) for k in range(flying_knots)]
             + [gait.knot([]) for _ in range(flying_knots)]
             + [gait.impulse(feet, [(f, ground[f] + length) for f in feet])]
             + [gait.knot(feet, landed) for _ in range(ground_knots - 1)])
    terminal = (com_residual(gait.model, landed, weight=1e6), gait.regularisation(), *gait.bounds)
    return gait.problem(knots, dt, terminal)


def _order(gait: Gait, orders: dict, name: str) -> list:
    """The feet in the order `name` steps them, for the gait's number of feet."""
    if len(gait.feet) not in orders:
        raise ValueError(f"{name} is written for {' or '.join(map(str, orders))} feet, "
                         f"got gait.feet = {gait.feet}")
    return [gait.feet[i] for i in orders[len(gait.feet)]]
