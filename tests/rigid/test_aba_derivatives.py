"""The analytic derivatives of the dynamics: `rnea_partials` (the composite-body form of Carpentier
and Mansard 2018) against JAX's derivative of the RNEA, `jax.jacfwd(forward_dynamics)` in the
tangent space against Pinocchio's `computeABADerivatives` on robots of example-robot-data, and
the linear maps' rules (batching, transpose, higher orders) against each other and against
central differences, at random states, zero rotations and half turns."""

import warnings

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import mbjax
from mbjax._src.model.states import _pinocchio_layout, _continuous
from mbjax._src.rigid import rnea_derivatives
from mbjax._src.rigid.operator import mass_matrix as operator_mass_matrix
from mbjax._src.rigid.rnea import inverse_dynamics
from mbjax.model import chain, state_to_pinocchio
from mbjax_harness.peers import random_state
from tests.conftest import example_robots

QUICK_ROBOTS = ("panda/panda", "solo/solo12", "hector/quadrotor_base")


def _states(model, seed):
    """A random state, then the same at zero rotation and with every joint a half turn away."""
    q, v, a = (jnp.asarray(x) for x in random_state(model, seed))
    yield q, v, a
    for angle in (0.0, np.pi):
        turned = model.integrate(model.neutral(), jnp.full(model.nv, angle))
        yield turned, v, a


def _jacobians(model, q, v, tau):
    """d(v_dot)/d(e, v, tau) by `jax.jacfwd`, e the tangent of q at q (`Model.integrate`)."""
    def fd(e, v, tau):
        return mbjax.forward_dynamics(model, model.integrate(q, e), v, tau)
    return jax.jit(jax.jacfwd(fd, argnums=(0, 1, 2)))(jnp.zeros(model.nv), v, tau)


@pytest.mark.filterwarnings("ignore::mbjax.model.ModelWarning")
def test_rnea_partials_equal_the_rneas_derivative():
    """Every column of the composite-body matrices against `jax.jacfwd` through the RNEA itself,
    and their mass matrix against the operator form's: a chain with joint springs, an arm, a
    floating quadruped."""
    sprung = eqx.tree_at(lambda m: (m.stiffness, m.spring_reference), chain(7),
                         (jnp.linspace(1.0, 7.0, 7), jnp.full(7, 0.3)))     # joint springs
    models = [sprung] + [mbjax.load_urdf(p, floating_base="solo" in str(p))
                           for p in example_robots(("panda/panda", "solo/solo12"))]
    for model in models:
        partials = jax.jit(rnea_derivatives.rnea_partials)
        for q, v, a in _states(model, 3):
            D_e, D_v, M = partials(model, q, v, a)
            J_e, J_v = jax.jacfwd(lambda e, v, q=q, a=a: inverse_dynamics(
                model, model.integrate(q, e), v, a), argnums=(0, 1))(jnp.zeros(model.nv), v)
            scale = max(np.abs(J_e).max(), np.abs(J_v).max())
            assert np.abs(D_e - J_e).max() < 1e-12 * scale
            assert np.abs(D_v - J_v).max() < 1e-12 * scale
            mass = operator_mass_matrix(model, q)                  # Jerkovsky's operator form
            assert np.abs(M - mass).max() < 1e-12 * np.abs(mass).max()


def _against_pinocchio(path, pin, floating: bool, seed: int) -> float | None:
    """max relative difference of (d/dq, d/dv, d/dtau) of the accelerations, mbjax against
    Pinocchio's computeABADerivatives, in Pinocchio's layout (a free joint's tangent
    (v_origin; omega) body-local in both), without joint damping (Pinocchio's ABA has none)."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model = mbjax.load_urdf(path, floating_base=floating)
    except ValueError:                # a file that is not a robot
        return None
    model = eqx.tree_at(lambda m: m.damping, model, jnp.zeros_like(model.damping))
    pin_model = (pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer()) if floating
                 else pin.buildModelFromUrdf(str(path)))
    data = pin_model.createData()
    q, v, tau = (jnp.asarray(x) for x in random_state(model, seed))
    J = [np.asarray(x) for x in _jacobians(model, q, v, tau)]
    order = np.asarray(_pinocchio_layout(model.joint_types, _continuous(model))["v_src"])
    pq, pv = (np.asarray(x) for x in state_to_pinocchio(model, q, v))
    pin.computeABADerivatives(pin_model, data, pq, pv, np.asarray(tau)[order])
    ours = [x[np.ix_(order, order)] for x in J]
    theirs = [data.ddq_dq, data.ddq_dv, np.asarray(data.Minv)]
    theirs[2] = np.triu(theirs[2]) + np.triu(theirs[2], 1).T          # Pinocchio fills the upper
    return max(np.abs(o - t).max() / max(np.abs(t).max(), 1.0)
               for o, t in zip(ours, theirs, strict=True))


def test_forward_dynamics_derivatives_equal_pinocchios():
    """An arm, a floating quadruped and a floating quadrotor, in the tangent space."""
    pin = pytest.importorskip("pinocchio")
    paths = example_robots(QUICK_ROBOTS)
    assert len(paths) == len(QUICK_ROBOTS)
    for path in paths:
        floating = "panda" not in str(path)
        assert _against_pinocchio(path, pin, floating, 0) < 1e-10, path


@pytest.mark.slow
def test_forward_dynamics_derivatives_on_every_robot():
    """Every robot of example-robot-data, fixed and on a free base."""
    pin = pytest.importorskip("pinocchio")
    worst = {}
    for path in example_robots():
        for floating in (False, True):
            try:
                difference = _against_pinocchio(path, pin, floating, 1)
            except Exception as err:  # noqa: BLE001 (reported below with the robot's name)
                pytest.fail(f"{path} floating={floating}: {type(err).__name__}: {err}")
            if difference is not None:
                worst[(path.stem, floating)] = difference
    assert len(worst) > 100
    assert max(worst.values()) < 1e-9, max(worst.items(), key=lambda kv: kv[1])


def _fd(model, q):
    """x = (e, v, tau) -> the accelerations at (q (+) e, v, tau)."""
    def fd(x):
        e, v, tau = jnp.split(x, 3)
        return mbjax.forward_dynamics(model, model.integrate(q, e), v, tau)
    return fd


@pytest.mark.filterwarnings("ignore::mbjax.model.ModelWarning")
def test_linear_maps_agree_in_every_mode():
    """jax.jacfwd (the matrices once), jax.jacrev (the passes transposed), a vmapped jvp at many
    states (the passes mapped) and central differences give the same Jacobian. A floating
    quadruped."""
    model = mbjax.load_urdf(example_robots(("solo/solo12",))[0], floating_base=True)
    q, v, tau = (jnp.asarray(x) for x in random_state(model, 5))
    fd = _fd(model, q)
    x = jnp.concatenate([jnp.zeros(model.nv), v, tau])
    forward = jax.jit(jax.jacfwd(fd))(x)
    reverse = jax.jit(jax.jacrev(fd))(x)
    basis = jnp.eye(x.size)
    mapped = jax.jit(jax.vmap(lambda x, t: jax.jvp(fd, (x,), (t,))[1]))(
        jnp.broadcast_to(x, basis.shape), basis).T
    h = 1e-6
    central = jax.jit(jax.vmap(lambda t: (fd(x + h * t) - fd(x - h * t)) / (2 * h)))(basis).T
    scale = np.abs(forward).max()
    assert np.abs(forward - reverse).max() < 1e-11 * scale
    assert np.abs(forward - mapped).max() < 1e-11 * scale
    assert np.abs(forward - central).max() < 1e-6 * scale


def _second_derivatives(model):
    """The Hessian of an acceleration by forward over reverse and by reverse over forward mode
    agree, and equal central differences of the gradient."""
    q, v, tau = (jnp.asarray(x) for x in random_state(model, 6))
    fd = _fd(model, q)
    first = lambda x: fd(x)[model.nv - 1]                                  # noqa: E731
    x = jnp.concatenate([jnp.zeros(model.nv), v, tau])
    H_fr = jax.jit(jax.jacfwd(jax.grad(first)))(x)
    H_rf = jax.jit(jax.jacrev(jax.jacfwd(first)))(x)
    grad, h = jax.jit(jax.grad(first)), 1e-6
    H_c = jnp.stack([(grad(x + h * t) - grad(x - h * t)) / (2 * h) for t in jnp.eye(x.size)])
    scale = np.abs(H_fr).max()
    assert np.abs(H_fr - H_rf).max() < 1e-9 * scale
    assert np.abs(H_fr - H_c).max() < 1e-5 * scale


def test_second_derivatives_through_the_rules():
    """A 3-link chain."""
    _second_derivatives(chain(3))


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::mbjax.model.ModelWarning")
def test_second_derivatives_on_a_free_body():
    """The quadrotor: a quaternion's tangent through every rule."""
    _second_derivatives(mbjax.load_urdf(example_robots(("hector/quadrotor_base",))[0], floating_base=True))
