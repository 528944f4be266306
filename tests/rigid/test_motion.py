"""The bodies' motion and the generalized force of wrenches on them, with their derivatives
written out (`mbjax._src.rigid.motion`), against JAX's derivative of the plain passes, central
differences, and a real robot (ANYmal, from example-robot-data)."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax.model import random_tree
from mbjax._src.rigid import motion
from mbjax._src.rigid.kinematics import fixed_in_body

MODELS = {
    "hinges": random_tree(6, seed=2),
    "balls": random_tree(6, seed=8, joint_types=("free", "spherical", "revolute", "prismatic")),
}


def _state(model, seed=0):
    rng = np.random.default_rng(seed)
    q = model.normalize(jnp.asarray(rng.standard_normal(model.nq)))
    v, a = (jnp.asarray(rng.standard_normal(model.nv)) for _ in range(2))
    W = jnp.asarray(rng.standard_normal((model.n, 6)))
    return q, v, a, W


def _close(ours, plain, atol):
    for x, y in zip(jax.tree.leaves(ours), jax.tree.leaves(plain), strict=True):
        np.testing.assert_allclose(x, y, rtol=0, atol=atol)


def _check(model, seed=0, atol=1e-12):
    """Each mode of the rules against JAX's own derivative of the plain passes."""
    assert fixed_in_body(model)
    q, v, a, W = _state(model, seed)
    ours_m = lambda q, v, a: motion.body_motion(model, q, v, a)          # noqa: E731
    plain_m = lambda q, v, a: motion._motion.fun(model, q, v, a)         # noqa: E731
    ours_f = lambda q, W: motion.body_forces(model, q, W)                # noqa: E731
    plain_f = lambda q, W: motion._forces.fun(model, q, W)               # noqa: E731
    # a batch of directions (jacfwd: the joints' increments as one product) and one direction
    _close(jax.jit(jax.jacfwd(ours_m, argnums=(0, 1, 2)))(q, v, a),
           jax.jit(jax.jacfwd(plain_m, argnums=(0, 1, 2)))(q, v, a), atol)
    _close(jax.jit(jax.jacfwd(ours_f, argnums=(0, 1)))(q, W),
           jax.jit(jax.jacfwd(plain_f, argnums=(0, 1)))(q, W), atol)
    rng = np.random.default_rng(seed + 1)
    dq, dv, da = (jnp.asarray(rng.standard_normal(n)) for n in (model.nq, model.nv, model.nv))
    _close(jax.jvp(ours_m, (q, v, a), (dq, dv, da)), jax.jvp(plain_m, (q, v, a), (dq, dv, da)),
           atol)
    # reverse mode transposes the rule
    def scalar(f):
        return lambda q, v, a, W: (sum(jnp.sum(jnp.sin(x)) for x in f[0](q, v, a))
                                   + jnp.sum(jnp.cos(f[1](q, W))))
    _close(jax.grad(scalar((ours_m, ours_f)), argnums=(0, 1, 2, 3))(q, v, a, W),
           jax.grad(scalar((plain_m, plain_f)), argnums=(0, 1, 2, 3))(q, v, a, W), atol)
    return q, v, a, W


@pytest.mark.parametrize("name", MODELS)
def test_motion_and_force_derivatives_agree_with_autodiff_and_differences(name):
    model = MODELS[name]
    q, v, a, W = _check(model)
    # central differences of the velocity and acceleration along one direction of (q, v, a)
    rng = np.random.default_rng(7)
    dq, dv, da = (jnp.asarray(rng.standard_normal(n)) for n in (model.nq, model.nv, model.nv))
    h = 1e-6
    plus, minus = (motion.body_motion(model, q + s * h * dq, v + s * h * dv, a + s * h * da)
                   for s in (1, -1))
    _, tangent = jax.jvp(lambda q, v, a: motion.body_motion(model, q, v, a), (q, v, a),
                         (dq, dv, da))
    for t, p, m in zip(tangent, plus, minus, strict=True):
        np.testing.assert_allclose(t, (p - m) / (2 * h), atol=2e-7)
    _, dtau = jax.jvp(lambda q: motion.body_forces(model, q, W), (q,), (dq,))
    np.testing.assert_allclose(dtau, (motion.body_forces(model, q + h * dq, W)
                                      - motion.body_forces(model, q - h * dq, W)) / (2 * h),
                               atol=2e-7)


def test_floating_quadruped_from_example_robot_data():
    """ANYmal (a free base and twelve hinges, a URDF no one here wrote)."""
    erd = pytest.importorskip("example_robot_data")
    import mbjax

    model = mbjax.load_urdf(erd.load("anymal").urdf, floating_base=True)
    _check(model, seed=3, atol=1e-11)
