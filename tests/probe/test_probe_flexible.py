"""Probes of flexible bodies (`mbjax.flex`) (issue 43, item 5): inputs drawn by hypothesis, each
answered by a clear error naming the argument or the right answer against an independent
reference (the cantilever's closed-form static deflections and Euler-Bernoulli frequencies,
SciPy's generalized eigenvalues); never a silent NaN.

The shapes stay fixed (4- and 6-element beams) and the drawn values vary, so the beam's matrices,
its modes and its modal body compile once."""

import functools

import jax.numpy as jnp
import numpy as np
import pytest
import scipy.linalg
from hypothesis import Phase, given, settings
from hypothesis import strategies as st

from mbjax.flex import Beam, ModalBasis, beam_body, craig_bampton

# one xdist worker runs the module, so its programs compile once (the group tests/conftest.py
# adds comes after xdist has read the groups)
pytestmark = pytest.mark.xdist_group("tests/probe/test_probe_flexible.py")

# XLA flushes subnormal numbers to zero on the CPU: draws keep clear of them
floats = functools.partial(st.floats, allow_subnormal=False)
FEW = settings(max_examples=15, deadline=None)
# a defect's test stops at its first failing example: no shrinking (each may compile anew)
DEFECT = settings(max_examples=10, deadline=None, phases=[Phase.explicit, Phase.generate])
N_ELEMENTS = 6
NODES = N_ELEMENTS + 1
BEAM = Beam.rectangle(1.0, 0.02, 0.01, 2.1e11, 7800.0, nu=0.3, n_elements=N_ELEMENTS)
MODES = 4
NAMES = ("L", "E", "G", "rho", "A", "Iy", "Iz", "J", "kappa")
GOOD = dict(L=1.0, E=2e11, G=8e10, rho=7800.0, A=1e-4, Iy=2e-9, Iz=5e-9, J=3e-9)


def _interior_eigenvalues(beam, clamped=0):
    """omega^2 of the beam clamped at node `clamped`, by SciPy on the assembled matrices."""
    M, K = (np.asarray(x) for x in beam.matrices())
    free = np.setdiff1d(np.arange(6 * beam.n_nodes), 6 * clamped + np.arange(6))
    return scipy.linalg.eigh(K[np.ix_(free, free)], M[np.ix_(free, free)], eigvals_only=True)


@functools.cache
def _basis():
    """BEAM's basis of MODES normal modes (made on first use: collection stays quick)."""
    return craig_bampton(BEAM, n_modes=MODES)


@functools.cache
def _frequencies():
    """BEAM's clamped frequencies by SciPy."""
    return np.sqrt(_interior_eigenvalues(BEAM))


# -- the beam's parameters ---------------------------------------------------------------------------

@FEW
@given(name=st.sampled_from(NAMES), value=st.sampled_from([0.0, -1.0, -1e-12, np.nan, np.inf, -np.inf]),
       timoshenko=st.booleans())
def test_beam_parameters_that_are_not_positive_and_finite_are_named(name, value, timoshenko):
    with pytest.raises(ValueError, match=f"Beam: {name} must be positive and finite"):
        Beam(**{**GOOD, name: value}, n_elements=4, timoshenko=timoshenko)


@FEW
@given(st.one_of(st.integers(-5, 0), floats(0.1, 9.9).filter(lambda x: x != int(x)),
                 st.just(True), st.just("4")))
def test_element_counts_that_are_not_positive_ints_are_named(n):
    with pytest.raises(ValueError, match="Beam: n_elements must be an integer >= 1"):
        Beam(**GOOD, n_elements=n)


@DEFECT
@given(st.sampled_from([np.nan, np.inf, -np.inf, None]))
def test_element_counts_that_are_not_numbers_are_named(n):
    with pytest.raises(ValueError, match="n_elements"):
        Beam(**GOOD, n_elements=n)


@FEW
@given(nu=st.one_of(floats(-10.0, -1.0), st.just(np.nan)))
def test_a_poisson_ratio_giving_no_positive_shear_modulus_is_named(nu):
    """G = E / (2 (1 + nu)) is not positive (or not finite) for nu <= -1."""
    with pytest.raises(ValueError, match="Beam: G must be positive and finite"):
        Beam.round(1.0, 0.01, 2e11, 7800.0, nu=nu)


# -- statics and modes against closed forms ----------------------------------------------------------

@FEW
@given(L=floats(0.2, 5.0), E=floats(1e9, 4e11), G=floats(1e9, 2e11), A=floats(1e-5, 1e-2),
       Iy=floats(1e-10, 1e-5), Iz=floats(1e-10, 1e-5), J=floats(1e-10, 1e-5),
       timoshenko=st.booleans())
def test_cantilever_tip_deflections_are_the_closed_forms(L, E, G, A, Iy, Iz, J, timoshenko):
    """Clamped at node 0, unit loads at the tip: P L^3 / (3 E I) (+ P L / (kappa G A) with shear),
    P L / (E A), T L / (G J), and the slope P L^2 / (2 E I), all exact for these elements."""
    beam = Beam(L, E, G, 7800.0, A, Iy, Iz, J, 4, timoshenko=timoshenko)
    K = np.asarray(beam.matrices()[1])
    free = np.arange(6, K.shape[0])
    tip = K.shape[0] - 6
    shear = L / (5.0 / 6.0 * G * A) if timoshenko else 0.0
    for load, dof, expected in ((0, 0, L / (E * A)), (1, 1, L**3 / (3 * E * Iz) + shear),
                                (2, 2, L**3 / (3 * E * Iy) + shear), (3, 3, L / (G * J)),
                                (1, 5, L**2 / (2 * E * Iz))):
        u = np.linalg.solve(K[np.ix_(free, free)], np.eye(len(free))[tip - 6 + load])
        np.testing.assert_allclose(u[tip - 6 + dof], expected, rtol=1e-8)


@FEW
@given(L=floats(1.5, 3.0), width=floats(0.005, 0.02), height=floats(0.005, 0.05),
       E=floats(5e10, 3e11), rho=floats(1e3, 1e4))
def test_cantilever_bending_frequencies_are_euler_bernoulli(L, width, height, E, rho):
    """The first two xy bending modes: (1.8751, 4.6941)^2 sqrt(E Iz / (rho A L^4)) (slender beams:
    the radius of gyration under 0.4 % of the length, so the elements' rotary inertia, which the
    closed form leaves out, and their discretization error stay below 0.2 %)."""
    beam = Beam.rectangle(L, width, height, E, rho, nu=0.3, n_elements=N_ELEMENTS)
    basis = craig_bampton(beam, n_modes=2, planar="xy")
    scale = np.sqrt(E * (height * width**3 / 12) / (rho * width * height * L**4))
    np.testing.assert_allclose(basis.frequencies, np.array([1.87510407, 4.69409113])**2 * scale,
                               rtol=2e-3)


# -- Craig-Bampton -----------------------------------------------------------------------------------

@FEW
@given(st.one_of(st.integers(-3, 45), st.just(True), floats(0.5, 9.5).filter(lambda x: x != int(x))))
def test_mode_counts_are_checked_and_give_the_lowest_eigenvalues(n_modes):
    """Valid counts give SciPy's lowest generalized eigenvalues of the clamped beam."""
    interior = 6 * (NODES - 1)
    if isinstance(n_modes, bool) or n_modes != int(n_modes) or not 1 <= n_modes <= interior:
        match = ("empty basis" if n_modes == 0 and not isinstance(n_modes, bool)
                 else rf"n_modes must be an integer in 0\.\.{interior}")
        with pytest.raises(ValueError, match=match):
            craig_bampton(BEAM, n_modes=n_modes)
        return
    basis = craig_bampton(BEAM, n_modes=n_modes)
    np.testing.assert_allclose(basis.frequencies, _frequencies()[:n_modes], rtol=1e-9)


@FEW
@given(st.one_of(st.sampled_from([0.0, -1.0, np.nan, -np.inf]), floats(1.0, 1e5)))
def test_cutoffs_are_checked_and_keep_the_modes_below_them(cutoff):
    if not cutoff > 0:
        with pytest.raises(ValueError, match="cutoff must be positive"):
            craig_bampton(BEAM, cutoff=cutoff)
        return
    count = int(np.sum(_frequencies() <= cutoff))
    if count == 0:
        with pytest.raises(ValueError, match="empty basis"):
            craig_bampton(BEAM, cutoff=cutoff)
        return
    assert craig_bampton(BEAM, cutoff=cutoff).mu == count


@FEW
@given(clamped=st.integers(-3, 10), interface=st.lists(st.integers(-3, 10), max_size=3),
       static=st.lists(st.integers(-3, 10), max_size=2))
def test_node_lists_outside_the_beam_repeated_or_clashing_are_named(clamped, interface, static):
    outside = lambda nodes: any(not 0 <= n < NODES for n in nodes)    # noqa: E731
    clash = (set(interface) & {clamped}) or (set(static) & ({clamped} | set(interface)))
    repeated = len(set(interface)) != len(interface) or len(set(static)) != len(static)
    if not (outside([clamped]) or outside(interface) or outside(static) or clash or repeated):
        return      # a valid layout (the modes' own checks are above): no compilation per layout
    with pytest.raises(ValueError, match="craig_bampton: (clamped_node|interface_nodes|"
                                         "static_load_nodes) .*(outside 0..6|repeated|already)"):
        craig_bampton(BEAM, n_modes=2, clamped_node=clamped, interface_nodes=interface,
                      static_load_nodes=static)


@DEFECT
@given(floats(0.1, NODES - 1.1).filter(lambda x: x != int(x)))
def test_fractional_clamped_nodes_are_named(node):
    with pytest.raises((TypeError, ValueError), match="clamped_node"):
        craig_bampton(BEAM, n_modes=2, clamped_node=node)


# -- the modal body ----------------------------------------------------------------------------------

@FEW
@given(st.integers(1, 12).filter(lambda n: n != N_ELEMENTS), st.integers(1, 4))
def test_a_basis_of_a_beam_with_other_nodes_is_named(n_elements, mu):
    basis = ModalBasis(jnp.zeros((6 * (n_elements + 1), mu)), jnp.ones(mu), ("normal",) * mu)
    with pytest.raises(ValueError, match=rf"basis has shapes for {n_elements + 1} nodes .* but beam "
                                         rf"has {NODES}"):
        beam_body(BEAM, basis)


@FEW
@given(st.sampled_from([(), (MODES,), (MODES, 1), (MODES - 1, MODES - 1), (MODES + 1, MODES),
                        (1, MODES, MODES), (0, 0)]))
def test_damping_of_the_wrong_shape_is_named(shape):
    with pytest.raises(ValueError, match=rf"damping must be the modal damping matrix of shape "
                                         rf"\({MODES}, {MODES}\)"):
        beam_body(BEAM, _basis(), damping=jnp.zeros(shape))


@FEW
@given(nodes=st.lists(st.integers(-5, 12), min_size=1, max_size=3), clamped=st.integers(-2, 9))
def test_attachment_nodes_outside_the_beam_are_named(nodes, clamped):
    bad = [h for h in (*nodes, clamped) if not 0 <= h < NODES]
    if not bad:
        return      # valid attachments compile a body per layout: covered by the module's basis
    with pytest.raises(ValueError, match=rf"nodes and clamped_node must be nodes of the beam "
                                         rf"\(0 \.\.\. {NODES - 1}\), got \[{', '.join(map(str, bad))}\]"):
        beam_body(BEAM, _basis(), nodes=nodes, clamped_node=clamped)


@DEFECT
@given(floats(0.1, NODES - 1.1).filter(lambda x: x != int(x)))
def test_fractional_attachment_nodes_are_named(node):
    with pytest.raises((TypeError, ValueError), match="nodes"):
        beam_body(BEAM, _basis(), nodes=(node,))


@DEFECT
@given(st.integers(4, NODES - 1))
def test_a_basis_clamped_elsewhere_is_named(node):
    """Clamped at a node past the middle, the lowest modes are the long part's, whose free end,
    node 0, moves: node 0 cannot be this basis's joint grid."""
    basis = craig_bampton(BEAM, n_modes=2, clamped_node=node)
    assert np.abs(np.asarray(basis.shapes)[:6]).max() > 0.1          # node 0 moves in this basis
    with pytest.raises(ValueError, match="clamped"):
        beam_body(BEAM, basis, clamped_node=0)
