"""Tree topology (Jerkovsky 1978 eqs 1-3, Anderson 1993 eqs 2-4) and the forward/backward tree passes.

Expected sets and matrices are written by hand from the definitions; the passes are checked
against plain-Python recursions over the parent array.
"""

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mbjax._src.tree import Topology, backward_pass, forward_pass, outward_sum, path_sum, topology

# --------------------------------------------------------------------------------------------
# Validation
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("parents, match", [
    ([], "at least one body"),
    ([-1, 2, 1], r"parents\[1\] = 2: every body must be numbered higher than its parent"),
    ([-1, 1], r"parents\[1\] = 1: a body cannot be its own parent"),
    ([0], r"parents\[0\] = 0: a body cannot be its own parent"),
    ([-1, 0, 7], r"parents\[2\] = 7 is out of range"),
    ([-1, -2], r"parents\[1\] = -2 is out of range"),
])
def test_invalid_parent_arrays_are_rejected(parents, match):
    with pytest.raises(ValueError, match=match):
        Topology(parents)


def test_topology_is_static_and_hashable():
    a, b = Topology([-1, 0, 0]), Topology(np.array([-1, 0, 0]))
    assert a == b and hash(a) == hash(b)
    assert a != Topology([-1, 0, 1])
    assert a.parents == (-1, 0, 0) and all(type(p) is int for p in a.parents)
    assert a.n == 3
    assert "[-1, 0, 0]" in repr(a)


# --------------------------------------------------------------------------------------------
# A small branched tree, by hand
# --------------------------------------------------------------------------------------------
#
#   ground - 0 -+- 1 -+- 2          (Jerkovsky 1978 labels: 1 is the central body, here 0)
#               |     +- 3
#               +- 4 --- 5
#
FIVE_PARENTS = [-1, 0, 1, 1, 0, 4]
FIVE = Topology(FIVE_PARENTS)


def test_sets_of_branched_tree():
    """An[k] (Anderson 1993 eq 2, nearest first), Dist[k] (eq 3), Des[k] (eq 4)."""
    assert [FIVE.ancestors(k) for k in range(6)] == [(), (0,), (1, 0), (1, 0), (0,), (4, 0)]
    assert [FIVE.distal(k) for k in range(6)] == [(1, 4), (2, 3), (), (), (5,), ()]
    assert [FIVE.descendants(k) for k in range(6)] == [(1, 2, 3, 4, 5), (2, 3), (), (), (5,), ()]


def test_path_and_reference_matrices_of_branched_tree():
    """pi (Jerkovsky 1978 eq 1): row i is the inward set i^, column j the outward set j-bar;
    rho (eq 2): I on the diagonal and -I where body i is referenced to body j; eq 3."""
    pi = np.array([[1, 0, 0, 0, 0, 0],
                   [1, 1, 0, 0, 0, 0],
                   [1, 1, 1, 0, 0, 0],
                   [1, 1, 0, 1, 0, 0],
                   [1, 0, 0, 0, 1, 0],
                   [1, 0, 0, 0, 1, 1]])
    rho = np.array([[1, 0, 0, 0, 0, 0],
                    [-1, 1, 0, 0, 0, 0],
                    [0, -1, 1, 0, 0, 0],
                    [0, -1, 0, 1, 0, 0],
                    [-1, 0, 0, 0, 1, 0],
                    [0, 0, 0, 0, -1, 1]])
    np.testing.assert_array_equal(FIVE.path_matrix(), pi)
    np.testing.assert_array_equal(FIVE.reference_matrix(), rho)
    np.testing.assert_array_equal(rho @ pi, np.eye(6))
    np.testing.assert_array_equal(pi @ rho, np.eye(6))


@pytest.fixture(params=["levels", "one body per step"])
def schedule(request, monkeypatch):
    """Both kinds of tree pass: level steps (where `levels_pay`) and one body per step."""
    monkeypatch.setattr(topology, "levels_pay", lambda: request.param == "levels")
    return request.param


def test_depth_levels_and_schedule_of_branched_tree(monkeypatch):
    monkeypatch.setattr(topology, "levels_pay", lambda: True)
    FIVE = Topology(FIVE_PARENTS)
    assert FIVE.depth == (0, 1, 2, 2, 1, 2)
    assert FIVE.levels == ((0,), (1, 4), (2, 3, 5))
    order, mask = FIVE.schedule
    # 3 levels of width 3 <= 2 n: one vectorized step per level, short levels padded.
    assert order.shape == mask.shape == (3, 3)
    assert [sorted(order[s][mask[s]].tolist()) for s in range(3)] == [[0], [1, 4], [2, 3, 5]]


def test_forest_with_several_base_bodies():
    """Several bodies may hang from the ground (parent -1): a forest."""
    top = Topology([-1, -1, 0, 1, 1])
    assert top.depth == (0, 0, 1, 1, 1)
    assert top.levels == ((0, 1), (2, 3, 4))
    assert top.ancestors(3) == (1,) and top.descendants(0) == (2,)
    np.testing.assert_array_equal(top.path_matrix(), [[1, 0, 0, 0, 0],
                                                      [0, 1, 0, 0, 0],
                                                      [1, 0, 1, 0, 0],
                                                      [0, 1, 0, 1, 0],
                                                      [0, 1, 0, 0, 1]])


def test_chain_and_star():
    chain = Topology(np.arange(5) - 1)
    assert chain.depth == (0, 1, 2, 3, 4)
    np.testing.assert_array_equal(chain.path_matrix(), np.tril(np.ones((5, 5), int)))
    np.testing.assert_array_equal(chain.reference_matrix(), np.eye(5, dtype=int) - np.eye(5, k=-1))
    star = Topology([-1, 0, 0, 0, 0])
    assert star.levels == ((0,), (1, 2, 3, 4))
    assert star.descendants(0) == (1, 2, 3, 4) and star.distal(0) == (1, 2, 3, 4)
    assert all(star.ancestors(k) == (0,) for k in range(1, 5))


# --------------------------------------------------------------------------------------------
# Random trees (hypothesis)
# --------------------------------------------------------------------------------------------

parent_arrays = st.integers(1, 25).flatmap(
    lambda n: st.tuples(*[st.integers(-1, k - 1) for k in range(n)]))


def _ancestors_by_walking(parents, k):
    out = []
    while parents[k] >= 0:
        k = parents[k]
        out.append(k)
    return out


@settings(max_examples=150, deadline=None)
@given(parent_arrays)
def test_random_tree_matrices_and_sets(parents):
    top = Topology(parents)
    n = len(parents)
    pi, rho = top.path_matrix(), top.reference_matrix()
    np.testing.assert_array_equal(rho @ pi, np.eye(n))          # Jerkovsky 1978 eq 3
    np.testing.assert_array_equal(pi @ rho, np.eye(n))
    assert np.array_equal(pi, np.tril(pi)) and np.array_equal(rho, np.tril(rho))
    for k in range(n):
        inward = _ancestors_by_walking(parents, k)
        assert list(top.ancestors(k)) == inward
        assert set(np.flatnonzero(pi[k])) == {k, *inward}           # row k: the inward set
        outward = [j for j in range(n) if k in _ancestors_by_walking(parents, j)]
        assert list(top.descendants(k)) == outward
        assert set(np.flatnonzero(pi[:, k])) == {k, *outward}       # column k: outward set
        assert list(top.distal(k)) == [j for j in range(n) if parents[j] == k]
        assert top.depth[k] == len(inward)
        assert rho[k, k] == 1 and (parents[k] < 0 or rho[k, parents[k]] == -1)
        assert np.abs(rho[k]).sum() == (1 if parents[k] < 0 else 2)
    # Levels partition the bodies by depth.
    assert sorted(k for level in top.levels for k in level) == list(range(n))
    assert all(top.depth[k] == d for d, level in enumerate(top.levels) for k in level)


@settings(max_examples=150, deadline=None)
@given(parent_arrays)
def test_random_tree_schedule_visits_parents_first(parents):
    """Every body appears once unmasked, strictly after its parent's step."""
    order, mask = Topology(parents).schedule
    assert order.shape == mask.shape and order.ndim == 2
    real = order[mask]
    assert sorted(real.tolist()) == list(range(len(parents)))
    step = {int(k): s for s in range(order.shape[0]) for k in order[s][mask[s]]}
    assert all(step[k] > step[p] for k, p in enumerate(parents) if p >= 0)
    # Padding repeats a real body of the same step (no made-up rows).
    for s in range(order.shape[0]):
        assert set(order[s].tolist()) <= set(order[s][mask[s]].tolist())


# --------------------------------------------------------------------------------------------
# Tree passes against plain-Python recursions
# --------------------------------------------------------------------------------------------


def _random_parents(n, seed, max_back=4):
    rng = np.random.default_rng(seed)
    return [-1] + [int(rng.integers(max(0, k - max_back), k)) for k in range(1, n)]


def _chain_with_leaves(n_chain, n_leaves):
    """A long chain with many leaves on its last body: too deep and too wide for level steps."""
    return list(range(-1, n_chain - 1)) + [n_chain - 1] * n_leaves


TREES = {
    "single": [-1],
    "chain": list(range(-1, 9)),
    "star": [-1] + [0] * 9,
    "branched": list(FIVE.parents),
    "forest": [-1, -1, 0, 1, 1, 2, -1],
    "random": _random_parents(17, seed=3),
    "random_wide": _random_parents(30, seed=4, max_back=12),
    "sequential": _chain_with_leaves(12, 12),
}


def test_sequential_and_level_schedules_are_both_exercised(schedule):
    assert Topology(TREES["sequential"]).schedule[0].shape == (24, 1)     # one body per step
    star = (2, 9) if schedule == "levels" else (10, 1)                    # two wide steps
    assert Topology(TREES["star"]).schedule[0].shape == star
    assert Topology(TREES["chain"]).schedule[0].shape == (10, 1)


def _python_forward(parents, matrices, ground):
    """value[k] = value[parent] @ matrices[k]; non-commutative, so order along a path matters."""
    values = [None] * len(parents)
    for k, p in enumerate(parents):
        values[k] = (ground if p < 0 else values[p]) @ matrices[k]
    return np.stack(values)


def _python_subtree(parents, weights, matrices):
    """received[k] = weights[k] + sum over children c of matrices[c] @ received[c]."""
    received = [np.array(w, dtype=float) for w in weights]
    ground = np.zeros_like(received[0])
    for k in reversed(range(len(parents))):
        sent = matrices[k] @ received[k]
        if parents[k] >= 0:
            received[parents[k]] = received[parents[k]] + sent
        else:
            ground = ground + sent
    return np.stack(received), ground


@pytest.mark.parametrize("name", list(TREES))
def test_forward_pass_depth_and_path_products(name, schedule):
    parents = TREES[name]
    top, n = Topology(parents), len(parents)
    depth = forward_pass(top, lambda d, _: d + 1, jnp.array(-1))
    np.testing.assert_array_equal(depth, top.depth)
    np.testing.assert_array_equal(depth, [len(_ancestors_by_walking(parents, k)) for k in range(n)])

    rng = np.random.default_rng(len(name))
    M, G = rng.normal(size=(n, 3, 3)), rng.normal(size=(2, 3))
    # A pytree state: (product along the path, sum of inputs along the path).
    x = rng.normal(size=n)
    prod, total = forward_pass(top, lambda parent, inp: (parent[0] @ inp[0], parent[1] + inp[1]),
                               (jnp.asarray(G), jnp.array(0.0)), (jnp.asarray(M), jnp.asarray(x)))
    np.testing.assert_allclose(prod, _python_forward(parents, M, G), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(total, top.path_matrix() @ x, rtol=1e-12)   # pi sums the path


@pytest.mark.parametrize("name", list(TREES))
def test_backward_pass_subtree_sizes_and_transported_sums(name, schedule):
    parents = TREES[name]
    top, n = Topology(parents), len(parents)
    size, ground = backward_pass(top, lambda r, _: (r, r), jnp.ones(n, dtype=int))
    expected = [1 + len(top.descendants(k)) for k in range(n)]
    np.testing.assert_array_equal(size, expected)
    np.testing.assert_array_equal(size, top.path_matrix().sum(0))          # column sums of pi
    assert int(ground) == n

    rng = np.random.default_rng(len(name) + 100)
    w, M = rng.normal(size=(n, 3)), rng.normal(size=(n, 3, 3)) / 2
    # pytree outputs of different shapes; what goes to the parent is transported by M[k]
    (doubled, norm2), ground = backward_pass(top, lambda r, X: ((2.0 * r, r @ r), X @ r),
                                             jnp.asarray(w), jnp.asarray(M))
    ref, ref_ground = _python_subtree(parents, w, M)
    np.testing.assert_allclose(doubled, 2.0 * ref, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(norm2, np.sum(ref**2, axis=1), rtol=1e-12)
    np.testing.assert_allclose(ground, ref_ground, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("name", ["chain", "random", "sequential"])
def test_passes_are_differentiable(name, schedule):
    """Reverse mode through both passes matches the plain-Python recursion's derivative."""
    parents = TREES[name]
    top, n = Topology(parents), len(parents)
    x = jnp.asarray(np.random.default_rng(0).normal(size=n))

    def f(x):
        path_sum = forward_pass(top, lambda p, xk: p + jnp.sin(xk), jnp.array(0.0), x)
        subtree, _ = backward_pass(top, lambda r, _: (r, r), path_sum * x)
        return jnp.sum(subtree ** 2)

    pi = top.path_matrix().astype(float)

    def reference(x):
        return jnp.sum((pi.T @ ((pi @ jnp.sin(x)) * x)) ** 2)

    np.testing.assert_allclose(jax.jit(f)(x), reference(x), rtol=1e-12)
    np.testing.assert_allclose(jax.jit(jax.grad(f))(x), jax.grad(reference)(x), rtol=1e-10)


def test_long_chain_pass_is_one_scan():
    """A 1000-body chain: the passes trace to one scan (no unrolled loop over bodies) and give
    the right depths and subtree sizes."""
    n = 1000
    top = Topology(np.arange(n) - 1)

    @jax.jit
    def run(w):
        depth = forward_pass(top, lambda d, _: d + 1, jnp.array(-1))
        sizes, ground = backward_pass(top, lambda r, _: (r, r), w)
        return depth, sizes, ground

    depth, sizes, ground = run(jnp.ones(n, dtype=int))
    np.testing.assert_array_equal(depth, np.arange(n))
    np.testing.assert_array_equal(sizes, n - np.arange(n))
    assert int(ground) == n
    # The traced program does not grow with n: two scans and a handful of equations.
    counts = _count_equations(jax.make_jaxpr(run)(jnp.ones(n, dtype=int)).jaxpr)
    assert counts["scan"] == 2
    assert counts["total"] < 200


def _count_equations(jaxpr, counts=None):
    """Equations of a jaxpr and its sub-jaxprs (scan bodies, nested jits), by primitive."""
    counts = {"total": 0} if counts is None else counts
    for eqn in jaxpr.eqns:
        counts["total"] += 1
        counts[eqn.primitive.name] = counts.get(eqn.primitive.name, 0) + 1
        for param in eqn.params.values():
            for sub in param if isinstance(param, (tuple, list)) else (param,):
                if hasattr(sub, "jaxpr") and hasattr(sub, "consts"):      # ClosedJaxpr
                    _count_equations(sub.jaxpr, counts)
                elif hasattr(sub, "eqns"):                                # Jaxpr
                    _count_equations(sub, counts)
    return counts


def test_pass_program_size_is_flat_in_n():
    """The traced program of a pass is the same size for a chain of 10 and of 1000 bodies."""
    def size(n):
        top = Topology(np.arange(n) - 1)
        def f(w):
            return backward_pass(top, lambda r, _: (r, r), w)[0]
        return _count_equations(jax.make_jaxpr(f)(jnp.ones(n)).jaxpr)["total"]
    assert size(10) == size(1000)


@pytest.mark.parametrize("name", list(TREES))
def test_path_and_outward_sums_against_plain_python(name):
    """`path_sum` (pi x) and `outward_sum` (pi^T x), for a chain by the passes and for a
    branched tree by the path matrix, against sums over each body's path and outward set walked
    in plain Python, for a pytree of arrays, also under `jax.vmap`."""
    parents = TREES[name]
    top, n = Topology(parents), len(parents)
    rng = np.random.default_rng(7)
    x = {"a": rng.normal(size=(n, 3)), "b": rng.normal(size=(n, 2, 2))}

    def path(k):                                    # k's path from the ground, k included
        return [k] + (path(parents[k]) if parents[k] >= 0 else [])

    along = {key: np.stack([sum(a[j] for j in path(k)) for k in range(n)]) for key, a in x.items()}
    outward = {key: np.stack([sum(a[j] for j in range(n) if k in path(j)) for k in range(n)])
               for key, a in x.items()}
    for fn, expected in ((path_sum, along), (outward_sum, outward)):
        got = jax.jit(lambda x: fn(top, x))(x)
        batched = jax.vmap(lambda x: fn(top, x))({k: np.stack([a, 2 * a]) for k, a in x.items()})
        for key in x:
            np.testing.assert_allclose(got[key], expected[key], rtol=1e-12, atol=1e-12)
            np.testing.assert_allclose(batched[key][1], 2 * expected[key], rtol=1e-12, atol=1e-12)
