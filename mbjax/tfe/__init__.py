"""Time finite elements for rigid-body dynamics (seed 000): elements and quadrature so far; the
weak forms, Newton per element and the transition matrices are issue 4's remaining work."""

from mbjax.tfe.elements import QUADRATURES, Element, gauss_legendre, lagrange

__all__ = ["QUADRATURES", "Element", "gauss_legendre", "lagrange"]
