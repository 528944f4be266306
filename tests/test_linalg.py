"""mbjax._src.linalg.spd_solve against NumPy's solve, and free of library calls where it is written out."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax._src.linalg import UNROLL, spd_solve


@pytest.mark.parametrize("w", [1, 2, 3, 6, 8])
def test_spd_solve_matches_numpy_for_vectors_matrices_and_batches(w):
    rng = np.random.default_rng(w)
    X = rng.normal(size=(4, w, w))
    A = X @ X.transpose(0, 2, 1) + w * np.eye(w)
    b, B = rng.normal(size=(4, w)), rng.normal(size=(4, w, 3))
    np.testing.assert_allclose(spd_solve(A, b), np.linalg.solve(A, b[..., None])[..., 0], atol=1e-12)
    np.testing.assert_allclose(spd_solve(A, B), np.linalg.solve(A, B), atol=1e-12)
    np.testing.assert_allclose(spd_solve(A[0], b[0]), np.linalg.solve(A[0], b[0]), atol=1e-12)
    # derivative along a symmetric direction (the lower triangle is what Cholesky reads): -A^-1 dA x
    dA = rng.normal(size=(w, w))
    dA = dA + dA.T
    x = np.linalg.solve(A[0], b[0])
    dx = jax.jvp(lambda A: spd_solve(A, b[0]), (jnp.asarray(A[0]),), (jnp.asarray(dA),))[1]
    np.testing.assert_allclose(dx, -np.linalg.solve(A[0], dA @ x), atol=1e-12)


def test_written_out_blocks_hold_no_library_call():
    A = jnp.eye(UNROLL) * 2.0
    hlo = jax.jit(spd_solve).lower(A, jnp.ones(UNROLL)).compile().as_text()
    assert "custom-call" not in hlo
