"""Lagrange time elements and Gauss-Legendre rules against closed forms and identities."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax.tfe import Element, ExactQuadrature, ReducedQuadrature
from mbjax._src.tfe import gauss_legendre, lagrange

QUADRATURES = {"exact": ExactQuadrature(), "reduced": ReducedQuadrature()}


@pytest.mark.parametrize("points", [1, 2, 3, 4, 5])
def test_gauss_rule_is_exact_to_degree_2p_minus_1(points):
    tau, w = gauss_legendre(points)
    assert np.all((tau > 0) & (tau < 1)) and np.isclose(w.sum(), 1.0, rtol=0, atol=1e-15)
    for degree in range(2 * points):
        assert np.isclose(w @ tau**degree, 1.0 / (degree + 1), rtol=1e-14)
    # and not beyond: the first moment it misses
    assert not np.isclose(w @ tau ** (2 * points), 1.0 / (2 * points + 1), rtol=1e-12)


def test_one_point_rule_is_the_midpoint():
    """§7: reduced integration of the two-node element uses one Gauss point, tau = 1/2."""
    tau, w = gauss_legendre(1)
    np.testing.assert_array_equal(tau, [0.5])
    np.testing.assert_array_equal(w, [1.0])


@pytest.mark.parametrize("nodes", [2, 3, 4, 7])
def test_lagrange_kronecker_partition_of_unity_and_polynomial_reproduction(nodes):
    node_tau = np.linspace(0, 1, nodes)
    s, ds = lagrange(node_tau, node_tau)
    np.testing.assert_allclose(s, np.eye(nodes), atol=1e-12)           # s_k(t_j) = delta_kj
    tau = np.linspace(-0.2, 1.3, 17)
    s, ds = lagrange(node_tau, tau)
    np.testing.assert_allclose(s.sum(1), 1.0, rtol=1e-12)
    np.testing.assert_allclose(ds.sum(1), 0.0, atol=1e-10)
    for degree in range(nodes):                                        # degree n - 1 exactly
        np.testing.assert_allclose(s @ node_tau**degree, tau**degree, rtol=1e-11, atol=1e-12)
        np.testing.assert_allclose(ds @ node_tau**degree, degree * tau ** max(degree - 1, 0) * (degree > 0),
                                   rtol=1e-10, atol=1e-11)


@pytest.mark.parametrize("nodes", [2, 3, 4])
def test_lagrange_derivative_matches_autodiff_of_the_interpolant(nodes):
    node_tau = np.linspace(0, 1, nodes)
    values = jnp.asarray(np.random.default_rng(nodes).normal(size=nodes))

    def interpolant(t):
        prod = jnp.prod(jnp.where(jnp.eye(nodes, dtype=bool), 1.0,
                                  (t - node_tau[None, :]) / (node_tau[:, None] - node_tau[None, :]
                                                             + jnp.eye(nodes))), axis=1)
        return prod @ values

    tau = np.array([0.1, 0.37, 0.8])
    _, ds = lagrange(node_tau, tau)
    np.testing.assert_allclose(ds @ np.asarray(values), jax.vmap(jax.grad(interpolant))(jnp.asarray(tau)),
                               rtol=1e-12)


@pytest.mark.parametrize("nodes", [2, 3, 4])
@pytest.mark.parametrize("quadrature", ["exact", "reduced"])
def test_element_tables(nodes, quadrature):
    element = Element(nodes, QUADRATURES[quadrature])
    assert element.points == (nodes if quadrature == "exact" else nodes - 1)
    assert element.s.shape == element.ds.shape == (element.points, nodes)
    assert element.length(0.1) == pytest.approx((nodes - 1) * 0.1)
    # the element mass-like matrix int ds ds^T dtau: exact integration gets it right, reduced
    # integration of the two-node element is exact too (ds is constant) but of s s^T is not
    exact = Element(nodes)                     # ExactQuadrature(), the default
    M = (element.ds * element.weights[:, None]).T @ element.ds
    M_exact = (exact.ds * exact.weights[:, None]).T @ exact.ds
    if quadrature == "exact" or nodes == 2:
        np.testing.assert_allclose(M, M_exact, rtol=1e-12, atol=1e-14)
    N = (element.s * element.weights[:, None]).T @ element.s
    if nodes == 2:
        # eq 7.6: int s_1 s_1 dt = a dt / 2 and int s_1 s_2 dt = b dt / 2, with a = 2/3, b = 1/3
        # for exact integration and a = b = 1/2 with one Gauss point
        a, b = 2 * N[0, 0], 2 * N[0, 1]
        np.testing.assert_allclose((a, b), (2 / 3, 1 / 3) if quadrature == "exact" else (0.5, 0.5),
                                   rtol=1e-14)
    # a static argument of solve_tfe: equal elements hash alike, whatever instance of the rule
    assert hash(element) == hash(Element(nodes, type(QUADRATURES[quadrature])()))
    assert element == Element(nodes, type(QUADRATURES[quadrature])())


@pytest.mark.parametrize("args, match", [((1,), "at least 2 nodes"), ((2.0,), "at least 2 nodes")])
def test_element_rejects_bad_input(args, match):
    with pytest.raises(ValueError, match=match):
        Element(*args)


@pytest.mark.parametrize("quadrature, hint", [("exact", ""), ("reduced", ""), ("full", ""),
                                              (ExactQuadrature, r" \(an instance")])
def test_element_refuses_a_quadrature_that_is_not_a_strategy_by_name(quadrature, hint):
    with pytest.raises(TypeError, match=r"quadrature must be a quadrature strategy, "
                                        r"ExactQuadrature\(\) or ReducedQuadrature\(\)" + hint):
        Element(3, quadrature)


def test_the_quadratures_are_the_old_strings_rules():
    """ExactQuadrature() is the n-point Gauss-Legendre rule "exact" took, ReducedQuadrature()
    the (n - 1)-point rule of "reduced": the same points, weights and tables."""
    for nodes in (2, 3, 4):
        for quadrature, points in ((ExactQuadrature(), nodes), (ReducedQuadrature(), nodes - 1)):
            element = Element(nodes, quadrature)
            tau, weights = gauss_legendre(points)
            np.testing.assert_array_equal(element.tau, tau)
            np.testing.assert_array_equal(element.weights, weights)
            np.testing.assert_array_equal(element.s, lagrange(element.node_tau, tau)[0])


def test_bad_rules_and_nodes_are_rejected():
    with pytest.raises(ValueError, match="at least one point"):
        gauss_legendre(0)
    with pytest.raises(ValueError, match="distinct"):
        lagrange([0.0, 0.5, 0.5], [0.2])
