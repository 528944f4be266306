"""The accuracy status (issue 23): `simulate(..., rtol=, atol=)` estimates the final state's
error by step doubling at sampled states and flags INACCURATE past the tolerance. Checked
against the true error (a run at dt = 1e-4), its order, and the flag on both sides."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax import simulate
from mbjax.integrate import RK4
from mbjax._src.integrate import Status
from mbjax._src.model.builders import chain
from mbjax.rigid import TreeSystem

SYSTEM = TreeSystem(chain(3))
Q0, V0 = jnp.array([0.8, -0.4, 0.3]), jnp.zeros(3)
T1 = 2.0


@pytest.fixture(scope="module")
def reference():
    sol = simulate(SYSTEM, RK4(), Q0, V0, dt=1e-4, t1=T1, saveat=[T1])
    return jnp.concatenate([sol.qs[-1], sol.vs[-1]])


def test_rk4_estimate_follows_the_true_error_and_its_order(reference):
    estimates, errors = [], []
    for dt in (0.04, 0.02, 0.01):
        sol = simulate(SYSTEM, RK4(), Q0, V0, dt=dt, t1=T1, saveat=[T1], rtol=1e-6, atol=1e-6)
        estimates.append(float(sol.error))
        errors.append(float(jnp.max(jnp.abs(jnp.concatenate([sol.qs[-1], sol.vs[-1]])
                                            - reference))))
    for estimate, error in zip(estimates, errors, strict=True):
        assert error / 10 < estimate < 10 * error, (estimates, errors)
    # fourth order: quartering dt divides the estimate by about 256 (the sampled states differ
    # between step sizes, so a single halving's ratio wanders: 21 and 6.5 measured)
    assert 64 < estimates[0] / estimates[-1] < 1024, estimates


def test_the_status_says_inaccurate_past_the_tolerance_only():
    coarse = simulate(SYSTEM, RK4(), Q0, V0, dt=0.05, t1=T1, rtol=0.0, atol=1e-3)
    fine = simulate(SYSTEM, RK4(), Q0, V0, dt=0.005, t1=T1, rtol=0.0, atol=1e-3)
    assert coarse.messages()[0].startswith("inaccurate (estimated error") and not bool(coarse.ok)
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


# -- the invariants' drift -------------------------------------------------------------------------

def _energy_drift(system, sol):
    """The energy's largest change over the run relative to the largest kinetic energy, from the
    system's energy functions directly."""
    E = jax.vmap(system.energy)(sol.qs, sol.vs)
    T = jax.vmap(system.kinetic_energy)(sol.qs, sol.vs)
    return float(jnp.max(jnp.abs(E - E[0])) / jnp.max(T))


def test_energy_drift_flags_what_a_loose_step_doubling_tolerance_lets_through():
    """Explicit Euler on the triple pendulum gains energy (about 17 % of its kinetic energy
    here); with atol = 10 the step-doubling estimate passes, the energy's drift does not."""
    from mbjax.integrate import ExplicitEuler

    sol = simulate(SYSTEM, ExplicitEuler(), Q0, V0, dt=0.005, t1=T1, rtol=1e-3, atol=10.0)
    assert float(sol.drift) == pytest.approx(_energy_drift(SYSTEM, sol), rel=1e-12)
    assert float(sol.drift) > 0.1
    assert sol.messages() == ["inaccurate (the energy drifted by 0.168 of its scale; first at "
                              "t = 0.02 s)"]
    # step doubling alone passes it (rtol = 0: the drift is reported, not held to anything)
    alone = simulate(SYSTEM, ExplicitEuler(), Q0, V0, dt=0.005, t1=T1, rtol=0.0, atol=10.0)
    assert alone.messages() == ["success"] and float(alone.drift) > 0.1
    fine = simulate(SYSTEM, RK4(), Q0, V0, dt=0.005, t1=T1, rtol=1e-3, atol=10.0)
    assert float(fine.drift) < 1e-6 and fine.messages() == ["success"]
    assert float(fine.drift) == pytest.approx(_energy_drift(SYSTEM, fine), rel=1e-6)


def test_damped_energy_may_fall_but_not_rise():
    import equinox as eqx

    damped = TreeSystem(eqx.tree_at(lambda m: m.damping, SYSTEM.model, jnp.full(3, 0.5)))
    sol = simulate(damped, RK4(), Q0, V0, dt=0.005, t1=T1, rtol=1e-4, atol=1e-4)
    assert _energy_drift(damped, sol) > 0.1             # the damping has taken energy out
    assert float(sol.drift) < 1e-7 and sol.messages() == ["success"]


def test_momentum_of_a_floating_tree_with_and_without_gravity():
    """A free base carrying two hinged links: H along gravity and P - M g t are conserved (all
    of H without gravity); RK4's drift falls at fourth order, and a wrong weight impulse would
    be seen (M g t = 29 N s at t = 1 s)."""
    import equinox as eqx

    from mbjax._src.rigid.energy import free_momenta

    model = chain(3, joint_types=("free", "revolute", "revolute"))
    q0 = model.neutral()
    v0 = jnp.array([0.3, -0.2, 0.5, 0.1, 0.2, 0.3, 1.0, -2.0])
    for gravity in (model.gravity, jnp.zeros(3)):
        system = TreeSystem(eqx.tree_at(lambda m: m.gravity, model, gravity))
        drifts = []
        for dt in (0.02, 0.01):
            sol = simulate(system, RK4(), q0, v0, dt=dt, t1=1.0, rtol=1e-6, atol=1e-6)
            moments = jax.vmap(lambda t, q, v: free_momenta(system.model, t, q, v))(
                sol.ts, sol.qs, sol.vs)
            change = jnp.max(jnp.abs(moments.values - moments.values[0]))
            drifts.append(float(change / jnp.max(moments.scale)))
            assert float(sol.drift) >= drifts[-1] * (1 - 1e-9)   # the energy's drift joins it
        assert 8 < drifts[0] / drifts[1] < 40, drifts
        assert drifts[1] < 1e-6
    # the momentum form (u = M v) has the same invariants, at its velocities
    from mbjax.rigid import MomentumSystem

    momentum = MomentumSystem(model)
    sol = simulate(momentum, RK4(), q0, TreeSystem(model).mass_matrix(q0) @ v0, dt=0.01, t1=1.0,
                   rtol=1e-6, atol=1e-6)
    assert 0 < float(sol.drift) < 1e-6, float(sol.drift)
    # the gravity terms are right: without `- M g t`, P changes by the weight's impulse
    sol = simulate(TreeSystem(model), RK4(), q0, v0, dt=0.01, t1=1.0)
    P = jax.vmap(lambda q, v: free_momenta(model, 0.0, q, v).values[3:])(sol.qs, sol.vs)
    np.testing.assert_allclose(P[-1] - P[0], jnp.sum(model.mass) * model.gravity * 1.0,
                               rtol=1e-6, atol=1e-7)


def test_no_invariant_under_a_control_and_the_closed_loop_energy():
    from mbjax.scenes import four_bar

    driven = TreeSystem(SYSTEM.model, jnp.ones(3))
    sol = simulate(driven, RK4(), Q0, V0, dt=0.01, t1=0.5, rtol=1e-3, atol=1e-3)
    assert np.isnan(sol.drift) and driven.invariants(0.0, Q0, V0) is None
    system, q0, u0 = four_bar.build()
    sol = simulate(system, RK4(), q0, u0, dt=0.002, t1=0.5, rtol=1e-3, atol=1e-3)
    assert 0 <= float(sol.drift) < 1e-3, float(sol.drift)


def test_a_rigid_body_s_energy_and_momenta():
    """A tumbling free body under gravity: its energy, H along gravity and m (v - g t) are
    conserved, RK4's drift of them falls at fourth order; a control removes them."""
    from mbjax.rigid import RigidBody

    body = RigidBody(2.0, jnp.diag(jnp.array([0.1, 0.2, 0.3])))
    q0, u0 = body.initial_state(jnp.eye(3), (0.3, 4.0, 0.2), v0=(1.0, 0.0, 2.0))
    drifts = [float(simulate(body, RK4(), q0, u0, dt=dt, t1=2.0, rtol=1e-6, atol=1e-6).drift)
              for dt in (0.02, 0.01)]
    assert 8 < drifts[0] / drifts[1] < 40 and drifts[1] < 1e-5, drifts
    invariants = body.invariants(1.5, q0, u0)
    np.testing.assert_allclose(invariants.values[-3:], 2.0 * (u0[3:] - body.gravity * 1.5))
    assert RigidBody(2.0, jnp.eye(3), control=jnp.ones(6)).invariants(0.0, q0, u0) is None


def test_the_status_follows_the_true_error_over_random_starts():
    """Hypothesis over the triple pendulum's start (angles to 1.5 rad, rates to 3 rad/s), RK4 at
    dt = 0.05 s for 1 s held to atol = 1e-3: a run whose true final error (against dt = 2.5 ms,
    in the tolerance's norm) is 10 times past the tolerance is never called a success, and one
    10 times inside it never inaccurate. The states are traced, so every example reuses one
    compilation."""
    from hypothesis import given, settings
    from hypothesis import strategies as st

    tolerance = {"rtol": 0.0, "atol": 1e-3}

    @jax.jit
    def runs(q0, v0):
        coarse = simulate(SYSTEM, RK4(), q0, v0, dt=0.05, t1=1.0, saveat=[1.0], **tolerance)
        fine = simulate(SYSTEM, RK4(), q0, v0, dt=0.0025, t1=1.0, saveat=[1.0])
        error = jnp.concatenate([coarse.qs[-1] - fine.qs[-1], coarse.vs[-1] - fine.vs[-1]])
        return coarse.status, jnp.sqrt(jnp.mean((error / tolerance["atol"]) ** 2))

    seen = set()

    @settings(max_examples=30, deadline=None)
    @given(st.lists(st.floats(-1.5, 1.5), min_size=3, max_size=3),
           st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3))
    def check(q0, v0):
        status, ratio = runs(jnp.asarray(q0), jnp.asarray(v0))
        if float(ratio) > 10:
            assert int(status) & Status.INACCURATE, (q0, v0, float(ratio))
            seen.add("inaccurate")
        elif float(ratio) < 0.1:
            assert int(status) == 0, (q0, v0, float(ratio))
            seen.add("success")

    check()
    assert seen == {"inaccurate", "success"}          # both sides were exercised
