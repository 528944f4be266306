"""Forward kinematics' written-out derivative (`kinematics.forward_kinematics`: each body moved
rigidly by the sum of its path's joint twists) against JAX's derivative of the products of
rotations and against central differences, in every mode and for the model's parameters."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax.data import ARM7
from mbjax.model import random_tree
from mbjax._src.model.urdf import load_urdf
from mbjax.rigid import forward_kinematics
from mbjax._src.rigid.kinematics import _poses, fixed_in_body

MODELS = {
    "hinges": random_tree(6, seed=2),
    "balls": random_tree(6, seed=8, joint_types=("free", "spherical", "revolute", "prismatic")),
    "universal": random_tree(5, seed=4, joint_types=("free", "spherical", "universal", "revolute",
                                                     "prismatic")),
}


def _plain(model, q):
    """The poses without the rule: JAX differentiates the products of rotations."""
    return _poses.fun(model, q)


def _q(model, seed=0):
    return model.normalize(jnp.asarray(np.random.default_rng(seed).standard_normal(model.nq)))


@pytest.mark.parametrize("name", MODELS)
def test_pose_jacobian_agrees_with_autodiff_and_differences(name):
    model = MODELS[name]
    assert fixed_in_body(model) == (name != "universal")
    q = _q(model)
    ours = jax.jit(jax.jacfwd(lambda q: forward_kinematics(model, q)))(q)
    plain = jax.jit(jax.jacfwd(lambda q: _plain(model, q)))(q)
    for a, b in zip(ours, plain, strict=True):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-13)
    # central differences along one direction that moves every coordinate (a quaternion's
    # normalization is part of the map: the rule and the difference both see it)
    dq = jnp.asarray(np.random.default_rng(1).standard_normal(model.nq))
    h = 1e-6
    plus, minus = (forward_kinematics(model, q + s * h * dq) for s in (1, -1))
    _, (dR, dp) = jax.jvp(lambda q: forward_kinematics(model, q), (q,), (dq,))
    np.testing.assert_allclose(dR, (plus[0] - minus[0]) / (2 * h), atol=1e-8)
    np.testing.assert_allclose(dp, (plus[1] - minus[1]) / (2 * h), atol=1e-8)


@pytest.mark.parametrize("name", ["hinges", "balls"])
def test_reverse_mode_second_order_and_model_parameters(name):
    """grad in (model, q) and the Hessian in q of a scalar of the poses, through the rule."""
    model = MODELS[name]
    q = _q(model, 3)

    def scalar(poses):
        R, p = poses
        return jnp.sum(jnp.sin(R)) + jnp.sum(p**2)

    def ours(m, q):
        return scalar(forward_kinematics(m, q))

    def plain(m, q):
        return scalar(_plain(m, q))

    g_ours, g_plain = (jax.jit(jax.grad(f, argnums=(0, 1)))(model, q) for f in (ours, plain))
    leaves = [(a, b) for a, b in zip(jax.tree.leaves(g_ours), jax.tree.leaves(g_plain),
                                     strict=True) if np.size(a)]
    assert any(np.abs(b).max() > 0 for _, b in leaves)       # the placements do matter
    for a, b in leaves:
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)
    H_ours, H_plain = (jax.jit(jax.hessian(lambda q, f=f: f(model, q)))(q) for f in (ours, plain))
    np.testing.assert_allclose(H_ours, H_plain, rtol=0, atol=1e-12)


def test_real_arm_flange_jacobian_matches_frame_jacobian():
    """The shipped 7-dof arm: d(flange position)/dq by the rule against `frame_jacobian`'s
    linear rows (the flange's origin velocity per joint rate)."""
    from mbjax.rigid import frame_jacobian, frame_pose

    model = load_urdf(str(ARM7))
    q = _q(model, 5)
    name = model.names[-1]
    J = jax.jacfwd(lambda q: frame_pose(model, q, name)[1])(q)
    np.testing.assert_allclose(J, frame_jacobian(model, q, name)[3:], atol=1e-13)
