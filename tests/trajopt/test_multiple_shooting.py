"""`MultipleShooting`: the linear-quadratic slider's optimum in closed form (exact dynamics, so
the knots' defects close and the LQR optimum is reached), with bounds against SciPy's bounded
quasi-Newton, and the 7-dof arm's reach against iLQR's optimum of the same problem."""

import numpy as np
from scipy.optimize import minimize

from mbjax.scenes import arm as scene
from mbjax.trajopt import ILQR, MultipleShooting, solve
from tests.trajopt.test_ilqr import N, _slider_problem, _slider_qp


def test_a_linear_quadratic_problem_lands_on_the_lqr_optimum():
    result = solve(_slider_problem(), MultipleShooting())
    H, g, c = _slider_qp()
    u = np.linalg.solve(H, -g)
    assert result.messages() == ["success"]
    np.testing.assert_allclose(np.asarray(result.us[:, 0]), u, rtol=0, atol=1e-7)
    assert abs(float(result.cost) - (0.5 * u @ H @ u + g @ u + c)) < 1e-9


def test_control_bounds_give_the_box_constrained_optimum():
    result = solve(_slider_problem(lower=-1.5, upper=1.5), MultipleShooting(tolerance=1e-12))
    H, g, c = _slider_qp()
    reference = minimize(lambda u: 0.5 * u @ H @ u + g @ u, np.zeros(N), jac=lambda u: H @ u + g,
                         bounds=[(-1.5, 1.5)] * N, method="L-BFGS-B",
                         options={"ftol": 1e-15, "gtol": 1e-12, "maxiter": 10_000})
    assert result.messages() == ["success"]
    # at its defect tolerance the augmented Lagrangian leaves a projected gradient of about
    # 2e-7 (iLQR's: 3e-15), so the free controls next to the clamped ones move by 2e-6
    np.testing.assert_allclose(np.asarray(result.us[:, 0]), reference.x, atol=1e-5)
    assert abs(float(result.cost) - (reference.fun + c)) < 1e-8


def test_arm_reach_reaches_the_ilqr_optimum():
    """The arm's reach from the rolled-out guess: the same optimum as iLQR's (cost to 1e-4,
    relative: the merit's tail is slow and the inner test stops on a relative decrease of 1e-8),
    the flange on the target."""
    problem = scene.reach_problem(steps=40)
    guess = scene.hold(problem)
    result = solve(problem, MultipleShooting(), guess)
    reference = solve(problem, ILQR(), guess)
    assert result.messages() == ["success"]
    np.testing.assert_allclose(float(result.cost), float(reference.cost), rtol=1e-4)
    target = scene.reach_target(problem.system.model)
    assert np.linalg.norm(scene.flange(problem.system.model, result.qs[-1]) - target) < 1e-4
