"""Jerkovsky 1978's operators: A from the path matrix, B = A^-1 from the reference matrix (eq 17)."""

import functools

import equinox as eqx
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax.model import chain, random_tree
from mbjax.rigid import transformation_operator
from mbjax._src.rigid import inverse_operator, operator_terms, primitive_inverse_mass

MODELS = {
    "chain": chain(6, seed=3),
    "tree": random_tree(9, seed=2),
    "mixed": random_tree(7, seed=5, joint_types=("revolute", "universal", "spherical", "free")),
}


def _state(model, seed=0):
    rng = np.random.default_rng(seed)
    return model.normalize(model.neutral() + 0.4 * rng.normal(size=model.nq))


@eqx.filter_jit
def _operators(model, q, v):
    """Every operator the tests compare, in one compiled call per model (op-by-op dispatch of the
    tree passes compiled each small operation per model: seconds per test)."""
    A, A_hat = transformation_operator(model, q)
    terms = operator_terms(model, q, v)
    return {"A": A, "A_hat": A_hat, "B": inverse_operator(model, q), "sigma": terms.sigma,
            "mu": terms.mu, "nu": primitive_inverse_mass(terms)}


@functools.cache
def _case(name):
    """(model, q, v, operators at (q, v)) of MODELS[name], shared by the tests of this module."""
    model = MODELS[name]
    q = _state(model)
    v = jnp.asarray(np.random.default_rng(1).normal(size=model.nv))
    return model, q, v, _operators(model, q, v)


def _block_pattern(M: np.ndarray, n: int) -> np.ndarray:
    return np.abs(np.asarray(M)).reshape(n, 6, n, 6).max(axis=(1, 3)) > 0


@pytest.mark.parametrize("name", MODELS)
def test_B_is_inverse_of_A(name):
    """A B = B A = I (eq 17): pi and rho are inverse (eq 3), block by block."""
    model, _, _, out = _case(name)
    A, B = out["A"], out["B"]
    eye = np.eye(6 * model.n)
    np.testing.assert_allclose(A @ B, eye, atol=1e-13)
    np.testing.assert_allclose(B @ A, eye, atol=1e-13)


@pytest.mark.parametrize("name", MODELS)
def test_sparsity_is_path_and_reference_matrix(name):
    """A's non-zero blocks are pi's entries (eq 14), B's are rho's (eq 15)."""
    model, _, _, out = _case(name)
    A, B = out["A"], out["B"]
    np.testing.assert_array_equal(_block_pattern(A, model.n), model.topology.path_matrix() != 0)
    np.testing.assert_array_equal(_block_pattern(B, model.n),
                                  model.topology.reference_matrix() != 0)


@pytest.mark.parametrize("name", MODELS)
def test_velocity_transformation(name):
    """sigma = A A_hat_f v (eqs 17, 47) equals the primitive velocities, and B sigma gives back the
    relative velocities A_hat_f v (eq 17's inverse)."""
    _, _, v, out = _case(name)
    A, A_hat, B = out["A"], out["A_hat"], out["B"]
    sigma = out["sigma"].reshape(-1)
    np.testing.assert_allclose(A @ A_hat @ v, sigma, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(B @ sigma, A_hat @ v, atol=1e-12)


@pytest.mark.parametrize("name", MODELS)
def test_nu_is_inverse_of_mu(name):
    """nu = mu^-1 (eq 7b)."""
    _, _, _, out = _case(name)
    nu, mu = out["nu"], out["mu"]
    np.testing.assert_allclose(nu @ mu, np.broadcast_to(np.eye(6), nu.shape), atol=1e-12)
