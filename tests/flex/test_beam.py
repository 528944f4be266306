"""Beam finite elements (Anderson 1993 eq (9)): element matrices, frequencies, statics, gradients."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax._src.flex.beam import (Beam, axial_forces, dof_groups, eigenmodes, element_mass, element_stiffness,
                             free_dofs, geometric_stiffness, interpolation)

BETA = np.array([1.875104069, 4.694091133, 7.854757438])  # clamped-free roots of cos b cosh b = -1


def steel(n=10, d=0.01, **kw):
    return Beam.round(1.0, d, 2.1e11, 7800.0, nu=0.3, n_elements=n, **kw)


def modes(beam, planar=None):
    M, K = beam.matrices()
    free = free_dofs(beam, planar=planar)
    return eigenmodes(M, K, free, dof_groups(free))


def test_validation():
    with pytest.raises(ValueError, match="n_elements"):
        steel(n=0)
    with pytest.raises(ValueError, match="A must be positive"):
        Beam(1.0, 1.0, 1.0, 1.0, -1.0, 1.0, 1.0, 1.0)
    with pytest.raises(ValueError, match="exactly one of nu or G"):
        Beam.round(1.0, 0.01, 2e11, 7800.0)
    with pytest.raises(ValueError, match="diameter"):
        Beam.round(1.0, 0.0, 2e11, 7800.0, nu=0.3)
    with pytest.raises(ValueError, match="planar"):
        free_dofs(steel(), planar="yz")
    with pytest.raises(ValueError, match="clamped nodes"):
        free_dofs(steel(), clamped_nodes=(11,))


def test_element_matrices_closed_form():
    """Quadrature mass against the textbook consistent mass (translation + rotary inertia)."""
    b = Beam(0.7, 2.0, 0.8, 3.0, 0.5, 0.02, 0.03, 0.04, 1)
    L, m = 0.7, 3.0 * 0.5
    Me = np.asarray(element_mass(b))
    t = m * L / 420 * np.array([[156, 22 * L, 54, -13 * L], [22 * L, 4 * L**2, 13 * L, -3 * L**2],
                                [54, 13 * L, 156, -22 * L], [-13 * L, -3 * L**2, -22 * L, 4 * L**2]])
    r = 3.0 / (30 * L) * np.array([[36, 3 * L, -36, 3 * L], [3 * L, 4 * L**2, -3 * L, -L**2],
                                   [-36, -3 * L, 36, -3 * L], [3 * L, -L**2, -3 * L, 4 * L**2]])
    xy = [1, 5, 7, 11]
    np.testing.assert_allclose(Me[np.ix_(xy, xy)], t + 0.03 * r, rtol=1e-13)
    s = np.diag([1, -1, 1, -1])  # xz plane: ry = -duz/dx
    xz = [2, 4, 8, 10]
    np.testing.assert_allclose(Me[np.ix_(xz, xz)], s @ (t + 0.02 * r) @ s, rtol=1e-13)
    np.testing.assert_allclose(Me[np.ix_([0, 6], [0, 6])], m * L / 6 * np.array([[2, 1], [1, 2]]))
    np.testing.assert_allclose(Me[np.ix_([3, 9], [3, 9])], 3.0 * 0.05 * L / 6 * np.array([[2, 1], [1, 2]]))
    assert np.abs(Me[np.ix_(xy, xz)]).max() == 0 and np.allclose(Me, Me.T)


@pytest.mark.parametrize("timoshenko", [False, True])
def test_stiffness_is_energy_of_interpolation(timoshenko):
    """Przemieniecki's closed form equals the strain energy of the (interdependent) interpolation:
    EA ux'^2 + GJ rx'^2 + E Iz rz'^2 + E Iy ry'^2 + kGA ((uy' - rz)^2 + (uz' + ry)^2)."""
    b = Beam(0.3, 2.0, 0.8, 1.0, 0.5, 0.02, 0.03, 0.04, 1, timoshenko=timoshenko, kappa=0.9)
    x, w = np.polynomial.legendre.leggauss(4)
    K = np.zeros((12, 12))
    for xi, wg in zip((x + 1) / 2, w / 2):
        Nt, Nr = interpolation(b, xi)
        dNt, dNr = [np.asarray(d) / 0.3 for d in jax.jacfwd(lambda s: interpolation(b, s))(xi)]
        Nr = np.asarray(Nr)
        K += 0.3 * wg * (2.0 * 0.5 * np.outer(dNt[0], dNt[0]) + 0.8 * 0.04 * np.outer(dNr[0], dNr[0])
                         + 2.0 * 0.03 * np.outer(dNr[2], dNr[2]) + 2.0 * 0.02 * np.outer(dNr[1], dNr[1])
                         + 0.9 * 0.8 * 0.5 * (np.outer(dNt[1] - Nr[2], dNt[1] - Nr[2])
                                              + np.outer(dNt[2] + Nr[1], dNt[2] + Nr[1])))
    np.testing.assert_allclose(element_stiffness(b), K, rtol=1e-11, atol=1e-11 * np.abs(K).max())


def test_euler_bernoulli_frequencies():
    """Clamped-free bending (both planes), axial and torsional frequencies against closed forms. The
    slender section (L/d = 100) keeps the rotary-inertia shift (~(r/L)^2) below 1e-4."""
    b = steel(n=12)
    w, X = modes(b)
    M, K = b.matrices()
    np.testing.assert_allclose(X.T @ M @ X, np.eye(X.shape[1]), atol=1e-10)
    c = np.sqrt(float(b.E * b.Iz / (b.rho * b.A)))
    bend = BETA**2 * c
    np.testing.assert_allclose(w[:6:2], bend, rtol=2e-4)
    np.testing.assert_allclose(w[1:6:2], bend, rtol=2e-4)
    # axial and torsion: linear elements with consistent mass, error ~ (k pi h)^2 / 24
    free = free_dofs(b)
    for dof, wave in ((0, float(np.sqrt(b.E / b.rho))), (3, float(np.sqrt(b.G / b.rho)))):
        g = free[free % 6 == dof]
        wa, _ = eigenmodes(M, K, g)
        exact = (2 * np.arange(1, 3) - 1) * np.pi / 2 * wave
        np.testing.assert_allclose(wa[:2], exact, rtol=0.01)
        assert abs(wa[0] / exact[0] - 1) < 2e-3


def test_timoshenko_lower_for_stubby_beam():
    eb, ti = steel(n=8, d=0.1), steel(n=8, d=0.1, timoshenko=True)
    w_eb, _ = modes(eb, "xy")
    w_ti, _ = modes(ti, "xy")
    assert w_ti[0] < w_eb[0] and w_ti[1] < w_eb[1]
    # slender: the two agree
    w_eb, _ = modes(steel(n=8, d=0.002), "xy")
    w_ti, _ = modes(steel(n=8, d=0.002, timoshenko=True), "xy")
    np.testing.assert_allclose(w_ti[0], w_eb[0], rtol=1e-5)  # shear ~ (r/L)^2 E / (kappa G)


def test_static_tip_deflection_exact():
    """P L^3 / (3 E I) is exact for cubic elements (and + P L / (kappa G A) for Timoshenko)."""
    for timo in (False, True):
        b = steel(n=4, d=0.05, timoshenko=timo)
        _, K = b.matrices()
        f = free_dofs(b)
        F = jnp.zeros(b.n_dofs).at[6 * 4 + 1].set(100.0)
        u = jnp.zeros(b.n_dofs).at[f].set(jnp.linalg.solve(K[np.ix_(f, f)], F[f]))
        exact = 100.0 / (3 * b.E * b.Iz) + (100.0 / (b.kappa * b.G * b.A) if timo else 0.0)
        np.testing.assert_allclose(u[6 * 4 + 1], exact, rtol=1e-12)
        np.testing.assert_allclose(u[6 * 4 + 5], 100.0 / (2 * b.E * b.Iz), rtol=1e-12)


def test_axial_forces_and_geometric_stiffness():
    b = steel(n=4)
    _, K = b.matrices()
    f = free_dofs(b)
    F = jnp.zeros(b.n_dofs).at[6 * 2].set(10.0)  # axial load at node 2
    u = jnp.zeros(b.n_dofs).at[f].set(jnp.linalg.solve(K[np.ix_(f, f)], F[f]))
    np.testing.assert_allclose(axial_forces(b, u), [10.0, 10.0, 0.0, 0.0], atol=1e-9)
    KG = geometric_stiffness(b, jnp.array([1.0, 2.0, 0.0, 0.0]), torsion=False)
    Le = 0.25
    ref = 2.0 / (30 * Le) * np.array([[36, 3 * Le, -36, 3 * Le], [3 * Le, 4 * Le**2, -3 * Le, -Le**2],
                                      [-36, -3 * Le, 36, -3 * Le], [3 * Le, -Le**2, -3 * Le, 4 * Le**2]])
    d = [7, 11, 13, 17]  # uy, rz of nodes 1 and 2: element 1
    e1 = np.asarray(geometric_stiffness(b, jnp.array([0.0, 2.0, 0.0, 0.0]), torsion=False))
    np.testing.assert_allclose(e1[np.ix_(d, d)], ref, rtol=1e-12)
    assert np.abs(KG[0::6]).max() == 0  # no axial terms
    kt = geometric_stiffness(b, jnp.array([0.0, 2.0, 0.0, 0.0])) - e1
    np.testing.assert_allclose(kt[9, 9], 2.0 * float(b.Iy + b.Iz) / float(b.A) / Le, rtol=1e-12)


def test_gradient_of_frequency_wrt_E():
    """d omega / dE = omega / (2 E) (G held fixed), in-plane and in 3-D with the equal-frequency pair
    of a round section (finite thanks to the split groups / safe eigh)."""
    def first(E, planar):
        b = Beam(1.0, E, 8e10, 7800.0, 7.85e-5, 4.9e-10, 4.9e-10, 9.8e-10, 6)
        return modes(b, planar)[0][0]

    for planar in ("xy", None):
        w, g = jax.value_and_grad(first)(2.1e11, planar)
        np.testing.assert_allclose(g, w / (2 * 2.1e11), rtol=1e-8)
    # the mode shapes' gradients are finite too
    g = jax.grad(lambda E: modes(Beam(1.0, E, 8e10, 7800.0, 7.85e-5, 4.9e-10, 4.9e-10, 9.8e-10, 3))[1][:, 0]
                 .sum())(2.1e11)
    assert np.isfinite(g)
