"""Mass-point cloud of a modal beam: the grid points P^{k,i} of Anderson 1993 eqs (5)-(8), (36)-(42).

Mass and section rotary inertia are lumped at the Gauss points of each element (the quadrature
that defines the consistent mass matrix, `beam.element_mass`), so the time-invariant modal
coefficients of Anderson 1993 (e.g. eq (58): sum_i Phi^T I_1 Phi) are sums over points, and with
n_gauss = 4 they reproduce phi^T M phi exactly (cubic interpolation, degree-6 integrands).
Translational shapes phi use the element interpolation (Hermite cubic transverse, linear axial);
rotational shapes psi are torsion (linear) and the bending section rotations (rz = duy/dx,
ry = -duz/dx for Euler-Bernoulli; the interdependent Timoshenko rotations otherwise). The beam
axis is the body x axis, so element and body components coincide. Since the basis is clamped at
J^k (node 0 by default), phi and psi are already relative to J^k as eqs (6)-(7) require.
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from mbjax._src.flex.beam import Beam, _gauss, interpolation
from mbjax._src.flex.modal import ModalBasis

__all__ = ["MassPoints", "mass_points", "node_shapes", "shape_at"]


class MassPoints(eqx.Module):
    """P = n_elements * n_gauss points, element-major. Body-frame components throughout.

    mass (P,), position (P, 3) undeformed (r^{k,i}, eq (6) with J^k at node 0), phi (P, 3, mu),
    psi (P, 3, mu) (eqs (7)-(8)), inertia (P, 3, 3) section rotary inertia I^{k,i} (eq (37))."""

    mass: jax.Array
    position: jax.Array
    phi: jax.Array
    psi: jax.Array
    inertia: jax.Array


def mass_points(beam: Beam, basis: ModalBasis, n_gauss=4) -> MassPoints:
    """Gauss-point masses m = rho A Le w_g and inertias rho Le w_g diag(Iy + Iz, Iy, Iz) (w_g the
    weights on [0, 1], i.e. Le w_g / 2 on [-1, 1]) with the modal shapes there."""
    if isinstance(n_gauss, bool) or int(n_gauss) != n_gauss or n_gauss < 1:
        raise ValueError(f"mass_points: n_gauss must be an integer >= 1, got {n_gauss!r}")
    return _mass_points(beam, basis, int(n_gauss))


@eqx.filter_jit
def _mass_points(beam, basis, n_gauss):
    xi, w = _gauss(n_gauss)
    Nt, Nr = jax.vmap(lambda x: interpolation(beam, x))(xi)  # (G, 3, 12)
    Pe = basis.shapes[beam.element_dofs()]  # (E, 12, mu)
    phi = jnp.einsum("gik,ekm->egim", Nt, Pe).reshape(-1, 3, basis.mu)
    psi = jnp.einsum("gik,ekm->egim", Nr, Pe).reshape(-1, 3, basis.mu)
    n_e, _n_g = beam.n_elements, len(w)
    x = ((jnp.arange(n_e)[:, None] + xi[None, :]) * beam.Le).reshape(-1)
    position = jnp.stack([x, jnp.zeros_like(x), jnp.zeros_like(x)], axis=-1)
    wl = jnp.tile(w, n_e) * beam.Le
    Ir = beam.rho * jnp.diag(jnp.stack([beam.Iy + beam.Iz, beam.Iy, beam.Iz]))
    return MassPoints(beam.rho * beam.A * wl, position, phi, psi, wl[:, None, None] * Ir)


def node_shapes(basis: ModalBasis, node):
    """Rotational and translational shapes at grid node `node`: (psi (3, mu), phi (3, mu))."""
    d = 6 * node
    return basis.shapes[d + 3:d + 6], basis.shapes[d:d + 3]


def shape_at(beam: Beam, basis: ModalBasis, s):
    """Translational and rotational shapes at arc length s in [0, L] (interpolated inside its
    element): (phi (3, mu), psi (3, mu))."""
    e = jnp.clip(jnp.floor(s / beam.Le), 0, beam.n_elements - 1).astype(int)
    Nt, Nr = interpolation(beam, s / beam.Le - e)
    Pe = basis.shapes[6 * e + np.arange(12)]
    return Nt @ Pe, Nr @ Pe


def centreline(beam: Beam, basis: ModalBasis, q, points: int = 21, magnification: float = 1.0):
    """The deformed beam axis in the body frame, for a picture.

    Args:
        beam: the beam (along the body x axis, from its root).
        basis: its modal basis.
        q: modal coordinates, shape (..., mu).
        points: number of points, evenly spaced along the axis.
        magnification: factor on the deflection.

    Returns:
        Positions [m], shape (..., points, 3).
    """
    s = jnp.linspace(0.0, beam.L, points)
    phi = jax.vmap(lambda si: shape_at(beam, basis, si)[0])(s)          # (points, 3, mu)
    axis = s[:, None] * jnp.array([1.0, 0.0, 0.0])
    return axis + magnification * jnp.einsum("kim,...m->...ki", phi, jnp.asarray(q))
