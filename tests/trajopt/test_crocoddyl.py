"""iLQR against an independent optimal-control library: Crocoddyl's FDDP (analytic derivatives
on Pinocchio) on the arm reach built from the same URDF, residuals, weights, semi-implicit Euler
steps and first guess (`mbjax_harness.crocoddyl.terms.crocoddyl_reach`), and on Crocoddyl's own
contact-free examples (`mbjax_harness.crocoddyl.examples`: the Kinova arm, the double pendulum,
the quadrotor's free base with and without thrust bounds). Skipped where Crocoddyl is not
installed or its pairing with Pinocchio is broken (`crocoddyl_working` says which)."""

import jax.numpy as jnp
import numpy as np
import pytest

from mbjax_harness.crocoddyl.terms import crocoddyl_working
from mbjax_harness.bench.trajopt import arm_reach
from mbjax_harness.crocoddyl.solver import CrocoddylSolver
from mbjax.trajopt import ILQR, solve
from mbjax._src.trajopt.ilqr import CROCODDYL_SCHEDULE

WHY = crocoddyl_working()
pytestmark = pytest.mark.skipif(WHY is not None, reason=str(WHY))


@pytest.mark.parametrize("schedule", [{}, CROCODDYL_SCHEDULE], ids=["default", "crocoddyl"])
def test_arm_reach_matches_crocoddyl(schedule):
    """One problem in two libraries: the first guess's rollout and cost agree to rounding, and
    the two solvers' optima agree (iLQR with its default globalization and with Crocoddyl's):
    cost to 1e-6 (relative), controls to 1e-3 of their largest, both flanges on the target."""
    problem, us0, final_error, build = arm_reach()
    croc_problem, _ = build()
    croc = CrocoddylSolver(croc_problem, us0)
    xs = np.asarray(problem.rollout(jnp.asarray(us0)))
    np.testing.assert_allclose(np.array(croc_problem.rollout(croc.us0)), xs, atol=1e-9)
    np.testing.assert_allclose(croc_problem.calc(list(xs), croc.us0),
                               problem.cost(jnp.asarray(xs), jnp.asarray(us0)), rtol=1e-12)

    result = solve(problem, ILQR(**schedule), us0)
    assert result.messages() == ["success"]
    assert croc.solve(200)
    np.testing.assert_allclose(result.cost, croc.solver.cost, rtol=1e-6)
    us = np.array(croc.solver.us)
    np.testing.assert_allclose(np.asarray(result.us), us, atol=1e-3 * np.abs(us).max())
    # both reach the target; the final joint angles differ by about 2e-4 rad along the
    # redundant arm's self-motion, which only the 1e-4 state regularization prices
    assert final_error(result.qs[-1]) < 1e-5
    assert final_error(jnp.asarray(croc.solver.xs[-1])[:problem.nq]) < 1e-5


# -- Crocoddyl's own contact-free examples (`mbjax_harness.crocoddyl.examples`) --------------------

@pytest.mark.parametrize("name", [
    "double-pendulum", "quadrotor",
    pytest.param("kinova-reach", marks=pytest.mark.slow),
    pytest.param("quadrotor-bounded", marks=pytest.mark.slow)])
def test_crocoddyls_examples_reach_fddps_optimum(name):
    """The same problem in both libraries (each of Crocoddyl's steps from the guess's mbjax
    rollout lands on mbjax's next state: semi-implicit Euler on SE(3) for the quadrotor's free
    base; the guess costs the same), and iLQR from the same first guess ends within 1e-6
    (relative) of FDDP's optimum or below it, each engine pricing the other's solution as it
    does."""
    from mbjax_harness.crocoddyl.solver import agreement
    from mbjax_harness.crocoddyl.examples import EXAMPLES

    example = EXAMPLES[name]()
    croc_problem = example.crocoddyl()
    checks = agreement(example, croc_problem)
    assert checks["one_step_agreement"] < 1e-12 and checks["cost_agreement"] < 1e-12, checks
    result = solve(example.problem, ILQR(), jnp.asarray(example.us0))
    assert result.messages() == ["success"]
    croc = CrocoddylSolver(croc_problem, example.us0, example.solver)
    croc.solve(200)
    assert float(result.cost) <= croc.solver.cost * (1 + 1e-6), (float(result.cost),
                                                                 croc.solver.cost)
    us = [np.asarray(u) for u in result.us]
    np.testing.assert_allclose(croc_problem.calc(croc_problem.rollout(us), us), result.cost,
                               rtol=1e-10)
    np.testing.assert_allclose(example.problem.objective(jnp.asarray(np.array(croc.solver.us))),
                               croc.solver.cost, rtol=1e-8)
