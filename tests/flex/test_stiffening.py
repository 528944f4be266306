"""Geometric stiffening (Anderson 1993 eqs (32)-(33), Table 1): Southwell, Euler buckling, the load basis.

Tolerances: the axial force is constant per element (the element average of the exact N(x), as the
linear axial elements deliver it), so the stiffening coefficient converges as O(h^2). Measured
Southwell coefficients K1 for the first mode with 5 / 10 / 20 / 40 elements: 1.2030 / 1.1956 /
1.1938 / 1.1933 against 1.1932 (errors 9.8e-3, 2.4e-3, 6.1e-4, 1.5e-4: ratio 4 per halving). The
tests use 5 and 10 elements, bound the error by 0.3 / n^2 and check the ratio (second order).
"""

import jax.numpy as jnp
import numpy as np
import scipy.linalg

from mbjax._src.flex.beam import Beam, geometric_stiffness
from mbjax._src.flex.modal import craig_bampton, reduced
from mbjax._src.flex.points import mass_points
from mbjax._src.flex.stiffening import (_acceleration_basis, _moment_basis, distal_stiffening,
                                   inertial_scalars, inertial_stiffening)

K1 = 1.1932  # Southwell coefficient of the first cantilever bending mode (Wright et al. 1982: 1.193)


def steel(n):
    return Beam.round(1.0, 0.01, 2.1e11, 7800.0, nu=0.3, n_elements=n)


def spinning(n):
    """3-D basis (both bending planes, 6 modes) and K_inertial of a cantilever with n elements."""
    b = steel(n)
    basis = craig_bampton(b, n_modes=6)
    return b, basis, inertial_stiffening(b, basis)


def southwell(n):
    """(omega^2 - omega_0^2) / Omega^2 of the first in-plane (xy) and out-of-plane (xz) bending
    modes, spinning about body z through the clamp."""
    b, basis, Ki = spinning(n)
    Mr, Kr = reduced(b, basis)
    p = mass_points(b, basis)
    w0 = float(basis.frequencies[0])
    Om = 0.1 * w0  # small spin: the slope of omega^2(Omega^2) at 0, Southwell's coefficient
    s = inertial_scalars(jnp.zeros(3), jnp.zeros(3), jnp.array([0.0, 0.0, Om]))
    assert s[11] == s[20] == Om**2
    KG = jnp.einsum("q,qmn->mn", s, Ki)
    soft = jnp.einsum("p,pm,pn->mn", p.mass, p.phi[:, 1], p.phi[:, 1])  # rotating frame, y only
    lam = scipy.linalg.eigh(np.asarray(Kr + KG - Om**2 * soft), np.asarray(Mr), eigvals_only=True)
    # the modes stay in their plane: the lowest is in-plane (softened), the next out-of-plane
    return (lam[0] - w0**2) / Om**2, (lam[1] - w0**2) / Om**2


def test_southwell_spinning_cantilever():
    """In-plane (xy): omega^2 = omega_0^2 + (K1 - 1) Omega^2; out-of-plane (xz): + K1 Omega^2. The
    O(h^2) error (see module docstring) is 9.8e-3 at 5 elements, 2.4e-3 at 10: bound 0.3 / n^2, and
    the ratio checks the convergence rate."""
    errs = {}
    for n in (5, 10):
        k_in, k_out = southwell(n)
        errs[n] = k_in - (K1 - 1)
        np.testing.assert_allclose(k_out - K1, errs[n], atol=1e-4)  # same K_G, no softening
        assert 0 < errs[n] < 0.3 / n**2
    assert 3.5 < errs[5] / errs[10] < 4.5  # second order


def test_euler_buckling_from_distal_load():
    """det(K_r - P K_distal[tip, force x]) = 0 at P = pi^2 E I / (4 L^2) (compressive tip load; the
    brief's det(K_r + P K) = 0 with P < 0). Full xz basis, so only the mesh error is left: measured
    3.3e-5 (4 elements) and 2.1e-6 (8): fourth order, from above (Rayleigh-Ritz)."""
    errs = []
    for n in (4, 8):
        b = steel(n)
        basis = craig_bampton(b, n_modes=3 * n, planar="xz")  # every axial and xz-bending dof
        _, Kr = reduced(b, basis)
        Kd = distal_stiffening(b, basis, [n, n // 2])
        assert Kd.shape == (2, 6, 3 * n, 3 * n)
        assert np.abs(Kd[:, 1:]).max() == 0  # moments and transverse forces do not stiffen
        P = scipy.linalg.eigvals(np.asarray(Kr), np.asarray(Kd[0, 0]))
        P = np.min(P.real[np.isfinite(P) & (P.real > 0)])
        errs.append(P / (np.pi**2 * float(b.E * b.Iy) / 4.0) - 1)
    assert 0 < errs[0] < 5e-5 and 14 < errs[0] / errs[1] < 18
    # a load at mid-span stresses only the inner half: buckling at pi^2 EI / (4 (L/2)^2)
    P = scipy.linalg.eigvals(np.asarray(Kr), np.asarray(Kd[1, 0]))
    P = np.min(P.real[np.isfinite(P) & (P.real > 0)])
    np.testing.assert_allclose(P, np.pi**2 * float(b.E * b.Iy), rtol=5e-5)


def test_load_basis_matches_table_1():
    """G @ s and H @ s reproduce a + alpha x rho + omega x (omega x rho) and I alpha + omega x I omega."""
    rng = np.random.default_rng(0)
    a, al, om, rho = rng.normal(size=(4, 3))
    Q = rng.normal(size=(3, 3))
    I = Q @ Q.T  # noqa: E741 (the inertia)
    s = inertial_scalars(a, al, om)
    np.testing.assert_allclose(_acceleration_basis(jnp.asarray(rho)) @ s[:12],
                               a + np.cross(al, rho) + np.cross(om, np.cross(om, rho)), atol=1e-12)
    np.testing.assert_allclose(_moment_basis(jnp.asarray(I)) @ s[12:], I @ al + np.cross(om, I @ om),
                               atol=1e-12)


def test_inertial_stiffening_structure():
    """Only axial load fields stiffen a straight beam along x: a_x (q=0), w2^2 (q=9), w3^2 (q=11);
    an axial acceleration a_x is a compressive (D'Alembert) load, so K_inertial[0] is negative
    definite on the bending modes, and the centrifugal cases are positive definite."""
    _, basis, Ki = spinning(10)
    Ki = np.asarray(Ki)
    nonzero = [q for q in range(21) if np.abs(Ki[q]).max() > 1e-9 * np.abs(Ki).max()]
    assert nonzero == [0, 9, 11]
    np.testing.assert_allclose(Ki[9], Ki[11], atol=1e-12 * np.abs(Ki).max())
    assert np.all(np.linalg.eigvalsh(Ki[0]) < 0) and np.all(np.linalg.eigvalsh(Ki[11]) > 0)
    # against K_G of the closed-form axial forces (element averages of the exact N(x)): a_x = 1 pulls
    # every point towards the clamp, N = -m (L - x); spin w3 = 1 gives N = m (L^2 - x^2) / 2
    b = steel(10)
    m, x1 = float(b.rho * b.A), np.arange(10) * 0.1
    x2 = x1 + 0.1
    for q, N in ((0, -m * (1.0 - (x1 + x2) / 2)), (11, m * (1.0 - (x1**2 + x1 * x2 + x2**2) / 3) / 2)):
        ref = basis.shapes.T @ geometric_stiffness(b, jnp.asarray(N)) @ basis.shapes
        np.testing.assert_allclose(Ki[q], ref, atol=1e-10 * np.abs(ref).max())


def test_a_grid_points_second_order_displacement_is_the_beams_foreshortening():
    """The distal unit-load stiffness is the Hessian of the grid point's axial displacement
    (`mbjax._src.flex.kinematics.grid_point`): bent by a static tip load, a cantilever's tip moves in by
    (1/2) int w'^2 dx = (3/5) delta^2 / L for tip deflection delta (the cubic w = delta (3 x^2 L -
    x^3) / (2 L^3), which cubic elements hold exactly), at the tip and, (1/2) int_0^a w'^2 dx, at
    an inner node a; and a load along the beam at the point does work through it that is the
    geometric stiffness K_G(F) q of eq 33."""
    import jax

    from mbjax.flex import beam_body
    from mbjax._src.flex.kinematics import grid_point
    from mbjax._src.flex.points import node_shapes

    n, L = 4, 1.0
    b = Beam(L, 2.1e11, 8e10, 7800.0, 1e-4, 1e-8, 1e-8, 2e-8, n)
    basis = craig_bampton(b, n_modes=3 * n, planar="xy")
    body = beam_body(b, basis, nodes=(n, n // 2))
    _, Kr = reduced(b, basis)
    _, phi_tip = node_shapes(basis, n)
    q = jnp.linalg.solve(Kr, phi_tip[1] * 50.0)                 # 50 N across the tip
    delta = float(phi_tip[1] @ q)
    for h, a in ((0, L), (1, L / 2)):
        args = (body.node_position[h], body.node_phi[h], body.node_psi[h], body.distal_stiffening[h])
        _, o = grid_point(*args, q)
        axial_static = float((body.node_phi[h] @ q)[0])          # the (linear) axial stretch
        slope2 = (9 * delta**2 / (4 * L**6)) * (4 * L**2 * a**3 / 3 - L * a**4 + a**5 / 5)
        np.testing.assert_allclose(float(o[0]) - a - axial_static, -0.5 * slope2, rtol=1e-10)
        F = 3.0                                                   # N along the beam, at the point
        work = jax.grad(lambda q_: F * grid_point(*args, q_)[1][0])(q)
        np.testing.assert_allclose(work, F * body.node_phi[h][0] - F * body.distal_stiffening[h, 0] @ q,
                                   rtol=1e-12, atol=1e-12 * float(jnp.max(jnp.abs(work))))
        if a == L:                                                # the tip: (3/5) delta^2 / L
            np.testing.assert_allclose(0.5 * slope2, 0.6 * delta**2 / L, rtol=1e-12)
