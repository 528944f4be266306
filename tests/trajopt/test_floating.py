"""Trajectory optimisation on a floating base: a free rigid body, driven through an actuation
matrix, brought to a pose half a turn away. iLQR and multiple shooting (from an infeasible
state guess; from its rollout in a slow test) reach the same optimum on SE(3); the residual
helpers and the actuation matrix's checks."""

import jax.numpy as jnp
import numpy as np
import pytest

from mbjax.integrate import SemiImplicitEuler
from mbjax.model import Model
from mbjax.rigid import TreeSystem
from mbjax.trajopt import (ILQR, MultipleShooting, Problem, control_residual, frame_residual,
                           solve, state_residual)

BODY = Model([-1], "free", mass=[2.0], inertia=[np.diag([0.1, 0.2, 0.3])],
             gravity=(0.0, 0.0, 0.0))
# four actuators: a torque about each body axis and a force along body x pushing off-centre
S = np.array([[1, 0, 0, 0], [0, 1, 0, 0.2], [0, 0, 1, 0], [0, 0, 0, 1], [0, 0, 0, 0],
              [0, 0, 0, 0]], float)
TARGET_R = np.array([[-1.0, 0, 0], [0, -1, 0], [0, 0, 1]])          # half a turn about z
TARGET_P = np.array([0.5, 0.0, 0.0])


def _problem(horizon=20):
    goal = frame_residual(BODY, "body0", TARGET_P, TARGET_R, weight=100.0)
    return Problem(TreeSystem(BODY, actuation=S), BODY.neutral(), jnp.zeros(6), dt=0.05,
                   horizon=horizon, running=(control_residual(4, weight=1e-2),
                                             state_residual(BODY, BODY.neutral(), weight=1e-4)),
                   terminal=(goal, state_residual(BODY, BODY.neutral(), weight=np.r_[[0.0] * 6,
                                                                                    [1.0] * 6])),
                   integrator=SemiImplicitEuler())


def test_ilqr_and_multiple_shooting_agree_on_se3_with_an_infeasible_start():
    problem = _problem()
    ilqr = solve(problem, ILQR())
    assert ilqr.messages() == ["success"]
    assert ilqr.feedback.shape == (problem.horizon, 4, 12)           # on the tangent space
    assert np.isclose(np.linalg.norm(np.asarray(ilqr.qs[-1, 3:7])), 1.0)   # on the group
    # the pose reached: a half turn (within the regularisation's pull)
    angle = np.linalg.norm(np.asarray(BODY.difference(BODY.neutral(), ilqr.qs[-1]))[:3])
    assert abs(angle - np.pi) < 0.05, angle
    # an infeasible start: the states of a straight slide to the target, not the dynamics'
    s = np.linspace(0.0, 1.0, problem.horizon + 1)[:, None]
    guess = np.concatenate([s * TARGET_P, np.tile([1.0, 0, 0, 0], (len(s), 1)),
                            np.zeros((len(s), 6))], 1)
    warm = solve(problem, MultipleShooting(), states0=guess)
    assert warm.messages() == ["success"]
    np.testing.assert_allclose(warm.cost, ilqr.cost, rtol=1e-6)


@pytest.mark.slow
def test_multiple_shooting_from_its_rollout_agrees_on_se3():
    problem = _problem()
    shooting = solve(problem, MultipleShooting())
    assert shooting.messages() == ["success"]
    np.testing.assert_allclose(shooting.cost, solve(problem, ILQR()).cost, rtol=1e-6)


def test_actuation_matrices_are_checked_by_name():
    with pytest.raises(ValueError, match=r"actuation as a matrix must have shape \(nv, nu\)"):
        TreeSystem(BODY, actuation=np.ones((5, 2)))
    with pytest.raises(ValueError, match="actuation matrix has rank 1 < nu = 2"):
        TreeSystem(BODY, actuation=np.ones((6, 2)))
    with pytest.raises(ValueError, match="actuation matrix must be finite"):
        TreeSystem(BODY, actuation=np.full((6, 1), np.nan))
    system = TreeSystem(BODY, jnp.array([1.0, 2.0, 3.0, 4.0]), actuation=S)
    assert system.n_controls == 4
    np.testing.assert_allclose(system.applied(0.0, BODY.neutral(), jnp.zeros(6)),
                               S @ np.array([1.0, 2.0, 3.0, 4.0]))
    with pytest.raises(ValueError, match="one per actuator"):
        TreeSystem(BODY, lambda t, q, v: jnp.ones(3), actuation=S).applied(
            0.0, BODY.neutral(), jnp.zeros(6))
    with pytest.raises(KeyError):
        frame_residual(BODY, "nowhere", TARGET_P)
    with pytest.raises(TypeError, match="difference"):
        state_residual(object(), BODY.neutral())
