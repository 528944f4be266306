"""`mbjax._src.trajopt.solve` with `ILQR`: the LQR optimum of a linear problem in closed form, the
box-constrained optimum against SciPy's bounded quasi-Newton, a 7-dof arm's reach (stationary
under the single-shooting gradient), many targets in one vmapped solve, and clear errors."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.optimize import minimize

from mbjax.model import Model
from mbjax.rigid import TreeSystem
from mbjax.scenes import arm as scene
from mbjax.trajopt import ILQR, MultipleShooting, Problem, Shooting, solve

# a 2 kg slider without gravity: x = (q, v), q_ddot = u / m; RK4 with u held over the step is
# exact for it, x_{k+1} = F x_k + G u_k
MASS, DT, N = 2.0, 0.05, 40
F = np.array([[1.0, DT], [0.0, 1.0]])
G = np.array([[DT**2 / (2 * MASS)], [DT / MASS]])
W_X, W_U, W_F = np.diag([1.0, 0.1]), 0.01, np.diag([100.0, 10.0])
GOAL = np.array([1.0, 0.0])


def _slider() -> TreeSystem:
    return TreeSystem(Model([-1], "prismatic", mass=[MASS], inertia=[0.1 * np.eye(3)],
                            axis=[[1.0, 0.0, 0.0]], gravity=(0.0, 0.0, 0.0)))


def _slider_running(q, v, u):
    e = jnp.concatenate([q, v]) - GOAL
    return e @ W_X @ e + W_U * u @ u


def _slider_problem(x0=0.0, running=_slider_running, **bounds) -> Problem:
    def terminal(q, v):
        e = jnp.concatenate([q, v]) - GOAL
        return e @ W_F @ e

    return Problem(_slider(), jnp.reshape(x0, (1,)), [0.0], dt=DT, horizon=N, running=running,
                   terminal=terminal, **bounds)


def _slider_qp():
    """The problem as a quadratic in the controls, 1/2 u^T H u + g^T u + c, built from F and G."""
    Phi = np.vstack([np.linalg.matrix_power(F, k + 1) for k in range(N)])
    Gamma = np.zeros((2 * N, N))
    for k in range(N):
        for j in range(k + 1):
            Gamma[2 * k:2 * k + 2, j] = (np.linalg.matrix_power(F, k - j) @ G)[:, 0]
    weights = np.kron(np.eye(N), W_X * DT)
    weights[-2:, -2:] = W_F                                    # x_N's weight is the terminal one
    offset = Phi @ np.zeros(2) - np.tile(GOAL, N)              # states x_1 ... x_N minus the goal
    H = 2 * (Gamma.T @ weights @ Gamma + W_U * DT * np.eye(N))
    g = 2 * Gamma.T @ weights @ offset
    c = offset @ weights @ offset + GOAL @ W_X @ GOAL * DT      # x_0's running cost
    return H, g, c


def test_a_linear_quadratic_problem_lands_on_the_lqr_optimum():
    result = solve(_slider_problem(), ILQR())
    H, g, c = _slider_qp()
    u = np.linalg.solve(H, -g)
    assert result.messages() == ["success"] and int(result.iterations) <= 3
    np.testing.assert_allclose(np.asarray(result.us[:, 0]), u, rtol=0, atol=1e-9)
    assert abs(float(result.cost) - (0.5 * u @ H @ u + g @ u + c)) < 1e-10
    costs = np.asarray(result.costs)
    assert np.all(np.isnan(costs[int(result.iterations) + 1:]))
    assert np.all(np.diff(costs[:int(result.iterations) + 1]) <= 0)


def test_an_infeasible_start_closes_its_gaps_on_the_lqr_optimum():
    """FDDP's infeasible start (`solve(..., states0=...)`, Mastalli et al. 2020): from states
    far from any rollout, the first iteration's full step closes every gap (a linear-quadratic
    problem's model, the gaps' terms included, is exact: its trajectory is then the rollout of
    its controls), and the iteration ends on the LQR optimum, converged only once feasible.
    The cost history starts at the infeasible guess's own cost."""
    problem = _slider_problem()
    H, g, c = _slider_qp()
    u = np.linalg.solve(H, -g)
    states = jnp.asarray(np.random.default_rng(0).normal(size=(N + 1, 2)))
    first = solve(problem, ILQR(iterations=1), states0=states)
    # not converged after its one iteration, and the message says what to change
    assert first.messages()[0].startswith("not converged (iterations=1 ran out")
    assert "raise ILQR(iterations=...)" in first.messages()[0]
    np.testing.assert_allclose(problem.rollout(first.us),
                               jnp.concatenate([first.qs, first.vs], axis=1), rtol=0, atol=1e-12)
    result = solve(problem, ILQR(), states0=states)
    assert result.messages() == ["success"] and int(result.iterations) <= 4
    np.testing.assert_allclose(np.asarray(result.us[:, 0]), u, rtol=0, atol=1e-9)
    assert abs(float(result.cost) - (0.5 * u @ H @ u + g @ u + c)) < 1e-10
    xs = jnp.concatenate([result.qs, result.vs], axis=1)
    np.testing.assert_array_equal(result.xs, xs)          # the states as Problem takes them
    np.testing.assert_allclose(problem.rollout(result.us), xs, rtol=0, atol=1e-12)
    guess = states.at[0].set(problem.x0)
    assert float(result.costs[0]) == pytest.approx(
        float(problem.cost(guess, jnp.zeros((N, 1)))), rel=1e-14)


def test_control_bounds_give_the_box_constrained_optimum():
    result = solve(_slider_problem(lower=-1.5, upper=1.5), ILQR())
    H, g, c = _slider_qp()
    reference = minimize(lambda u: 0.5 * u @ H @ u + g @ u, np.zeros(N), jac=lambda u: H @ u + g,
                         bounds=[(-1.5, 1.5)] * N, method="L-BFGS-B",
                         options=dict(ftol=1e-15, gtol=1e-12, maxiter=10_000))
    us = np.asarray(result.us[:, 0])
    assert result.messages() == ["success"]
    assert np.all(np.abs(us) <= 1.5) and np.sum(np.isclose(np.abs(us), 1.5)) >= 3
    np.testing.assert_allclose(us, reference.x, atol=1e-6)
    assert abs(float(result.cost) - (reference.fun + c)) < 1e-8


def test_the_arm_reaches_its_target_at_a_stationary_point():
    problem = scene.reach_problem(scene.REACH)           # the arm-reach problem: 0.4 m, 100 steps
    us0 = scene.hold(problem)
    result = solve(problem, ILQR(), us0)
    assert result.messages() == ["success"]
    final = scene.flange(problem.system.model, result.qs[-1])
    target = scene.flange(problem.system.model, problem.q0) + jnp.array([0.0, 0.4, 0.0])
    assert float(jnp.linalg.norm(final - target)) < 1e-5
    assert float(jnp.linalg.norm(result.vs[-1])) < 1e-2
    # the single-shooting gradient (reverse mode through the rollout) vanishes at the optimum
    start = jnp.linalg.norm(jax.grad(problem.objective)(us0))
    assert float(jnp.linalg.norm(jax.grad(problem.objective)(result.us))) < 1e-4 * float(start)
    # the trajectory is the rollout of its controls
    np.testing.assert_allclose(np.asarray(problem.rollout(result.us)[:, :7]),
                               np.asarray(result.qs), atol=1e-12)


@pytest.mark.slow     # 45 s; notebook 11's smoke run solves several targets in one vmapped solve
def test_many_targets_in_one_vmapped_solve():
    offsets = jnp.array([[0.0, 0.2, 0.0], [0.1, 0.0, 0.1], [0.0, -0.15, 0.05]])

    @jax.vmap
    def reach(offset):
        return solve(scene.reach_problem(offset, steps=40), ILQR())

    results = reach(offsets)
    assert results.messages() == ["success"] * 3
    one = solve(scene.reach_problem(offsets[1], steps=40), ILQR(iterations=300))
    np.testing.assert_allclose(np.asarray(results.us[1]), np.asarray(one.us), atol=1e-8)


def test_bad_problems_are_refused_with_the_argument_named():
    system = _slider()
    costs = dict(running=lambda q, v, u: u @ u, terminal=lambda q, v: q @ q)
    with pytest.raises(ValueError, match="horizon"):
        Problem(system, [0.0], [0.0], dt=0.1, horizon=0, **costs)
    with pytest.raises(ValueError, match="dt"):
        Problem(system, [0.0], [0.0], dt=-0.1, horizon=5, **costs)
    with pytest.raises(ValueError, match="lower"):
        Problem(system, [0.0], [0.0], dt=0.1, horizon=5, lower=[1.0, 2.0], **costs)
    with pytest.raises(ValueError, match="lower must not exceed upper"):
        Problem(system, [0.0], [0.0], dt=0.1, horizon=5, lower=1.0, upper=-1.0, **costs)
    with pytest.raises(TypeError, match="mbjax system"):
        Problem(system.model, [0.0], [0.0], dt=0.1, horizon=5, **costs)
    problem = Problem(system, [0.0], [0.0], dt=0.1, horizon=5, **costs)
    with pytest.raises(ValueError, match="us0"):
        solve(problem, ILQR(), jnp.zeros((4, 1)))
    with pytest.raises(TypeError, match="solver"):
        solve(problem, ILQR)
    with pytest.raises(ValueError, match="states0: Shooting starts from the rollout"):
        solve(problem, Shooting(), states0=jnp.zeros((6, 2)))
    with pytest.raises(ValueError, match=r"states0 must be \(horizon \+ 1, nq \+ nv\)"):
        solve(problem, ILQR(), states0=jnp.zeros((5, 2)))
    with pytest.raises(ValueError, match=r"states0 must be \(horizon \+ 1, nq \+ nv\)"):
        solve(problem, MultipleShooting(), states0=jnp.zeros((5, 2)))


@pytest.mark.slow     # 41 s; test_multiple_shooting keeps the LQR optimum
def test_single_shooting_reaches_the_lqr_optimum_and_adam_descends():
    import optax

    from mbjax.trajopt import Shooting, cosine_adam

    H, g, c = _slider_qp()
    optimum = 0.5 * np.linalg.solve(H, -g) @ g + c       # 1/2 u^T H u + g^T u + c at u = -H^-1 g
    lbfgs = solve(_slider_problem(), Shooting(optax.lbfgs()))
    assert lbfgs.messages() == ["success"]
    assert abs(float(lbfgs.cost) - optimum) < 1e-7 * optimum
    adam = solve(_slider_problem(), Shooting(cosine_adam(0.5, 300), iterations=300))
    costs = np.asarray(adam.costs)
    assert costs[-1] < 0.05 * costs[0] and float(adam.cost) > optimum - 1e-12
    with pytest.raises(TypeError, match="optimizer must be an optax optimizer"):
        Shooting("newton")


def test_a_batch_of_problems_through_a_working_set_equals_single_solves():
    """Five starts, two slots: members leave as they converge and the next take their slots;
    bounded and unbounded, every member as its own solve."""
    starts = jnp.linspace(-1.0, 2.0, 5)
    for bounds in ({}, {"lower": -0.4, "upper": 0.4}):
        problems = eqx.filter_vmap(lambda x0, bounds=bounds: _slider_problem(x0, **bounds))(starts)
        batch = solve(problems, ILQR(), width=2)
        assert batch.us.shape == (5, N, 1) and batch.status.shape == (5,)
        for i, x0 in enumerate(starts):
            one = solve(_slider_problem(x0, **bounds), ILQR())
            assert int(batch.iterations[i]) == int(one.iterations)
            np.testing.assert_allclose(batch.us[i], one.us, rtol=1e-9, atol=1e-12)
            assert int(batch.status[i]) == int(one.status) == 0


def test_a_batch_needs_one_first_guess_per_member_and_a_working_set():
    problems = eqx.filter_vmap(_slider_problem)(jnp.zeros(3))
    with pytest.raises(ValueError, match="us0"):
        solve(problems, ILQR(), jnp.zeros((N, 1)))
    for width in (0, 1.5):
        with pytest.raises(ValueError, match="width"):
            solve(problems, ILQR(), width=width)


_TWO_DEVICES = """
import json, sys
import equinox as eqx, jax, jax.numpy as jnp
sys.path.insert(0, sys.argv[1])
jax.config.update("jax_enable_x64", True)
from tests.trajopt.test_ilqr import _slider_problem
from mbjax.trajopt import ILQR, solve
starts = jnp.linspace(-1.0, 2.0, 5)
batch = solve(eqx.filter_vmap(_slider_problem)(starts), ILQR())
ones = [solve(_slider_problem(x0), ILQR()) for x0 in starts]
print(json.dumps({"devices": len(jax.devices()),
                  "us": float(max(jnp.abs(batch.us[i] - one.us).max() for i, one in enumerate(ones))),
                  "iterations": [int(batch.iterations[i]) - int(one.iterations)
                                 for i, one in enumerate(ones)]}))
"""


def test_a_batch_split_over_two_devices_equals_single_solves():
    """Five problems over two CPU devices (padded to six, a working set on each), in a fresh
    process that has them."""
    import json
    import os
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).parents[2]
    env = {**os.environ, "XLA_FLAGS": os.environ.get("XLA_FLAGS", "")
           + " --xla_force_host_platform_device_count=2"}
    out = subprocess.run([sys.executable, "-c", _TWO_DEVICES, str(root)], env=env, cwd=root,
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    result = json.loads(out.stdout.strip().splitlines()[-1])
    assert result["devices"] == 2
    assert result["us"] < 1e-9 and result["iterations"] == [0] * 5


def test_a_cost_undefined_over_part_of_the_controls_is_not_reported_converged():
    """The slider's cost made NaN wherever a control passes 0.5 N (as sqrt(0.5 - u) would):
    the unconstrained optimum lies beyond, so the line search's longer steps meet NaN and the
    accepted short ones change the cost little. That is not convergence: the status says not
    converged and names the non-finite cost, and the cost stays finite; the same problem with
    an ordinary cost converges with success."""
    optimum = solve(_slider_problem(), ILQR())
    assert optimum.messages() == ["success"] and float(jnp.max(optimum.us)) > 0.5
    nan_beyond = _slider_problem(running=lambda q, v, u: _slider_running(q, v, u)
                                 + jnp.where(u[0] > 0.5, jnp.nan, 0.0))
    result = solve(nan_beyond, ILQR(iterations=50))
    assert not bool(result.ok)
    assert "not converged" in result.messages()[0] and "nonfinite" in result.messages()[0]
    assert bool(jnp.isfinite(result.cost)) and float(jnp.max(result.us)) <= 0.5
