"""A legged robot's gait builder: the knots of Crocoddyl's gait problems (its
`SimpleQuadrupedalGaitProblem` and `SimpleBipedGaitProblem`), cost by cost, from a model, its
standing configuration and its feet."""

from typing import NamedTuple

import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.contact.contact import PointContact, SurfaceContact
from mbjax._src.contact.stance import stance
from mbjax._src.integrate.semi_implicit_euler import SemiImplicitEuler
from mbjax._src.loops.method import AbstractLoopMethod
from mbjax._src.loops.coupled import Coupled
from mbjax._src.rigid.centre import center_of_mass
from mbjax._src.rigid.frames import frame_pose
from mbjax._src.rigid.system import TreeSystem
from mbjax._src.trajopt.knots import Impulse, Knot
from mbjax._src.trajopt.problem import Problem
from mbjax._src.trajopt.residuals import (barrier_residual, com_residual, control_residual,
                                          frame_residual, friction_cone_residual,
                                          state_residual, wrench_cone_residual)


class Weights(NamedTuple):
    """A state cost's weights in Crocoddyl's layout, each a scalar or a sequence: the base's
    placement (linear x y z, then angular), the joints' positions, the base's velocity (linear,
    then angular) and the joints' velocities. `Gait` orders them as mbjax's tangent space does
    (a free joint's angular part first).

    Args:
        base: the base's placement, 6 weights or one.
        joints: the joints' positions, nv - 6 weights or one.
        base_velocity: the base's twist, 6 weights or one.
        joint_velocity: the joints' velocities, nv - 6 weights or one.
    """

    base: object = (0.0, 0.0, 0.0, 500.0, 500.0, 500.0)
    joints: object = 0.01
    base_velocity: object = 10.0
    joint_velocity: object = 1.0

    def tangent(self, nv: int) -> np.ndarray:
        """The 2 nv weights in mbjax's tangent order (base angular, base linear, joints; then
        the velocity's, alike)."""
        nj = nv - 6
        w = np.concatenate([np.broadcast_to(np.asarray(x, float), (n,)) for x, n in (
            (self.base, 6), (self.joints, nj), (self.base_velocity, 6),
            (self.joint_velocity, nj))])
        return w[np.r_[3:6, 0:3, 6:6 + nj, nv + 3:nv + 6, nv:nv + 3, nv + 6:2 * nv]]


QUADRUPED = (Weights(), Weights(base=1.0, joints=10.0, base_velocity=10.0, joint_velocity=10.0))
"""`SimpleQuadrupedalGaitProblem`'s state weights: a step's knots' and an impulse's."""
BIPED = (Weights(joint_velocity=10.0),
         Weights(base=1.0, joints=0.1, base_velocity=10.0, joint_velocity=10.0))
"""`SimpleBipedGaitProblem`'s state weights: a step's knots' and an impulse's."""


class Gait:
    """The knots of a legged robot's gait, as Crocoddyl's gait builders write them.

    Each knot is written over all the feet, so that a whole gait is two compiled phases (every
    stance, whichever feet are down, and every impulse): a stance holds the support feet and
    has the others in the air (`active=False`), and a task that the knot lacks (the centre of
    mass, a foot that does not swing) is there with the weight 0. A knot's costs: the friction
    cones (point feet) or the soles' wrench cones (weight 10, `mu`), the centre of mass and the
    swinging feet tracked (1e6), the state regularisation (`weights[0]`), the controls (0.1),
    and the state's bounds as a barrier (1e3); an impulse's: its landing feet tracked
    (`impulse_tracking`) and the state (`weights[1]`).

    Args:
        model (Model): the robot, on a floating base.
        q0 (Array): its standing configuration, the state costs' reference and the problems'
            start (at rest).
        feet (Sequence[str]): the feet's frames. A quadruped's in Crocoddyl's order (left
            front, right front, left hind, right hind) for `walk` and `trot`; a biped's
            (right, left).
        sole: None for point feet (`PointContact`: friction cones, positions tracked), or a
            sole's (length, width) in metres for flat feet (`SurfaceContact(spatial=True)`:
            wrench cones, placements tracked).
        mu: the friction coefficient.
        weights: the state weights of a step's knots and of an impulse, a pair of `Weights`
            (`QUADRUPED` or `BIPED`).
        bounds: (lower, upper) on the state's deviation from the neutral configuration and its
            velocity (2 nv each, tangent order), or None for none.
        method (AbstractLoopMethod): how a stance holds its feet; Crocoddyl's Baumgarte gains
            (0, 50) by default (`Coupled(baumgarte=(25.0, 0.0))`; a biped's are (0, 30)).
        impulse_tracking: the weight of a landing foot's tracking at its impulse (1e7; a
            biped's is 1e8).
    """

    def __init__(self, model, q0, feet, *, sole=None, mu: float = 0.7,
                 weights=QUADRUPED, bounds=None,
                 method: AbstractLoopMethod = Coupled(baumgarte=(25.0, 0.0)),
                 impulse_tracking: float = 1e7):
        if isinstance(feet, str) or not len(feet):
            raise ValueError(f"feet must be a sequence of frame names, got {feet!r}")
        if model.joint_types[0] != "free":
            raise ValueError(f"model must be on a floating base (its first joint free, as "
                             f"load_urdf(..., floating_base=True) makes it), got a "
                             f"{model.joint_types[0]} joint")
        self.model = model
        self.q0 = jnp.asarray(q0, float)
        if self.q0.shape != (model.nq,):
            raise ValueError(f"q0 must have shape ({model.nq},), got {self.q0.shape}")
        self.feet = tuple(feet)
        self.sole = None if sole is None else tuple(float(x) for x in sole)
        self.mu = float(mu)
        self.tree = TreeSystem(model, actuation=range(6, model.nv))
        self.method = method
        self.impulse_tracking = float(impulse_tracking)
        self.weights = tuple(np.asarray(w.tangent(model.nv)) for w in weights)
        self.bounds = () if bounds is None else (barrier_residual(
            state_residual(model, model.neutral()), *bounds, weight=1e3),)
        # where the feet stand, and the centre of mass the gait carries: over the feet's mean
        self.positions = {f: np.asarray(frame_pose(model, self.q0, f)[1]) for f in self.feet}
        com = np.mean(list(self.positions.values()), axis=0)
        self.com = np.r_[com[:2], float(center_of_mass(model, self.q0)[2])]

    def contacts(self, down) -> list:
        """Every foot's contact, those in `down` on the ground and the others in the air."""
        if self.sole is None:
            return [PointContact(f, active=f in down) for f in self.feet]
        return [SurfaceContact(f, active=f in down, spatial=True) for f in self.feet]

    def regularisation(self, weights: Array | None = None):
        """The state cost (the standing configuration at rest) with a step's weights, or
        `weights` (2 nv, tangent order)."""
        w = self.weights[0] if weights is None else weights
        return state_residual(self.model, self.q0, weight=10.0 * np.asarray(w) ** 2)

    def tracks(self, swing, weight: float) -> list:
        """The feet's tracking costs: each foot of `swing` ((frame, target) pairs) tracked with
        `weight`, the others with 0 (so that every knot has the same costs)."""
        rotation = None if self.sole is None else np.eye(3)
        targets = dict(swing)
        return [frame_residual(self.model, f, targets.get(f, p), rotation,
                               weight=weight if f in targets else 0.0)
                for f, p in self.positions.items()]

    def knot(self, support, com=None, swing=()) -> Knot:
        """One step of the gait (Crocoddyl's `createSwingFootModel`).

        Args:
            support: the frames on the ground.
            com: the centre of mass's target, or None for none.
            swing: (frame, target position) pairs of the feet tracked in the air.

        Returns:
            The knot: a stance of the support feet and its costs.
        """
        phase = stance(self.tree, self.q0, self.contacts(support), method=self.method)
        cone = (friction_cone_residual(phase, self.mu, weight=10.0) if self.sole is None else
                wrench_cone_residual(phase, self.mu, *self.sole, weight=10.0))
        costs = (cone, com_residual(self.model, np.zeros(3) if com is None else com,
                                    weight=0.0 if com is None else 1e6),
                 *self.tracks(swing, 1e6), self.regularisation(),
                 control_residual(self.model.nv - 6, weight=0.1), *self.bounds)
        return Knot(phase, costs)

    def impulse_costs(self, swing) -> tuple:
        """An impulse's costs: the feet of `swing` ((frame, target) pairs) tracked, the state."""
        return (*self.tracks(swing, self.impulse_tracking),
                self.regularisation(self.weights[1]))

    def impulse(self, landing, swing) -> Impulse:
        """A touchdown (Crocoddyl's `createImpulseModel`): the feet of `landing` stopped on the
        ground, those of `swing` ((frame, target) pairs) tracked."""
        return Impulse(self.model, self.contacts(landing), self.impulse_costs(swing))

    def support(self, knots: int) -> list:
        """`knots` knots with every foot on the ground."""
        return [self.knot(self.feet) for _ in range(knots)]

    def steps(self, com, feet: dict, swing, length: float, height: float, knots: int):
        """A step (Crocoddyl's `createFootstepModels`): the feet of `swing` move `length` forward
        (x) along an arc of `height`, over `knots` knots, then land (an impulse); the centre
        of mass moves the swinging feet's share of the step.

        Args:
            com: the centre of mass's position at the step's start, shape (3,).
            feet: {frame: position} of the feet at the step's start.
            swing: the frames that step; the others support.
            length, height: the step's length and height [m].
            knots: the knots in the air.

        Returns:
            (knots, com, feet): the step's knots and impulse, and the centre of mass and the
            feet's positions after it.
        """
        support = [f for f in self.feet if f not in swing]
        fraction, half = len(swing) / len(self.feet), knots / 2
        out = []
        for k in range(knots):
            z = height * k / half if k < half else height * (1 - (k - half) / half)
            dp = np.array([length * (k + 1) / knots, 0.0, z])
            task = [(f, feet[f] + dp) for f in swing]
            out.append(self.knot(support, com + np.array([length * (k + 1) / knots, 0, 0])
                                 * fraction, task))
        out.append(self.impulse(swing, task))
        moved = {f: p + np.array([length, 0.0, 0.0]) if f in swing else p
                 for f, p in feet.items()}
        return out, com + np.array([length * fraction, 0.0, 0.0]), moved

    def problem(self, knots, dt: float, terminal=None) -> Problem:
        """The gait's `Problem` from the standing state, stepped by semi-implicit Euler (as
        Crocoddyl's `IntegratedActionModelEuler`).

        Args:
            knots: the gait's knots and impulses.
            dt: the step [s].
            terminal: the terminal costs; None for the state cost and the bounds.

        Returns:
            The problem.
        """
        terminal = (self.regularisation(), *self.bounds) if terminal is None else terminal
        return Problem(knots, self.q0, jnp.zeros(self.model.nv), dt=dt, terminal=terminal,
                       integrator=SemiImplicitEuler())
