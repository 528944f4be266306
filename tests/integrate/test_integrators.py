"""Integrators and the simulate driver on systems with closed-form solutions."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax.integrate import RK4, ExplicitEuler, ImplicitMidpoint, simulate, solve_reference
from mbjax._src.integrate import INTEGRATORS, AbstractSystem, Status
from mbjax.scenes import heavy_top as top


class Oscillator(AbstractSystem):
    """q_ddot = -k q - c q_dot (vector), a Euclidean system with a closed-form solution."""

    k: jax.Array
    c: float = 0.0

    def kinematics(self, q, u):
        return u

    def acceleration(self, t, q, u):
        return -self.k * q - self.c * u

    def exact(self, q0, u0, t):
        w = jnp.sqrt(self.k)
        return q0 * jnp.cos(w * t) + u0 / w * jnp.sin(w * t)


OSC = Oscillator(k=jnp.array(4.0))
Q0, U0 = jnp.array([1.0, 0.0]), jnp.array([0.0, 2.0])


@pytest.mark.parametrize("name", INTEGRATORS)
def test_convergence_order(name):
    cls = INTEGRATORS[name]
    dts = (0.02, 0.01, 0.005) if cls.order > 1 else (2e-3, 1e-3, 5e-4)
    errors = []
    for dt in dts:
        sol = simulate(OSC, cls(), Q0, U0, dt=dt, t1=2.0, saveat=[2.0])
        errors.append(float(jnp.max(jnp.abs(sol.qs[-1] - OSC.exact(Q0, U0, 2.0)))))
    order = np.polyfit(np.log(dts), np.log(errors), 1)[0]
    assert abs(order - cls.order) < 0.1, (name, order, errors)


@pytest.mark.parametrize("name", INTEGRATORS)
def test_a_known_first_acceleration_changes_no_step(name):
    """A step given the acceleration at its start (`a0`, as a knot that solved its stance for
    its costs passes it) is the step that evaluates it: bitwise for the integrators whose first
    stage is there, and an integrator that has none ignores it."""
    t, dt = jnp.asarray(0.3), jnp.asarray(0.05)
    integrator = INTEGRATORS[name]()
    plain = integrator.step(OSC, t, Q0, U0, dt)
    given = integrator.step(OSC, t, Q0, U0, dt, a0=OSC.acceleration(t, Q0, U0))
    for a, b in zip(plain, given, strict=True):
        np.testing.assert_array_equal(np.asarray(a), np.asarray(b))


def test_explicit_euler_gains_energy_and_midpoint_conserves_it():
    energy = lambda q, u: 0.5 * u @ u + 0.5 * OSC.k * q @ q  # noqa: E731
    E0 = energy(Q0, U0)
    sol = simulate(OSC, ExplicitEuler(), Q0, U0, dt=0.01, t1=10.0, saveat=[10.0])
    growth = energy(sol.qs[-1], sol.vs[-1]) / E0
    # exact growth of explicit Euler for this oscillator: (1 + k dt^2)^n
    np.testing.assert_allclose(growth, (1 + 4.0 * 0.01**2) ** 1000, rtol=1e-10)
    sol = simulate(OSC, ImplicitMidpoint(), Q0, U0, dt=0.1, t1=10.0, saveat=[10.0])
    np.testing.assert_allclose(energy(sol.qs[-1], sol.vs[-1]), E0, rtol=1e-13)


def test_saveat_and_grid():
    sol = simulate(OSC, RK4(), Q0, U0, dt=0.01, t1=1.0)
    assert sol.ts.shape == (101,) and sol.qs.shape == (101, 2)
    part = simulate(OSC, RK4(), Q0, U0, dt=0.01, t1=1.0, saveat=[0.0, 0.3, 0.5, 1.0])
    np.testing.assert_allclose(part.ts, [0.0, 0.3, 0.5, 1.0])
    np.testing.assert_allclose(part.qs, sol.qs[jnp.array([0, 30, 50, 100])], atol=1e-15)
    np.testing.assert_allclose(part.qs[0], Q0)
    with pytest.raises(ValueError, match="step grid"):
        simulate(OSC, RK4(), Q0, U0, dt=0.01, t1=1.0, saveat=[0.005])
    with pytest.raises(ValueError, match="step grid"):
        simulate(OSC, RK4(), Q0, U0, dt=0.01, t1=1.0, saveat=[1.5])
    with pytest.raises(ValueError, match="whole number of steps"):
        simulate(OSC, RK4(), Q0, U0, dt=0.03, t1=1.0)
    with pytest.raises(ValueError, match="positive"):
        simulate(OSC, RK4(), Q0, U0, dt=-0.1, t1=1.0)


def test_status_flags_divergence_and_newton_failure():
    body, q0, u0 = top.build()
    sol = simulate(body, ExplicitEuler(), q0, u0, dt=0.01, t1=10.0, saveat=[10.0])
    # blown up: non-finite at 3.72 s, and the default check saw the steps stop resolving the
    # motion before (the words name both, with their times)
    assert Status(int(sol.status)) == Status.NONFINITE | Status.INACCURATE
    (words,) = sol.messages()
    assert words.startswith("nonfinite (first at t = 3.7") and "do not resolve" in words
    assert float(sol.flagged_at[6]) < float(sol.flagged_at[0]) < 10.0
    sol = simulate(body, ImplicitMidpoint(newton_iterations=1), q0, u0, dt=0.05, t1=1.0,
                   saveat=[1.0])
    assert int(sol.status) & Status.NOT_CONVERGED
    assert "not converged" in sol.messages()[0]
    # Newton converges at dt = 0.05, but the 50 rad/s spin turns 2.5 rad a step: the final
    # quaternion is 1.9 off an RK4 run at dt = 5e-4, and the default check says so
    sol = simulate(body, ImplicitMidpoint(), q0, u0, dt=0.05, t1=1.0, saveat=[1.0])
    assert Status(int(sol.status)) == Status.INACCURATE and "do not resolve" in sol.messages()[0]
    sol = simulate(body, ImplicitMidpoint(), q0, u0, dt=0.01, t1=1.0, saveat=[1.0])
    assert sol.messages() == ["success"]


def test_vmap_over_initial_states_and_parameters():
    q0s = jnp.stack([Q0, 2 * Q0, -Q0])
    run = lambda k, q0: simulate(Oscillator(k=k), RK4(), q0, U0, dt=0.01,  # noqa: E731
                                 t1=1.0, saveat=[1.0]).qs[-1]
    batched = jax.jit(jax.vmap(run))(jnp.array([1.0, 4.0, 9.0]), q0s)
    for i, (k, q0) in enumerate(zip([1.0, 4.0, 9.0], q0s, strict=True)):
        np.testing.assert_allclose(batched[i], run(jnp.array(k), q0), atol=1e-14)


def test_gradient_through_implicit_steps_matches_finite_differences():
    def final(k):
        return simulate(Oscillator(k=k, c=0.3), ImplicitMidpoint(), Q0, U0, dt=0.01, t1=2.0,
                        saveat=[2.0]).qs[-1, 0]

    g = jax.grad(final)(4.0)
    h = 1e-5
    np.testing.assert_allclose(g, (final(4.0 + h) - final(4.0 - h)) / (2 * h), rtol=1e-6)


def test_diffrax_reference():
    ts = jnp.linspace(0.0, 3.0, 7)
    sol = solve_reference(OSC, Q0, U0, ts)
    assert bool(sol.ok)
    np.testing.assert_allclose(sol.qs, jax.vmap(lambda t: OSC.exact(Q0, U0, t))(ts), atol=1e-9)
    failed = solve_reference(OSC, Q0, U0, ts, max_steps=2)
    assert int(failed.status) & Status.SOLVER_FAILED
    for bad in ([0.0, 1.0, 1.0], [1.0, 0.0], [0.0]):
        with pytest.raises(ValueError, match="ts must be at least two increasing times"):
            solve_reference(OSC, Q0, U0, bad)


def test_diffrax_reference_program_holds_no_host_callback():
    """The reference's compiled program can be kept in the persistent compilation cache: no
    host callback (diffrax checks times it saves at inside a solve by callbacks, so the
    reference saves at each interval's end instead)."""
    from mbjax._src.integrate.reference import _solve

    text = _solve.lower(OSC, Q0, U0, jnp.linspace(0.0, 3.0, 7), 1e-10, 1e-10, None,
                        1000).as_text()
    assert "callback" not in text


def test_simplified_newton_steps_over_a_stiff_mode():
    """ImplicitMidpoint(simplified=True) on a slow mode (1 rad/s) coupled to a stiff one
    (1e4 rad/s) through a cubic spring, at dt = 0.01 (the stiff mode's omega dt = 100, 35 times
    RK4's limit): the quadratic energy of the linear part stays bounded (the midpoint rule maps
    the stiff mode onto the unit circle), the slow mode converges at second order to the
    full-Newton midpoint solution's limit, both report convergence, and the two Newton variants
    agree where both converge."""
    class Stiff(Oscillator):
        def acceleration(self, t, q, u):
            return -self.k * q - 0.1 * q[::-1] ** 3

    stiff = Stiff(k=jnp.array([1.0, 1e8]))
    q0, u0 = jnp.array([1.0, 1e-4]), jnp.array([0.0, 0.0])
    simplified = ImplicitMidpoint(simplified=True, newton_iterations=4)
    sol = simulate(stiff, simplified, q0, u0, dt=0.01, t1=5.0)
    # Newton converges; the default check says what is true: the stiff mode's phase is not
    # resolved (it carries half the energy and omega dt = 100)
    assert Status(int(sol.status)) == Status.INACCURATE and float(sol.resolution) > 1.0
    energy = 0.5 * jnp.sum(sol.vs**2 + stiff.k * sol.qs**2, axis=1)
    assert float(jnp.max(energy)) < 1.01 * float(energy[0])
    full = simulate(stiff, ImplicitMidpoint(), q0, u0, dt=0.01, t1=5.0)
    assert Status(int(full.status)) == Status.INACCURATE
    np.testing.assert_allclose(sol.qs, full.qs, atol=1e-9)
    fine = simulate(stiff, simplified, q0, u0, dt=0.00125, t1=5.0, saveat=[5.0]).qs[-1, 0]
    errors = [abs(float(simulate(stiff, simplified, q0, u0, dt=dt, t1=5.0, saveat=[5.0]).qs[-1, 0]
                        - fine)) for dt in (0.01, 0.005)]
    assert 3.0 < errors[0] / errors[1] < 5.0            # second order: 4
