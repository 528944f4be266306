"""Geometric stiffening of a modal beam, Anderson 1993 eqs (32)-(33) and Table 1 (Banerjee and Dickens).

The body geometric stiffness is linear in 21 temporal scalars s_q of the body's own motion and in
the 6 load components F_h applied by each distal body (eq (33)):

    K_G = sum_q s_q K_inertial[q] + sum_{h in nodes} sum_j F_hj K_distal[h, j],

and the elastic modal force is -(K_r + K_G) q. Each coefficient matrix is phi^T K_G(N) phi with N
the element axial forces of a static analysis (body clamped at J^k) under the corresponding unit
load case, and K_G(N) the beam form of eq (32) (`beam.geometric_stiffness`: axial prestress only, so
on a straight beam only loads along the beam axis stiffen it; the other coefficients are zero).
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from mbjax._src.flex.beam import Beam, _gauss, _unit_geometric_stiffness, axial_forces, free_dofs, interpolation
from mbjax._src.flex.modal import ModalBasis
from mbjax._src.flex.points import mass_points

__all__ = ["distal_stiffening", "inertial_stiffening", "inertial_scalars"]

_N_GAUSS = 4  # exact consistent loads for the (linear) inertial load fields on cubic elements


def inertial_scalars(a, alpha, omega):
    """The 21 temporal scalars s of Anderson 1993 Table 1 from the body-frame classical acceleration a of
    J^k, angular acceleration alpha and angular velocity omega:
    s = (a, alpha, w1^2, w1 w2, w1 w3, w2^2, w2 w3, w3^2, alpha, w1^2, w1 w2, w1 w3, w2^2, w2 w3, w3^2)."""
    w1, w2, w3 = omega[0], omega[1], omega[2]
    ww = jnp.stack([w1 * w1, w1 * w2, w1 * w3, w2 * w2, w2 * w3, w3 * w3])
    return jnp.concatenate([jnp.asarray(a), jnp.asarray(alpha), ww, jnp.asarray(alpha), ww])


def _acceleration_basis(rho):
    """G (3, 12) with a + alpha x rho + omega x (omega x rho) = G @ s[0:12], Table 1 rows 1-12."""
    r1, r2, r3 = rho[0], rho[1], rho[2]
    z, o = jnp.zeros_like(r1), jnp.ones_like(r1)
    cols = [jnp.stack(c) for c in (
        (o, z, z), (z, o, z), (z, z, o),                                     # a
        (z, -r3, r2), (r3, z, -r1), (-r2, r1, z),                            # alpha x rho
        (z, -r2, -r3), (r2, r1, z), (r3, z, r1),                             # w1^2, w1 w2, w1 w3
        (-r1, z, -r3), (z, r3, r2), (-r1, -r2, z))]                          # w2^2, w2 w3, w3^2
    return jnp.stack(cols, axis=1)


def _moment_basis(I):  # noqa: E741 (Anderson 1993 eq 37)
    """H (3, 9) with I alpha + omega x I omega = H @ s[12:21], Table 1 rows 13-21."""
    e = jnp.eye(3)
    pairs = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)]
    quad = [jnp.cross(e[i], I @ e[j]) + (jnp.cross(e[j], I @ e[i]) if i != j else 0.0) for i, j in pairs]
    return jnp.concatenate([I, jnp.stack(quad, axis=1)], axis=1)


def _static_axial_forces(beam: Beam, F, clamped_node):
    """Element axial forces (n_elements, k) of the static response to nodal loads F (6N, k), body
    clamped at J^k = `clamped_node` (its reaction balances the loads)."""
    _, K = beam.matrices()
    f = free_dofs(beam, (clamped_node,))
    c = jax.scipy.linalg.cho_factor(K[np.ix_(f, f)], lower=True)
    u = jnp.zeros_like(F).at[f].set(jax.scipy.linalg.cho_solve(c, F[f]))
    return axial_forces(beam, u)


def _project(beam: Beam, basis: ModalBasis, N, torsion):
    """sum_e N_e[..] phi_e^T kg phi_e: (k, mu, mu) from element axial forces N (n_elements, k)."""
    Pe = basis.shapes[beam.element_dofs()]  # (E, 12, mu)
    ke = jnp.einsum("ekm,kl,eln->emn", Pe, _unit_geometric_stiffness(beam, torsion), Pe)
    return jnp.einsum("eq,emn->qmn", N, ke)


@eqx.filter_jit
def inertial_stiffening(beam: Beam, basis: ModalBasis, clamped_node=0, torsion=True):
    """K_inertial (21, mu, mu): the inertial part of Anderson 1993 eq (33), K_G = sum_q s_q K_inertial[q].

    In the body frame with origin at the clamped grid J (node `clamped_node`), a is the classical
    acceleration of J, alpha the angular acceleration and omega the angular velocity; the scalars s
    are ordered as in Table 1 (see `inertial_scalars`): s[0:3] = a, s[3:6] = alpha,
    s[6:12] = (w1^2, w1 w2, w1 w3, w2^2, w2 w3, w3^2), s[12:15] = alpha, s[15:21] = the same omega
    products. Rows 1-12 are the D'Alembert forces -m_p (a + alpha x rho_p + omega x (omega x rho_p))
    on the mass points (rho_p the undeformed position from J), rows 13-21 the D'Alembert moments
    -(I_p alpha + omega x I_p omega) of the section rotary inertia. K_inertial[q] is phi^T K_G(N_q) phi
    with N_q the axial forces for the q-th unit case, i.e. the load field d/ds_q of the total. This is
    minus the loads printed in Table 1 (which lists m times the acceleration), so that the modal
    geometric stiffness for the actual motion is + sum_q s_q K_inertial[q] (centrifugal tension
    stiffens). Distributed loads enter as consistent nodal loads: point loads at the 4 Gauss points
    per element (those of `mass_points`) through the element interpolation, exact for these fields.
    """
    pts = mass_points(beam, basis, _N_GAUSS)
    x0 = beam.node_x()[clamped_node]
    rho = pts.position - jnp.array([1.0, 0.0, 0.0]) * x0
    f = -pts.mass[:, None, None] * jax.vmap(_acceleration_basis)(rho)  # (P, 3, 12)
    t = -jax.vmap(_moment_basis)(pts.inertia)  # (P, 3, 9)
    xi, _ = _gauss(_N_GAUSS)
    Nt, Nr = jax.vmap(lambda x: interpolation(beam, x))(xi)  # (G, 3, 12)
    E = beam.n_elements
    fe = jnp.einsum("gik,egiq->ekq", Nt, f.reshape(E, _N_GAUSS, 3, 12))
    te = jnp.einsum("gik,egiq->ekq", Nr, t.reshape(E, _N_GAUSS, 3, 9))
    loads = jnp.concatenate([fe, te], axis=-1)  # (E, 12 dofs, 21 cases)
    F = jnp.zeros((beam.n_dofs, 21)).at[beam.element_dofs()].add(loads)
    return _project(beam, basis, _static_axial_forces(beam, F, clamped_node), torsion)


def distal_stiffening(beam: Beam, basis: ModalBasis, nodes, clamped_node=0, torsion=True):
    """K_distal (len(nodes), 6, mu, mu): the distal-body part of Anderson 1993 eq (33), K_G per unit load
    applied at grid node h by a distal body, components (force x, y, z, moment x, y, z) in the body
    frame, reacted at J (`clamped_node`); a load F (6,) at node h adds sum_j F_j K_distal[h, j].
    Only force x (along the beam) is nonzero in the axial-prestress approximation of eq (32)."""
    nodes = tuple(int(n) for n in np.atleast_1d(np.asarray(nodes, dtype=int)))
    if any(not 0 <= n < beam.n_nodes for n in nodes):
        raise ValueError(f"distal_stiffening: nodes {nodes} outside 0..{beam.n_nodes - 1}")
    return _distal(beam, basis, nodes, int(clamped_node), bool(torsion))


@eqx.filter_jit
def _distal(beam, basis, nodes, clamped_node, torsion):
    nodes = np.array(nodes)
    dofs = (6 * nodes[:, None] + np.arange(6)).ravel()
    F = jnp.zeros((beam.n_dofs, len(dofs))).at[dofs, np.arange(len(dofs))].set(1.0)
    Kd = _project(beam, basis, _static_axial_forces(beam, F, clamped_node), torsion)
    return Kd.reshape(len(nodes), 6, basis.mu, basis.mu)
