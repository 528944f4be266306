"""`MultipleShooting`: the linear-quadratic slider's optimum in closed form (exact dynamics, so
the knots' defects close and the LQR optimum is reached), with bounds against SciPy's bounded
quasi-Newton (the 7-dof arm's reach against iLQR's optimum: `tests/test_cli.py::
test_reproduce_trajopt`)."""

import numpy as np
from scipy.optimize import minimize

from mbjax.trajopt import MultipleShooting, solve
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
