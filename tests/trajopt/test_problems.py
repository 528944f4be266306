"""The closed-loop and flexible trajectory-optimisation problems, each against an independent
reference: the four-bar's optimum against the same problem written in its one minimal
coordinate (the crank angle; closed-form position analysis and kinetic energy) and solved by
SciPy; the slewing
beam's optimal torque re-simulated on a finer model (twice the modes, a tenth of the step)."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.optimize import least_squares

from mbjax.scenes import four_bar as fb
from mbjax.scenes import slewing_beam as sb
from mbjax.trajopt import ILQR, Problem, solve


@pytest.mark.slow     # 70 s; a closed loop in a Problem: test_crocoddyl and test_ilqr keep the trees
def test_four_bar_matches_its_minimal_coordinate_optimum():
    """The crank's least-effort quarter turn through the closed loop (3 tree coordinates, the
    pin closure projected after each step) against the one-coordinate problem: the crank's
    effective inertia J(theta) from the bars' kinetic energy and the position analysis, Lagrange's
    equation J theta'' + 1/2 J'(theta) theta'^2 = u, the same RK4 step, hold and costs as
    least-squares residuals, solved by MINPACK's Levenberg-Marquardt (SciPy). The two optima
    agree to the discretizations' difference."""
    problem = fb.crank_problem()
    # the solver of `mbjax reproduce trajopt`: one program, compiled once for both (the
    # suite's persistent cache), whichever runs first
    from mbjax_harness.reproduce.trajopt import QUICK_SOLVERS

    result = solve(problem, QUICK_SOLVERS["ilqr"])
    assert result.messages() == ["success"]
    # the trajectory stays on the loop and arrives
    np.testing.assert_allclose(result.qs, jax.vmap(fb.joint_angles)(result.qs[:, 0]), atol=1e-10)
    assert abs(result.qs[-1, 0] - fb.CRANK_GOAL) < 1e-4

    def inertia(theta):
        """The crank's effective inertia: sum over the bars of m |dc/dtheta|^2 + I (da/dtheta)^2
        (c a bar's centre, a its angle, I = m L^2 / 12), planar, from the position analysis."""
        def bars(theta):
            crank, coupler, rocker = fb.joint_angles(theta)
            angles = jnp.array([crank, crank + coupler, rocker])
            pivots = jnp.array([[0.0, 0.0], [fb.A_ * jnp.cos(crank), fb.A_ * jnp.sin(crank)],
                                [fb.D_, 0.0]])
            axes = jnp.stack([jnp.cos(angles), jnp.sin(angles)], 1)
            return angles, pivots + fb.LENGTHS[:, None] / 2 * axes
        rates, velocities = jax.jacfwd(bars)(theta)
        return jnp.sum(fb.MASSES * (jnp.sum(velocities**2, 1) + fb.LENGTHS**2 / 12 * rates**2))

    def f(x, u):
        theta, omega = x
        J, dJ = jax.jvp(inertia, (theta,), (jnp.ones_like(theta),))
        return jnp.array([omega, (u - 0.5 * dJ * omega**2) / J])

    def step(x, u, h=fb.CRANK_DT):
        k1 = f(x, u)
        k2 = f(x + h / 2 * k1, u)
        k3 = f(x + h / 2 * k2, u)
        return x + h / 6 * (k1 + 2 * k2 + 2 * k3 + f(x + h * k3, u))

    def residuals(us):
        x, _ = jax.lax.scan(lambda x, u: (step(x, u), None), jnp.array([fb.THETA0, 0.0]), us)
        return jnp.concatenate([np.sqrt(fb.CRANK_DT) * us, 100.0 * (x[:1] - fb.CRANK_GOAL),
                                10.0 * jax.jacfwd(fb.joint_angles)(x[0]) * x[1]])

    r, J = jax.jit(residuals), jax.jit(jax.jacfwd(residuals))
    reference = least_squares(lambda u: np.asarray(r(u)), np.zeros(problem.horizon),
                              jac=lambda u: np.asarray(J(u)), method="lm", xtol=1e-15, ftol=1e-15,
                              gtol=1e-15)
    assert reference.success
    np.testing.assert_allclose(result.cost, reference.cost, rtol=1e-7)
    np.testing.assert_allclose(result.us[:, 0], reference.x, atol=1e-6 * np.abs(reference.x).max())


@pytest.mark.slow     # 36 s
def test_slewing_beam_suppresses_residual_vibration():
    """The flexible arm's quarter-turn slew: iLQR from the rigid arm's least-effort torque
    arrives at rest with the vibration gone. Re-simulated on a finer model (4 bending modes,
    dt / 10), the optimal torque leaves the tip swinging by less than 1 % of what the rigid
    arm's torque leaves, and the hub within 1e-4 rad of its goal."""
    problem = sb.slew_problem()
    guess = sb.rigid_guess(problem)
    result = solve(problem, ILQR(), guess)
    assert result.messages() == ["success"]
    assert abs(result.qs[-1, 0] - sb.SLEW) < 1e-4

    coarse = sb.slew_problem(n_bending=4)
    fine = Problem(coarse.system, coarse.q0, coarse.v0, dt=sb.DT / 10, horizon=10 * problem.horizon,
                   running=coarse.running, terminal=coarse.terminal)
    optimal, rigid = (fine.rollout(jnp.repeat(us, 10, 0))[-1] for us in (result.us, guess))
    assert abs(optimal[0] - sb.SLEW) < 1e-4
    left, baseline = (sb.residual_vibration(fine, x) for x in (optimal, rigid))
    assert baseline > 1e-2                           # the rigid torque leaves centimetres
    assert left < 1e-2 * baseline
