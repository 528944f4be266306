"""Lagrange time elements and Gauss-Legendre quadrature (Borri 1990 §5).

An n-node element spans [t_1, t_1 + (n - 1) dt] with its nodes dt apart (dt is "the time between
nodes" of Tables 1-2). On the unit parameter tau = (t - t_1) / ((n - 1) dt) in [0, 1] the shape
functions are the Lagrange polynomials through equally spaced nodes, s_k(tau_j) = delta_kj
(eqs 5.1-5.2); the weak forms are integrated by Gauss-Legendre quadrature, a strategy the element
takes: `ExactQuadrature()`, n points, which integrates the element's mass-like products
s_dot s_dot exactly, or `ReducedQuadrature()`, n - 1 points (one point fewer, the single Gauss
point of §7 for the two-node element).

Everything here is static numpy, evaluated once per element type: residuals trace only the
resulting constant tables.
"""

import abc
from dataclasses import dataclass
from functools import cached_property

import equinox as eqx
import numpy as np


def gauss_legendre(points: int) -> tuple[np.ndarray, np.ndarray]:
    """The Gauss-Legendre rule on [0, 1], exact for polynomials of degree 2 points - 1.

    Args:
        points: the number of points, a positive int.

    Returns:
        abscissae: the points in (0, 1), shape (points,).
        weights: their weights, summing to 1, shape (points,).

    Raises:
        ValueError: points is not a positive int.
    """
    if not (isinstance(points, int | np.integer) and points >= 1):
        raise ValueError(f"a Gauss rule needs at least one point, got {points!r}")
    x, w = np.polynomial.legendre.leggauss(int(points))
    return (x + 1.0) / 2.0, w / 2.0


def lagrange(nodes: np.ndarray, tau) -> tuple[np.ndarray, np.ndarray]:
    """The Lagrange polynomials through `nodes` (s_k(nodes_j) = delta_kj) and their derivatives.

    Args:
        nodes: distinct nodes, shape (n,).
        tau: where to evaluate, a scalar or shape (P,).

    Returns:
        values: s_k(tau), shape (P, n).
        derivatives: ds_k/dtau, shape (P, n).

    Raises:
        ValueError: the nodes are not distinct.
    """
    nodes = np.asarray(nodes, dtype=float)
    tau = np.atleast_1d(np.asarray(tau, dtype=float))
    n = len(nodes)
    if len(np.unique(nodes)) != n:
        raise ValueError(f"Lagrange nodes must be distinct, got {nodes}")
    values = np.ones((len(tau), n))
    derivatives = np.zeros((len(tau), n))
    for k in range(n):                       # static tables: a loop over the few nodes is fine
        others = np.delete(nodes, k)
        denominator = np.prod(nodes[k] - others)
        factors = tau[:, None] - others[None, :]                  # (P, n - 1)
        values[:, k] = np.prod(factors, axis=1) / denominator
        for m in range(n - 1):               # product rule: drop one factor at a time
            derivatives[:, k] += np.prod(np.delete(factors, m, axis=1), axis=1) / denominator
    return values, derivatives


class AbstractQuadrature(eqx.Module):
    """How many Gauss-Legendre points integrate an element's weak form (Borri 1990 §5, §7):
    `ExactQuadrature()` or `ReducedQuadrature()`, passed to `Element` as `quadrature=`.

    A subclass implements `points`; the rule is Gauss-Legendre's with that many points on the
    element's unit parameter (`gauss_legendre`).
    """

    @abc.abstractmethod
    def points(self, nodes: int) -> int:
        """The number of Gauss points for an element of `nodes` nodes.

        Args:
            nodes: the element's number of nodes, at least 2.

        Returns:
            The number of points, at least 1.
        """


class ExactQuadrature(AbstractQuadrature):
    """Full Gauss-Legendre quadrature: as many points as the element has nodes, which integrates
    its mass-like products s_dot s_dot exactly (Borri 1990's "exact" integration, Table 1)."""

    def points(self, nodes: int) -> int:
        """The number of Gauss points, `nodes`.

        Args:
            nodes: the element's number of nodes, at least 2.

        Returns:
            nodes.
        """
        return nodes


class ReducedQuadrature(AbstractQuadrature):
    """Reduced Gauss-Legendre quadrature: one point fewer than the element has nodes (Borri 1990's
    "reduced" integration, Table 2; the single Gauss point of §7 for the two-node element)."""

    def points(self, nodes: int) -> int:
        """The number of Gauss points, `nodes` - 1.

        Args:
            nodes: the element's number of nodes, at least 2.

        Returns:
            nodes - 1.
        """
        return nodes - 1


@dataclass(frozen=True)
class Element:
    """An n-node Lagrange time element with its quadrature rule (Borri 1990 §5).

    Hashable, so it is a static argument of `solve_tfe`. Tables on the unit parameter tau in
    [0, 1]: `s` and `ds` (points, nodes) are the shape functions and their tau-derivatives at
    the Gauss points `tau` with weights `weights`; with element length h = (nodes - 1) dt,
    ds/dt = ds / h and the integral over the element of f is h sum_g weights_g f(tau_g).

    Args:
        nodes: the number of nodes, at least 2, equally spaced dt apart.
        quadrature: the quadrature strategy, `ExactQuadrature()` (Gauss-Legendre with `nodes`
            points, the default) or `ReducedQuadrature()` (one point fewer; the single Gauss
            point of §7 for the two-node element).

    Raises:
        ValueError: nodes is not an int >= 2.
        TypeError: quadrature is not a quadrature strategy (the strings "exact" and "reduced"
            of old, say).
    """

    nodes: int = 2
    quadrature: AbstractQuadrature = ExactQuadrature()

    def __post_init__(self):
        if not (isinstance(self.nodes, int) and self.nodes >= 2):
            raise ValueError(f"a time element needs at least 2 nodes, got {self.nodes!r}")
        if not isinstance(self.quadrature, AbstractQuadrature):
            hint = (" (an instance: ExactQuadrature(), not ExactQuadrature)"
                    if isinstance(self.quadrature, type) else "")
            raise TypeError(f"quadrature must be a quadrature strategy, ExactQuadrature() or "
                            f"ReducedQuadrature(){hint}, got {self.quadrature!r}")

    @property
    def points(self) -> int:
        """The number of Gauss points: nodes (exact) or nodes - 1 (reduced quadrature)."""
        return self.quadrature.points(self.nodes)

    @cached_property
    def node_tau(self) -> np.ndarray:
        """The nodes on the unit parameter, shape (nodes,)."""
        return np.linspace(0.0, 1.0, self.nodes)

    @cached_property
    def tau(self) -> np.ndarray:
        """The Gauss points on the unit parameter, shape (points,)."""
        return gauss_legendre(self.points)[0]

    @cached_property
    def weights(self) -> np.ndarray:
        """The Gauss weights, summing to 1, shape (points,)."""
        return gauss_legendre(self.points)[1]

    @cached_property
    def s(self) -> np.ndarray:
        """The shape functions at the Gauss points, shape (points, nodes)."""
        return lagrange(self.node_tau, self.tau)[0]

    @cached_property
    def ds(self) -> np.ndarray:
        """The shape functions' tau-derivatives at the Gauss points, shape (points, nodes)."""
        return lagrange(self.node_tau, self.tau)[1]

    @cached_property
    def trial_tau(self) -> np.ndarray:
        """Nodes of the mixed forms' trial space (§5.2, eq 5.7): n - 1 functions, one node at
        the middle of each interval between the element's nodes (any basis of the polynomials
        of degree n - 2 spans the same space)."""
        return (np.arange(self.nodes - 1) + 0.5) / (self.nodes - 1)

    @cached_property
    def s_trial(self) -> np.ndarray:
        """The n - 1 trial functions s_a at the Gauss points, (points, nodes - 1)."""
        return lagrange(self.trial_tau, self.tau)[0]

    def length(self, dt: float) -> float:
        """The element's time span (nodes - 1) dt.

        Args:
            dt: the node spacing [s].

        Returns:
            The element's length [s].
        """
        return (self.nodes - 1) * dt
