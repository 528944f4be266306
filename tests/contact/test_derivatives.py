"""The derivatives of a stance's dynamics and of the impulse map (issue 57), taken through the
factored KKT system (`mbjax._src.loops.kkt`), against Pinocchio's analytic derivatives, forward
mode through the plain dense solves and central differences, on ANYmal and Solo12 from
example-robot-data; a stance with
every foot in the air is the free tree; and no program of a vmapped stance holds a LAPACK call
(jaxlib 0.10.2's batched LAPACK calls deadlock its CPU runtime)."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import mbjax
from mbjax._src.contact.stance import CROCODDYL_GAINS
from mbjax.contact import PointContact, impulse, stance
from mbjax.control import Constant
from mbjax.rigid import TreeSystem
from mbjax_harness.peers import pinocchio_point_contacts
from tests.conftest import example_robots

ROBOTS = {"anymal": ("anymal_b_simple/anymal", ["LF_FOOT", "LH_FOOT", "RF_FOOT", "RH_FOOT"]),
          "solo12": ("solo/solo12", ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"])}


def _robot(name):
    path, feet = ROBOTS[name]
    model = mbjax.load_urdf(example_robots([path])[0], floating_base=True)
    rng = np.random.default_rng(3)
    q = model.normalize(jnp.clip(model.home() + jnp.asarray(rng.uniform(-0.2, 0.2, model.nq)),
                                 model.lower, model.upper))
    x = tuple(jnp.asarray(rng.normal(size=model.nv)) * s for s in (0.05, 1.0, 1.0))
    return model, q, [PointContact(f) for f in feet], x


def _stance(model, q0, contacts):
    """(accelerations, multipliers) of the stance at (q0 (+) dq, v) under tau, and the same by
    the plain route: dense solves that forward mode differentiates through."""
    def new(dq, v, tau):
        phase = stance(TreeSystem(model, Constant(tau)), q0, contacts)
        q = model.integrate(q0, dq)
        return jnp.concatenate([phase.acceleration(0.0, q, v), phase.multipliers(0.0, q, v)])

    def plain(dq, v, tau):
        loops = stance(TreeSystem(model, Constant(tau)), q0, contacts).loops
        q, tree, (alpha, _) = model.integrate(q0, dq), loops.tree, CROCODDYL_GAINS
        M, A = tree.mass_matrix(q), loops.jacobian(q)
        b = loops.acceleration_bias(q, v) + 2 * alpha * loops.rate(q, v)
        a_free, Y = jnp.linalg.solve(M, -tree.bias(0.0, q, v)), jnp.linalg.solve(M, A.T)
        K = jnp.linalg.solve(A @ Y, -(A @ a_free + b))
        return jnp.concatenate([a_free + Y @ K, K])

    return new, plain


def _rel(a, b):
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / np.max(np.abs(np.asarray(b))))


@pytest.mark.slow
@pytest.mark.parametrize("robot", ["anymal", "solo12"])
def test_stance_derivatives_agree_with_the_plain_route_and_differences(robot):
    """d(v_dot, K_c)/d(dq, v, tau) by the factored KKT system equals forward mode through the
    dense solves (1e-10) and central differences (1e-6); reverse mode equals it too."""
    model, q0, contacts, x = _robot(robot)
    new, plain = (jax.jit(f) for f in _stance(model, q0, contacts))
    assert _rel(new(*x), plain(*x)) < 1e-12
    J_new = jax.jit(jax.jacfwd(new, argnums=(0, 1, 2)))(*x)
    J_plain = jax.jit(jax.jacfwd(plain, argnums=(0, 1, 2)))(*x)
    for a, b in zip(J_new, J_plain, strict=True):
        assert _rel(a, b) < 1e-10
    h = 1e-6
    for i, J in enumerate(J_new):
        for j in range(0, model.nv, 5):
            e = jnp.zeros(model.nv).at[j].set(h)
            xp, xm = list(x), list(x)
            xp[i], xm[i] = x[i] + e, x[i] - e
            # against the whole Jacobian's scale: a column may be zero (a yaw of the base)
            difference = (new(*xp) - new(*xm)) / (2 * h)
            assert float(jnp.max(jnp.abs(J[:, j] - difference))) < 1e-6 * float(jnp.max(jnp.abs(J)))
    w = jnp.asarray(np.random.default_rng(0).normal(size=J_new[0].shape[0]))
    grads = jax.jit(jax.grad(lambda *a: new(*a) @ w, argnums=(0, 1, 2)))(*x)
    for g, J in zip(grads, J_new, strict=True):
        assert _rel(g, w @ J) < 1e-10


@pytest.mark.slow
def test_impulse_derivatives_agree_with_the_plain_route():
    """d(v+, impulses)/d(q, v) of the impulse map equals forward mode through dense solves."""
    model, q0, contacts, (dq, v, _) = _robot("anymal")

    def new(dq, v):
        v_plus, impulses = impulse(model, model.integrate(q0, dq), v, contacts)
        return jnp.concatenate([v_plus, impulses.ravel()])

    def plain(dq, v):
        q = model.integrate(q0, dq)
        closures = [c.closure(model, q) for c in contacts]
        loops = stance(TreeSystem(model), q, contacts).loops
        M, A = loops.tree.mass_matrix(q), loops.jacobian(q)
        Y = jnp.linalg.solve(M, A.T)
        Lambda = jnp.linalg.solve(A @ Y, -(A @ v))
        forces = jnp.concatenate([jnp.zeros((len(closures), 3)), Lambda.reshape(-1, 3)], 1)
        return jnp.concatenate([v + Y @ Lambda, forces.ravel()])

    assert _rel(new(dq, v), plain(dq, v)) < 1e-12
    for a, b in zip(jax.jacfwd(new, argnums=(0, 1))(dq, v),
                    jax.jacfwd(plain, argnums=(0, 1))(dq, v), strict=True):
        assert _rel(a, b) < 1e-10


def test_a_stance_with_every_foot_in_the_air_is_the_free_tree():
    """All contacts let go (a flight written as a stance over the feet): the accelerations are
    the tree's own forward dynamics, the wrenches zero, the derivatives finite and equal."""
    model, q, contacts, (_, v, tau) = _robot("anymal")
    flying = [PointContact(c.frame, active=False) for c in contacts]

    @jax.jit
    def both(v):
        phase = stance(TreeSystem(model, Constant(tau)), q, flying)
        free = TreeSystem(model, Constant(tau))
        a, J = jax.jacfwd(lambda v_: (phase.acceleration(0.0, q, v_),) * 2, has_aux=True)(v)[::-1]
        J_free = jax.jacfwd(lambda v_: free.acceleration(0.0, q, v_))(v)
        return (a, J, free.acceleration(0.0, q, v), J_free, phase.multipliers(0.0, q, v),
                impulse(model, q, v, flying))

    a, J, a_free, J_free, multipliers, (v_plus, impulses) = both(v)
    assert _rel(a, a_free) < 1e-12
    assert not np.any(np.asarray(multipliers))
    assert np.all(np.isfinite(J)) and _rel(J, J_free) < 1e-10
    assert _rel(v_plus, v) < 1e-13 and not np.any(np.asarray(impulses))


def test_a_vmapped_stance_holds_no_lapack_call_and_runs_repeatedly():
    """`jax.vmap(jax.jacfwd(...))` of a four-foot stance's accelerations (the program that hung
    on its second call with jaxlib 0.10.2's batched LAPACK calls) compiles to a program with no
    LAPACK call and runs again and again."""
    model, q0, contacts, _ = _robot("anymal")
    new, _ = _stance(model, q0, contacts)
    rng = np.random.default_rng(1)
    xs = [jnp.asarray(rng.normal(size=(8, model.nv))) * s for s in (0.05, 1.0, 1.0)]
    J = jax.jit(jax.vmap(jax.jacfwd(new, argnums=(0, 1, 2))))
    assert 'custom_call_target="lapack' not in J.lower(*xs).compile().as_text()
    first = J(*xs)
    for _ in range(5):
        again = J(*xs)
    for a, b in zip(first, again, strict=True):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("robot", ["anymal", pytest.param("solo12", marks=pytest.mark.slow)])
def test_derivatives_equal_pinocchios_analytic_ones(robot):
    """The stance's d(v_dot, forces)/d(q, v, tau) equal Pinocchio's
    `computeConstraintDynamicsDerivatives`, and the impulse map's d(v+, impulses)/d(q, v) its
    `computeImpulseDynamicsDerivatives` (whose ddq_dv is the jump's, d(v+ - v)/dv), on the same
    point contacts with Crocoddyl's Kd = 50: Carpentier and Mansard's analytic derivatives,
    computed independently in C++."""
    pin = pytest.importorskip("pinocchio")
    from mbjax.model import state_to_pinocchio

    path, feet = ROBOTS[robot]
    path = example_robots([path])[0]
    model, q, contacts, (_, v, tau) = _robot(robot)
    zero = jnp.zeros(model.nv)

    @jax.jit
    def derivatives(v, tau):
        def dynamics(dq, v, tau):
            phase = stance(TreeSystem(model, Constant(tau)), q, contacts)
            q_ = model.integrate(q, dq)
            return phase.acceleration(0.0, q_, v), phase.multipliers(0.0, q_, v)

        def jump(dq, v):
            v_plus, impulses = impulse(model, model.integrate(q, dq), v, contacts)
            return v_plus, impulses[:, 3:].ravel()

        return (jax.jacfwd(dynamics, argnums=(0, 1, 2))(zero, v, tau),
                jax.jacfwd(jump, argnums=(0, 1))(zero, v))

    ((a_q, a_v, a_tau), (f_q, f_v, f_tau)), ((j_q, j_v), (i_q, i_v)) = (
        jax.tree.map(np.asarray, derivatives(v, tau)))
    q_pin, v_pin = (np.asarray(x) for x in state_to_pinocchio(model, q, v))
    P = np.asarray(jax.jacfwd(lambda v_: state_to_pinocchio(model, q, v_)[1])(v))  # a permutation
    D = np.diag(np.asarray(model.damping))    # URDF damping: Pinocchio's torque is tau - D v
    pm = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    pd = pm.createData()
    models, datas, settings = pinocchio_point_contacts(pm, feet, 2 * CROCODDYL_GAINS[0])
    pin.initConstraintDynamics(pm, pd, models, datas)
    pin.constraintDynamics(pm, pd, q_pin, v_pin, P @ np.asarray(tau - model.damping * v), models,
                           datas, settings)
    pin.computeConstraintDynamicsDerivatives(pm, pd, models, datas, settings)
    for ours, theirs in ((P @ a_q @ P.T, pd.ddq_dq), (P @ (a_v + a_tau @ D) @ P.T, pd.ddq_dv),
                         (P @ a_tau @ P.T, pd.ddq_dtau), (f_q @ P.T, pd.dlambda_dq),
                         ((f_v + f_tau @ D) @ P.T, pd.dlambda_dv), (f_tau @ P.T, pd.dlambda_dtau)):
        assert _rel(ours, theirs) < 1e-9
    pin.initConstraintDynamics(pm, pd, models, datas)
    pin.impulseDynamics(pm, pd, q_pin, v_pin, models, datas, 0.0, settings)
    pin.computeImpulseDynamicsDerivatives(pm, pd, models, datas, 0.0, settings)
    for ours, theirs in ((P @ j_q @ P.T, pd.ddq_dq), (P @ j_v @ P.T - np.eye(model.nv), pd.ddq_dv),
                         (i_q @ P.T, pd.dlambda_dq), (i_v @ P.T, pd.dlambda_dv)):
        assert _rel(ours, theirs) < 1e-9
