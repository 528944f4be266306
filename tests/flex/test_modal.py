"""Craig-Bampton reduction (Anderson 1993 sec. 2.2, eq (10)) and the mass-point cloud (eqs (36)-(42))."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax._src.flex.beam import Beam, dof_groups, eigenmodes, free_dofs
from mbjax._src.flex.modal import craig_bampton, reduced
from mbjax._src.flex.points import centreline, mass_points, node_shapes, shape_at

N = 6  # elements: 7 nodes, 42 dofs


def beam(**kw):
    return Beam.rectangle(1.0, 0.02, 0.01, 2.1e11, 7800.0, nu=0.3, n_elements=N, **kw)


def test_all_modes_reproduce_full_model():
    b = beam()
    M, K = b.matrices()
    f = free_dofs(b)
    w_full, _ = eigenmodes(M, K, f, dof_groups(f))
    basis = craig_bampton(b, n_modes=len(f))
    assert basis.kinds == ("normal",) * len(f)
    Mr, Kr = reduced(b, basis)
    np.testing.assert_allclose(Mr, np.eye(len(f)), atol=1e-10)
    np.testing.assert_allclose(np.sqrt(np.diag(Kr)), w_full, rtol=1e-10)
    np.testing.assert_allclose(basis.frequencies, w_full, rtol=1e-12)
    assert np.all(basis.shapes[:6] == 0)  # body frame clamped at J (node 0)


def test_selection_by_count_and_cutoff():
    b = beam()
    by_count = craig_bampton(b, n_modes=4)
    all_w = craig_bampton(b, n_modes=10).frequencies
    cut = 0.5 * float(all_w[3] + all_w[4])
    by_cut = craig_bampton(b, cutoff=cut)
    assert by_cut.mu == 4
    np.testing.assert_allclose(by_cut.frequencies, by_count.frequencies)
    np.testing.assert_allclose(jnp.abs(by_cut.shapes), jnp.abs(by_count.shapes), atol=1e-9)


def test_bad_input():
    b = beam()
    with pytest.raises(ValueError, match="exactly one of n_modes or cutoff"):
        craig_bampton(b)
    with pytest.raises(ValueError, match="exactly one of n_modes or cutoff"):
        craig_bampton(b, n_modes=2, cutoff=10.0)
    with pytest.raises(ValueError, match="n_modes must be an integer in 0..36"):
        craig_bampton(b, n_modes=37)
    with pytest.raises(ValueError, match="outside"):
        craig_bampton(b, n_modes=2, interface_nodes=(9,))
    with pytest.raises(ValueError, match="already the clamped"):
        craig_bampton(b, n_modes=2, interface_nodes=(0,))
    with pytest.raises(ValueError, match="already the clamped or interface"):
        craig_bampton(b, n_modes=2, interface_nodes=(3,), static_load_nodes=(3,))
    with pytest.raises(ValueError, match="empty basis"):
        craig_bampton(b, n_modes=0)
    with pytest.raises(ValueError, match="concrete"):
        jax.jit(lambda E: craig_bampton(Beam.round(1.0, 0.01, E, 7800.0, nu=0.3, n_elements=N),
                                        cutoff=100.0).shapes)(2e11)


def _static(b, F, basis=None):
    M, K = b.matrices()
    f = free_dofs(b)
    if basis is None:
        return jnp.zeros(b.n_dofs).at[f].set(jnp.linalg.solve(K[np.ix_(f, f)], F[f]))
    _, Kr = reduced(b, basis)
    return basis.shapes @ jnp.linalg.solve(Kr, basis.shapes.T @ F)


def test_constraint_and_static_modes_make_statics_exact():
    """Loads at interface nodes (constraint modes) or at static-load nodes (static modes) are
    reproduced exactly by the reduced model, with only 2 normal modes."""
    b = beam()
    F = jnp.zeros(b.n_dofs).at[6 * 3 + 1].set(3.0).at[6 * 6 + np.arange(6)].set(jnp.arange(1.0, 7.0))
    exact = _static(b, F)
    for kw, ortho in ((dict(interface_nodes=(3, 6)), True), (dict(interface_nodes=(3, 6)), False),
                      (dict(interface_nodes=(6,), static_load_nodes=(3,)), True)):
        basis = craig_bampton(b, n_modes=2, orthonormalize=ortho, **kw)
        np.testing.assert_allclose(_static(b, F, basis), exact, rtol=1e-9, atol=1e-9 * np.abs(exact).max())
        Mr, Kr = reduced(b, basis)
        if ortho:
            assert basis.kinds == ("reduced",) * 14
            np.testing.assert_allclose(Mr, np.eye(14), atol=1e-9)
            np.testing.assert_allclose(Kr, np.diag(basis.frequencies**2), atol=1e-8 * float(Kr.max()))
        else:
            assert basis.kinds == ("normal",) * 2 + ("constraint",) * 12
            assert np.all(np.isnan(basis.frequencies[2:]))
    # without them, two normal modes miss the interface deflection
    basis = craig_bampton(b, n_modes=2)
    assert abs(_static(b, F, basis)[6 * 6 + 1] / exact[6 * 6 + 1] - 1) > 1e-3


def test_planar_basis_and_interface_frequencies_bound():
    """A planar basis lives on (ux, uy, rz); reduced frequencies bound the full ones from above."""
    b = beam()
    basis = craig_bampton(b, n_modes=3, interface_nodes=(6,), planar="xy")
    keep = np.zeros(6, bool)
    keep[[0, 1, 5]] = True
    assert np.all(basis.shapes[~np.tile(keep, N + 1)] == 0) and basis.mu == 6
    M, K = b.matrices()
    f = free_dofs(b, planar="xy")
    w_full, _ = eigenmodes(M, K, f)
    assert np.all(basis.frequencies >= w_full[:6] * (1 - 1e-12))
    np.testing.assert_allclose(basis.frequencies[0], w_full[0], rtol=1e-4)


@pytest.mark.parametrize("timoshenko", [False, True])
def test_mass_points_reproduce_consistent_mass(timoshenko):
    b = beam(timoshenko=timoshenko)
    basis = craig_bampton(b, n_modes=8, interface_nodes=(6,))
    p = mass_points(b, basis)
    Mr, _ = reduced(b, basis)
    Mp = (jnp.einsum("p,pim,pin->mn", p.mass, p.phi, p.phi)
          + jnp.einsum("pim,pij,pjn->mn", p.psi, p.inertia, p.psi))
    np.testing.assert_allclose(Mp, Mr, atol=1e-12)
    m = float(b.rho * b.A)
    np.testing.assert_allclose(p.mass.sum(), m, rtol=1e-14)
    np.testing.assert_allclose(p.mass @ p.position, [m / 2, 0, 0], rtol=1e-14, atol=1e-16)
    assert p.mass.shape == (4 * N,) and p.inertia.shape == (4 * N, 3, 3)


def test_node_and_point_shapes():
    b = beam()
    basis = craig_bampton(b, n_modes=5, static_load_nodes=(6,))
    psi, phi = node_shapes(basis, 4)
    phi_s, psi_s = shape_at(b, basis, 4 * float(b.Le))
    np.testing.assert_allclose(phi_s, phi, atol=1e-13)
    np.testing.assert_allclose(psi_s, psi, atol=1e-13)
    phi_tip, _ = shape_at(b, basis, 1.0)
    np.testing.assert_allclose(phi_tip, node_shapes(basis, N)[1], atol=1e-13)
    # Euler-Bernoulli: rz = duy/dx, ry = -duz/dx, from a finite difference of the interpolated field
    s, h = 0.37, 1e-6
    dphi = (shape_at(b, basis, s + h)[0] - shape_at(b, basis, s - h)[0]) / (2 * h)
    _, psi_s = shape_at(b, basis, s)
    np.testing.assert_allclose(psi_s[2], dphi[1], atol=1e-6 * float(jnp.abs(dphi).max()))
    np.testing.assert_allclose(psi_s[1], -dphi[2], atol=1e-6 * float(jnp.abs(dphi).max()))
    # the centreline (for pictures): the undeformed axis plus each grid node's shapes times q
    q = jnp.asarray(np.random.default_rng(0).normal(size=(2, basis.shapes.shape[1])))
    line = centreline(b, basis, q, points=N + 1, magnification=3.0)
    nodes = np.stack([np.asarray(node_shapes(basis, k)[1]) for k in range(N + 1)])   # (N+1, 3, mu)
    axis = np.linspace(0.0, float(b.L), N + 1)[:, None] * np.array([1.0, 0.0, 0.0])
    np.testing.assert_allclose(line, axis + 3.0 * np.einsum("kim,tm->tki", nodes, q), atol=1e-12)
