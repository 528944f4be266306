"""The solvers of mbjax.loops beyond the velocity form: Jerkovsky 1978's momentum form (eqs 95-98),
Anderson 1993's loads from one triangularization (eqs 101-107), projection after every step, the
status flags, consistent initial conditions and the epsilon-dynamics with position feedback."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax import Dense
from mbjax.integrate import RK4, simulate
from mbjax._src.integrate import Status
from mbjax._src.model.closures import GROUND
from mbjax.loops import ClosedSystem, Coupled, CutJoint, Loops, Momentum, Prescribed, Stabilized, consistent_state
from mbjax.loops import Spherical
from mbjax._src.loops import coupled_acceleration, eta_and_gamma, loop_momentum_rate
from mbjax.rigid import TreeSystem
from mbjax._src.rigid.dynamics import forward_dynamics, mass_matrix
from mbjax.scenes import closed_chain

CHAIN, Q0, V0 = closed_chain.build(6)           # 3 links, 6 dof, 4 closure equations: 2 dof
TAU = jnp.array([0.3, -0.2, 0.1, 0.4, -0.1, 0.2])
MODEL = CHAIN.tree.model
TREE = TreeSystem(MODEL, TAU)
LOOPS = Loops(TREE, CHAIN.closures)


def test_momentum_form_multipliers_equal_the_velocity_forms():
    """Eq 98 (momentum form) and eq 92 (velocity form) give the same multipliers (eq 99), and
    G_dot = d/dt (mu v) = mu v_dot + mu_dot v."""
    @jax.jit                  # one compilation (op-by-op dispatch of the passes takes far longer)
    def both_forms(q, v):
        v_dot, K_c, _ = coupled_acceleration(LOOPS, q, v)
        mu = mass_matrix(MODEL, q)
        G_dot, K_c_momentum, rank = loop_momentum_rate(LOOPS, q, mu @ v)
        mu_dot = jax.jvp(lambda q_: mass_matrix(MODEL, q_), (q,), (MODEL.q_dot(q, v),))[1]
        return v_dot, K_c, mu, G_dot, K_c_momentum, rank, mu_dot

    v_dot, K_c, mu, G_dot, K_c_momentum, rank, mu_dot = both_forms(Q0, V0)
    np.testing.assert_allclose(K_c_momentum, K_c, rtol=1e-10, atol=1e-10 * np.abs(K_c).max())
    np.testing.assert_allclose(G_dot, mu @ v_dot + mu_dot @ V0, atol=1e-10 * np.abs(G_dot).max())
    assert int(rank) == LOOPS.m


def test_momentum_form_follows_the_same_motion():
    """Two discretizations of one motion: RK4 on (q, G) and on (q, v) agree to O(dt^4)."""
    system = ClosedSystem(TREE, CHAIN.closures, Momentum())
    ts = np.linspace(0.0, 0.2, 5)
    momentum = simulate(system, RK4(), Q0, system.initial_state(Q0, V0), dt=1e-3, t1=0.2, saveat=ts)
    velocity = simulate(ClosedSystem(TREE, CHAIN.closures), RK4(), Q0, V0, dt=1e-3, t1=0.2, saveat=ts)
    assert momentum.messages() == velocity.messages() == ["success"]
    np.testing.assert_allclose(momentum.qs, velocity.qs, atol=1e-9)
    v_end = jax.jit(jax.vmap(system.velocity))(momentum.qs, momentum.vs)
    np.testing.assert_allclose(v_end, velocity.vs, atol=1e-8)


def test_one_triangularization_gives_the_unit_load_responses():
    """eta and the columns of Gamma (Anderson 1993 eqs 101-107) against the dense forward dynamics,
    Gamma under the rows of A with no gravity and no velocity."""
    @jax.jit
    def loads_and_dense(q, v):
        eta, Gamma, A = eta_and_gamma(LOOPS, q, v)
        unloaded = eqx.tree_at(lambda m: m.gravity, MODEL, jnp.zeros(3))
        dense = jax.vmap(lambda load: forward_dynamics(unloaded, q, jnp.zeros(6), load,
                                                       method=Dense()))(A).T
        return eta, Gamma, forward_dynamics(MODEL, q, v, TAU, method=Dense()), dense

    eta, Gamma, eta_dense, dense = loads_and_dense(Q0, V0)
    np.testing.assert_allclose(eta, eta_dense, rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(Gamma, dense, rtol=1e-10, atol=1e-10 * np.abs(dense).max())


def test_projection_after_every_step_holds_a_driven_loop_on_its_constraints():
    """The chain's first joint driven at 2 rad/s (a rheonomic closure) and projected after
    every step: |Phi| and |A v + B| stay at round-off, where the unprojected run drifts past the
    (deliberately tight) tolerance and says so in its status."""
    drive = Prescribed(0, q0=Q0[0], rate=2.0)
    closures = [*CHAIN.closures, drive]
    projected_system = ClosedSystem(TREE, closures, projection=True, tolerance=1e-10)
    q0, v0 = consistent_state(projected_system, Q0, V0)
    ts = np.linspace(0.0, 0.3, 7)
    projected = simulate(projected_system, RK4(), q0, v0, dt=2e-3, t1=0.3, saveat=ts)
    assert projected.messages() == ["success"]
    loops = projected_system.loops
    phi = jax.jit(jax.vmap(loops.phi))(projected.qs, projected.ts)
    rate = jax.jit(jax.vmap(loops.rate))(projected.qs, projected.vs, projected.ts)
    assert float(jnp.abs(phi).max()) < 1e-10 and float(jnp.abs(rate).max()) < 1e-10
    free = simulate(ClosedSystem(TREE, closures, tolerance=1e-10), RK4(), q0, v0, dt=2e-3,
                    t1=0.3, saveat=ts)
    assert free.messages()[0].startswith("constraint violated (first at t = ") and not bool(free.ok)
    assert Status(int(free.status)) == Status.CONSTRAINT_VIOLATED


def test_inconsistent_initial_conditions_are_projected_or_rejected():
    q_bad, v_bad = Q0 + 0.02, V0 + 0.3
    q, v = consistent_state(CHAIN, q_bad, v_bad)
    assert float(jnp.abs(LOOPS.phi(q)).max()) < 1e-10
    assert float(jnp.abs(LOOPS.rate(q, v)).max()) < 1e-10
    with pytest.raises(ValueError, match="violates the loop closures"):
        consistent_state(CHAIN, q_bad, v_bad, project=False)
    same_q, same_v = consistent_state(LOOPS, q, v, project=False)   # consistent: unchanged
    np.testing.assert_array_equal(same_q, q)
    np.testing.assert_array_equal(same_v, v)
    too_far = ClosedSystem(TREE, [CutJoint(Spherical(), 2, GROUND, origin_a=(0.0, 0.0, -0.3),
                                           origin_b=(5.0, 0.0, 0.0))])   # the chain is 0.9 m
    with pytest.raises(ValueError, match="cannot be projected"):
        consistent_state(too_far, Q0, V0)
    with pytest.raises(ValueError, match="shapes"):
        consistent_state(CHAIN, Q0[:3], V0)
    with pytest.raises(ValueError, match="non-finite"):
        consistent_state(CHAIN, Q0.at[0].set(jnp.nan), V0)


def test_bad_system_parameters():
    with pytest.raises(ValueError, match=r"tau\) must have shape"):
        TreeSystem(MODEL, jnp.zeros(3))
    with pytest.raises(ValueError, match="baumgarte"):
        Coupled(baumgarte=(-1.0, 0.0))
    with pytest.raises(ValueError, match="set epsilon"):
        Stabilized(kappa=1.0)
    with pytest.raises(TypeError, match="callable"):
        TreeSystem(MODEL, "three")
    with pytest.raises(TypeError, match="an instance"):
        ClosedSystem(TREE, CHAIN.closures, method=Coupled)
    with pytest.raises(TypeError, match="TreeSystem"):
        ClosedSystem(MODEL, CHAIN.closures)
    with pytest.raises(ValueError, match="already has its control"):
        ClosedSystem(TREE, CHAIN.closures, control=TAU)


def test_epsilon_dynamics_with_position_feedback_keeps_its_invariant():
    """epsilon f_c_dot = A u_dot + b + kappa (A u + B) integrates to
    A u + B + kappa Phi - epsilon f_c = const: the position error is bounded by the loads."""
    eps, kappa = 0.5, 5.0
    system = ClosedSystem(TREE, CHAIN.closures, Stabilized(epsilon=eps, kappa=kappa))
    u0 = system.initial_state(Q0, V0, consistent=True)
    sol = simulate(system, RK4(), Q0, u0, dt=1e-3, t1=0.5, saveat=np.linspace(0.0, 0.5, 6))

    def invariant(q, u):
        return LOOPS.rate(q, u[:6]) + kappa * LOOPS.phi(q) - eps * u[6:]

    values = jax.jit(jax.vmap(invariant))(sol.qs, sol.vs)
    np.testing.assert_allclose(values, values[0] + 0 * values, atol=1e-8 * np.abs(values).max())


def test_baumgarte_gives_the_constraint_its_error_dynamics():
    """Coupled(baumgarte=(alpha, beta)) makes Phi_ddot + 2 alpha Phi_dot + beta^2 Phi = 0 at any
    state, on the manifold or off it: Phi's time derivatives taken here by forward-mode autodiff
    of Phi along the motion, not from the method's A and b."""
    alpha, beta = 10.0, 7.0
    system = ClosedSystem(TREE, CHAIN.closures, Coupled(baumgarte=(alpha, beta)))
    rng = np.random.default_rng(5)
    q = Q0 + 0.05 * jnp.asarray(rng.normal(size=Q0.shape))      # off the constraints
    v = V0 + 0.3 * jnp.asarray(rng.normal(size=V0.shape))

    @jax.jit
    def error_dynamics(q, v):
        v_dot = system.acceleration(0.0, q, v)

        def phi_dot(q, v):
            return jax.jvp(LOOPS.phi, (q,), (MODEL.q_dot(q, v),))[1]

        phi_ddot = jax.jvp(phi_dot, (q, v), (MODEL.q_dot(q, v), v_dot))[1]
        return LOOPS.phi(q), phi_dot(q, v), phi_ddot

    phi, phi_dot, phi_ddot = error_dynamics(q, v)
    assert float(jnp.max(jnp.abs(phi))) > 1e-3                  # truly off the manifold
    np.testing.assert_allclose(phi_ddot + 2 * alpha * phi_dot + beta**2 * phi, 0.0,
                               atol=1e-9 * float(jnp.max(jnp.abs(phi_ddot))))
    # so along a rollout Phi(t) is the linear ODE's solution c1 exp(r1 t) + c2 exp(r2 t)
    ts = np.linspace(0.0, 0.5, 6)
    held = simulate(system, RK4(), q, v, dt=1e-3, t1=0.5, saveat=ts)
    residual = np.asarray(jax.jit(jax.vmap(LOOPS.phi))(held.qs))
    r1, r2 = -alpha + np.sqrt(alpha**2 - beta**2), -alpha - np.sqrt(alpha**2 - beta**2)
    c1 = (np.asarray(phi_dot) - r2 * np.asarray(phi)) / (r1 - r2)
    c2 = np.asarray(phi) - c1
    expected = c1 * np.exp(r1 * ts[:, None]) + c2 * np.exp(r2 * ts[:, None])
    np.testing.assert_allclose(residual, expected, atol=1e-7)
    assert np.abs(residual[-1]).max() < 0.3 * np.abs(residual[0]).max()
