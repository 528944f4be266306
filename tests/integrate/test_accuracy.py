"""The accuracy status (issue 23): `simulate(..., rtol=, atol=)` estimates the final state's
error by step doubling at sampled states and flags INACCURATE past the tolerance. Checked
against the true error (a run at dt = 1e-4), its order, and the flag on both sides."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax import simulate
from mbjax.integrate import RK4, Status
from mbjax.model.builders import chain
from mbjax.rigid import TreeSystem

SYSTEM = TreeSystem(chain(3))
Q0, V0 = jnp.array([0.8, -0.4, 0.3]), jnp.zeros(3)
T1 = 2.0


@pytest.fixture(scope="module")
def reference():
    sol = simulate(SYSTEM, RK4(), Q0, V0, dt=1e-4, t1=T1, saveat=[T1])
    return jnp.concatenate([sol.qs[-1], sol.us[-1]])


def test_rk4_estimate_follows_the_true_error_and_its_order(reference):
    estimates, errors = [], []
    for dt in (0.04, 0.02, 0.01):
        sol = simulate(SYSTEM, RK4(), Q0, V0, dt=dt, t1=T1, saveat=[T1], rtol=1e-6, atol=1e-6)
        estimates.append(float(sol.error))
        errors.append(float(jnp.max(jnp.abs(jnp.concatenate([sol.qs[-1], sol.us[-1]])
                                            - reference))))
    for estimate, error in zip(estimates, errors, strict=True):
        assert error / 10 < estimate < 10 * error, (estimates, errors)
    # fourth order: halving dt divides the estimate by about 16
    assert all(8 < a / b < 40 for a, b in zip(estimates, estimates[1:])), estimates


def test_the_status_says_inaccurate_past_the_tolerance_only():
    coarse = simulate(SYSTEM, RK4(), Q0, V0, dt=0.05, t1=T1, rtol=0.0, atol=1e-3)
    fine = simulate(SYSTEM, RK4(), Q0, V0, dt=0.005, t1=T1, rtol=0.0, atol=1e-3)
    assert coarse.messages() == ["inaccurate"] and not bool(coarse.ok)
    assert Status(int(coarse.status)) == Status.INACCURATE and float(coarse.error) > 1e-3
    assert fine.messages() == ["success"] and bool(fine.ok) and float(fine.error) < 1e-3
    plain = simulate(SYSTEM, RK4(), Q0, V0, dt=0.05, t1=T1)        # no tolerance: no estimate
    assert plain.messages() == ["success"] and np.isnan(plain.error)


def test_estimate_under_vmap_and_bad_tolerances():
    q0s = jnp.stack([Q0, 0.5 * Q0])
    sols = jax.vmap(lambda q0: simulate(SYSTEM, RK4(), q0, V0, dt=0.05, t1=T1, rtol=0.0,
                                        atol=1e-3))(q0s)
    assert sols.error.shape == (2,) and np.all(np.isfinite(sols.error))
    one = simulate(SYSTEM, RK4(), q0s[1], V0, dt=0.05, t1=T1, rtol=0.0, atol=1e-3)
    np.testing.assert_allclose(sols.error[1], one.error, rtol=1e-12)
    for rtol, atol in ((0.0, 0.0), (-1.0, 1e-3), (np.nan, 1e-3)):
        with pytest.raises(ValueError, match="rtol"):
            simulate(SYSTEM, RK4(), Q0, V0, dt=0.05, t1=T1, rtol=rtol, atol=atol)


def test_throw_raises_the_failure_by_name_also_under_vmap():
    import equinox as eqx

    with pytest.raises(eqx.EquinoxRuntimeError, match="mbjax.simulate: .*status inaccurate"):
        simulate(SYSTEM, RK4(), Q0, V0, dt=0.05, t1=T1, rtol=0.0, atol=1e-3, throw=True)
    with pytest.raises(eqx.EquinoxRuntimeError, match="status nonfinite"):
        jax.vmap(lambda q0: simulate(SYSTEM, RK4(), q0, V0, dt=0.05, t1=T1, throw=True))(
            jnp.stack([Q0, jnp.full(3, jnp.nan)]))
    fine = simulate(SYSTEM, RK4(), Q0, V0, dt=0.005, t1=T1, rtol=0.0, atol=1e-3, throw=True)
    assert fine.messages() == ["success"]



def test_the_reference_solver_and_time_elements_throw_too():
    """solve_reference stopped by max_steps, and a time-element march whose Newton iteration
    cannot converge in one iteration, raise by name with throw=True."""
    import equinox as eqx

    from mbjax.integrate import solve_reference
    from mbjax.scenes import torque_free_body as tfb
    from mbjax.tfe import Body, initial_state, solve_tfe

    ts = jnp.linspace(0.0, 0.5, 3)
    with pytest.raises(eqx.EquinoxRuntimeError, match="solve_reference: .*solver failed"):
        solve_reference(SYSTEM, Q0, V0, ts, max_steps=2, throw=True)
    assert solve_reference(SYSTEM, Q0, V0, ts, max_steps=2).messages() == ["solver failed"]
    body = Body(1.0, jnp.diag(jnp.array([tfb.J_TRANSVERSE, tfb.J_TRANSVERSE, tfb.J_AXIAL])))
    state0 = initial_state(body, jnp.eye(3), jnp.array(tfb.OMEGA0))
    with pytest.raises(eqx.EquinoxRuntimeError, match="solve_tfe: .*not converged"):
        solve_tfe(body, state0, dt=0.2, n_elements=2, max_iter=1, throw=True)
