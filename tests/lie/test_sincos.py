"""`mbjax._src.lie.sincos` against the C library's sin and cos (NumPy's, an independent
implementation): Cephes' reduction and polynomials to within 2 ulp below 2^30, the library itself
beyond, exact derivatives, and the same answers under jit, vmap and inside loops."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax._src.lie import sincos
from mbjax._src.lie.sincos import LIMIT


@pytest.mark.parametrize("scale", [1e-8, 1.0, np.pi, 100.0, 1e6, 0.99 * LIMIT])
def test_within_two_ulp_of_the_library(scale):
    x = np.random.default_rng(0).uniform(-scale, scale, 100_000)
    s, c = (np.asarray(y) for y in sincos(x))
    for mine, exact in ((s, np.sin(x)), (c, np.cos(x))):
        ulp = np.spacing(np.abs(exact))
        assert np.max(np.abs(mine - exact) / ulp) <= 2.0


def test_special_points():
    x = np.array([0.0, np.pi / 4, np.pi / 2, 3 * np.pi / 4, np.pi, -np.pi, 2 * np.pi, 1e-300,
                  -5e-324])
    s, c = sincos(x)
    np.testing.assert_allclose(np.asarray(s), np.sin(x), rtol=0, atol=2.3e-16)
    np.testing.assert_allclose(np.asarray(c), np.cos(x), rtol=0, atol=2.3e-16)
    assert np.signbit(np.asarray(sincos(-0.0)[0]))            # sin(-0) = -0


def test_beyond_the_reduction_the_library_answers():
    x = np.array([0.5, LIMIT, -3.0 * LIMIT, 1e300])
    s, c = sincos(x)
    np.testing.assert_array_equal(np.asarray(s), np.asarray(jnp.sin(x)))
    np.testing.assert_array_equal(np.asarray(c), np.asarray(jnp.cos(x)))
    s, c = sincos(np.array([1.0, np.inf, np.nan]))
    assert np.isnan(np.asarray(s)[1:]).all() and np.isnan(np.asarray(c)[1:]).all()


def test_derivatives_are_cos_and_minus_sin():
    for x in (0.0, 0.3, np.pi, -2.5, 1e5):
        (s, c), (ds, dc) = jax.jvp(sincos, (x,), (1.0,))
        assert float(ds) == float(c) and float(dc) == -float(s)
    second = jax.grad(jax.grad(lambda x: sincos(x)[0]))(0.7)
    np.testing.assert_allclose(float(second), -np.sin(0.7), rtol=1e-15)


def test_float32_and_integers_use_the_library():
    s, c = sincos(np.float32(1.25))
    assert s.dtype == jnp.float32 and float(s) == float(jnp.sin(np.float32(1.25)))
    s, _ = sincos(np.arange(3))
    np.testing.assert_allclose(np.asarray(s), np.sin(np.arange(3)), rtol=0, atol=2.3e-16)


def test_same_in_jit_vmap_and_loops():
    x = np.random.default_rng(1).uniform(-10, 10, (6, 5))
    expected = np.asarray(sincos(x))
    np.testing.assert_array_equal(np.asarray(jax.jit(jax.vmap(sincos))(x)), expected)
    np.testing.assert_array_equal(np.asarray(jax.lax.map(sincos, x)), expected)   # a loop
