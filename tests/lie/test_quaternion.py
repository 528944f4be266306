"""Quaternion conversions against scipy and against the rotation vector."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mbjax._src import lie

rng = np.random.default_rng(1)
ROTATIONS = Rotation.random(20, random_state=3)


def as_wxyz(rotation):
    x, y, z, w = rotation.as_quat()
    q = np.array([w, x, y, z])
    return q if w >= 0 else -q


@pytest.mark.parametrize("i", range(20))
def test_matrix_quaternion_roundtrip_against_scipy(i):
    R = jnp.asarray(ROTATIONS[i].as_matrix())
    q = lie.quat_from_matrix(R)
    q = jnp.where(q[0] < 0, -q, q)
    np.testing.assert_allclose(q, as_wxyz(ROTATIONS[i]), atol=1e-14)
    np.testing.assert_allclose(lie.quat_to_matrix(q), R, atol=1e-14)


def test_quaternion_of_rotvec_matches_exp():
    for angle in (0.0, 1e-9, 0.5, 2.0, np.pi, 5.0):
        e = rng.normal(size=3)
        r = jnp.asarray(angle * e / np.linalg.norm(e))
        np.testing.assert_allclose(lie.quat_to_matrix(lie.quat_from_rotvec(r)), lie.exp(r),
                                   atol=1e-14)


def test_product_is_composition():
    p, q = (jnp.asarray(as_wxyz(ROTATIONS[k])) for k in (0, 1))
    np.testing.assert_allclose(lie.quat_to_matrix(lie.quat_multiply(p, q)),
                               lie.quat_to_matrix(p) @ lie.quat_to_matrix(q), atol=1e-14)
    np.testing.assert_allclose(lie.quat_multiply(q, lie.quat_conjugate(q)),
                               jnp.array([1.0, 0, 0, 0]), atol=1e-15)


def test_shepperd_branches_and_pi_rotations():
    """Rotations by pi about each axis exercise the x, y, z pivots of Shepperd's method."""
    for axis in jnp.eye(3):
        R = lie.exp(np.pi * axis)
        q = lie.quat_from_matrix(R)
        np.testing.assert_allclose(lie.quat_to_matrix(q), R, atol=1e-14)
        assert bool(jnp.all(jnp.isfinite(jax.jacfwd(lie.quat_from_matrix)(R))))
