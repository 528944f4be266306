"""`mbjax._src.tree.take`: static-index gathers as slices, and the scatter-free programs they give."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax.model import chain, random_tree
from mbjax._src.tree.take import MAX_RUNS, runs, take


def _primitives(jaxpr, found=None):
    found = set() if found is None else found
    for eqn in jaxpr.eqns:
        found.add(eqn.primitive.name)
        for param in eqn.params.values():
            for sub in param if isinstance(param, (tuple, list)) else (param,):
                inner = getattr(sub, "jaxpr", sub)
                if hasattr(inner, "eqns"):
                    _primitives(inner, found)
    return found


@pytest.mark.parametrize("index", [
    np.arange(12), np.arange(11, -1, -1), np.array([3, 4, 5, 9, 8, 7, 0]),
    np.array([[1, 2, 3], [2, 3, 4]]), np.array([5]), np.array([2, 2, 2]), np.zeros(0, int),
    np.random.default_rng(0).integers(0, 12, 30)])
def test_take_is_numpy_indexing(index):
    x = jnp.asarray(np.random.default_rng(1).normal(size=(12, 2)))
    np.testing.assert_array_equal(take(x, index), np.asarray(x)[index])
    # the gradient too (repeated indices add up)
    w = jnp.asarray(np.random.default_rng(2).normal(size=(*index.shape, 2)))
    np.testing.assert_allclose(jax.grad(lambda x: jnp.sum(take(x, index) * w))(x),
                               jax.grad(lambda x: jnp.sum(x[index] * w))(x), rtol=1e-15)


def test_runs_up_and_down():
    assert runs(np.array([3, 4, 5, 9, 8, 7, 0])) == [(3, 3, 1), (9, 3, -1), (0, 1, 1)]
    assert len(runs(np.random.default_rng(0).permutation(40))) > MAX_RUNS


def test_scatter_free_where_the_map_is_a_few_runs():
    """A run-structured map is slices both ways; a scattered one stays a gather."""
    x = jnp.arange(10.0)
    ordered = jax.make_jaxpr(jax.grad(lambda x: jnp.sum(take(x, np.arange(9, 1, -1)) ** 2)))(x)
    assert not _primitives(ordered.jaxpr) & {"gather", "scatter-add", "scatter"}
    scattered = np.random.default_rng(0).permutation(10)
    assert "gather" in _primitives(jax.make_jaxpr(lambda x: take(x, scattered))(x).jaxpr)


@pytest.mark.parametrize("model", [chain(7), random_tree(9, seed=2, joint_types=(
    "revolute", "prismatic", "universal", "spherical", "free"))], ids=["chain", "mixed"])
def test_body_v_flat_v_round_trip(model):
    v = jnp.arange(model.nv, dtype=float) + 1.0
    per_body = model.body_v(v)
    assert per_body.shape == (model.n, model.width)
    np.testing.assert_array_equal(np.asarray(per_body)[model.v_mask], v)   # real columns
    np.testing.assert_array_equal(np.asarray(per_body)[~model.v_mask], 0.0)
    np.testing.assert_array_equal(model.flat_v(per_body), v)
    # trailing axes ride along
    V = jnp.stack([v, 2 * v], -1)
    np.testing.assert_array_equal(model.flat_v(model.body_v(V)), V)


def test_forward_dynamics_gradient_is_scatter_free():
    """The 7-link chain's forward dynamics and its reverse-mode gradient hold no gather and no
    scatter, so XLA can compile a rollout and its reverse pass as one kernel per loop."""
    from mbjax.rigid import forward_dynamics

    model = chain(7)
    q = jnp.linspace(-0.5, 0.5, 7)
    loss = lambda q: jnp.sum(forward_dynamics(model, q, q, q) ** 2)     # noqa: E731
    assert not _primitives(jax.make_jaxpr(jax.grad(loss))(q).jaxpr) & {
        "gather", "scatter-add", "scatter"}
