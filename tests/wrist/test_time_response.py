"""The Carpal Wrist's time response (Canfield 1997 §6.4): the chapter's scheme, energy conservation,
convergence order, and stability exactly where each method's linearization says it fails."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax.integrate import RK4, ExplicitEuler, simulate
from mbjax._src.integrate import INTEGRATORS
from mbjax_harness.reproduce.carpal_wrist import QUICK_STEPS, linear_critical_steps, masked_rollout
from mbjax.scenes import carpal_wrist as cw


def test_explicit_euler_is_the_chapters_eq_6_45():
    system, q0, u0 = cw.servo()
    dt = 0.01
    q1, u1, _ = ExplicitEuler().step(system, 0.0, q0, u0 + 0.3, dt)
    a = system.model.forward_dynamics(q0, u0 + 0.3, system.torques(0.0, q0, u0 + 0.3))
    np.testing.assert_allclose(q1, q0 + (u0 + 0.3) * dt, rtol=0, atol=1e-15)
    np.testing.assert_allclose(u1, u0 + 0.3 + a * dt, rtol=0, atol=1e-13)


def test_energy_is_conserved_and_rk4_converges_at_order_four():
    system, q0, u0 = cw.free_motion()
    T = cw.FREE_DURATION
    E0 = system.model.energy(q0, u0)
    ends, drifts = [], []
    for dt in (0.02, 0.01, 0.005):
        sol = simulate(system, RK4(), q0, u0, dt=dt, t1=T, saveat=np.linspace(0, T, 11))
        assert sol.messages() == ["success"]
        E = jax.jit(jax.vmap(system.model.energy))(sol.qs, sol.vs)
        drifts.append(float(jnp.max(jnp.abs(E - E0)) / E0))
        ends.append(np.asarray(sol.qs[-1]))
    ref = np.asarray(simulate(system, RK4(), q0, u0, dt=1e-3, t1=T, saveat=[T]).qs[-1])
    errors = [np.abs(e - ref).max() for e in ends]
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(orders - 4) < 0.3), orders
    assert drifts[-1] < 1e-10 and drifts[0] / drifts[-1] > 100
    # the motion stays well inside the workspace (the study is not near a singularity)
    m = jax.jit(jax.vmap(system.model.singularity_measures))(sol.qs)
    assert float(m.inverse.min()) > 0.5 and float(m.direct.min()) > 0.9


@pytest.mark.slow     # the quick tour checks explicit Euler against RK4 by default
def test_stability_boundaries_match_the_linearization():
    """Explicit Euler (eq 6.45) fails first: between 5 and 10 ms, where semi-implicit Euler, RK4
    and implicit midpoint are stable; semi-implicit Euler fails between 10 and 20 ms, RK4 between
    20 and 40 ms, implicit midpoint never. The measured boundaries bracket the critical steps of each
    method's amplification matrix about the servo's equilibrium."""
    system, q0, u0 = cw.servo()
    law = system.control
    critical = linear_critical_steps(system, law.q_ref, jnp.zeros(3))
    assert 0.005 < critical["explicit_euler"] < 0.01
    assert 0.01 < critical["semi_implicit_euler"] < 0.02
    assert 0.02 < critical["rk4"] < 0.04
    assert critical["implicit_midpoint"] is None

    def servo_energy(q, u):
        e = q - law.q_ref
        return 0.5 * law.kp * e @ e + 0.5 * u @ system.model.mass_matrix(q) @ u

    energies = jax.jit(jax.vmap(servo_energy))
    E0 = float(jax.jit(servo_energy)(q0, u0))
    dts = QUICK_STEPS       # 2, 5, 10, 20, 40 ms: the tour's and notebook 06's runs (one compilation)
    expected = {"explicit_euler": (True, True, False, False, False),
                "semi_implicit_euler": (True, True, True, False, False),
                "rk4": (True, True, True, True, False), "implicit_midpoint": (True,) * 5}
    for name, stable in expected.items():
        q, u, _ = masked_rollout(system, INTEGRATORS[name](), q0, u0, dts, cw.SERVO_DURATION, lambda q, u: 0.0)
        E = np.asarray(energies(q, u))
        measured = tuple(bool(np.isfinite(e) and e < E0) for e in E)
        assert measured == stable, (name, E / E0)
        # clear verdicts: the stable runs lose at least 95 % of the energy in the second (explicit
        # Euler at 5 ms, near its 6.7 ms boundary, the least: its anti-damping eats into the
        # servo's), the unstable ones overflow or gain tenfold
        for e, s in zip(E, stable):
            assert (e < 0.05 * E0) if s else not (e < 10 * E0)
