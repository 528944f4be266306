"""Transition matrices (Borri 1990 §6-7): Tables 1-2, eq 7.10's boundaries, eqs 7.8-7.9, the
paper's eq 6.8 / 6.12 constructions against the implicit-function-theorem Jacobian, and long
marches against the one-element maps."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax import lie
from mbjax_harness.reproduce import top_long_run
from mbjax_harness.reproduce import vertical_top as rep
from mbjax.scenes import vertical_top as vt
from mbjax.tfe import (ConstantVelocityReference, Element, ExactQuadrature, ReducedQuadrature,
                       initial_state, solve_tfe, stability)
from mbjax._src.tfe import FORMS, element_map


# The 2-node rows by default; the 3- and 4-node elements (a compilation each) run with -m slow,
# and by default test_cli's vertical-top reproduction checks every table's rows (every 3rd dt)
# to the same tolerances.
@pytest.mark.parametrize("quadrature", ["exact", "reduced"])
@pytest.mark.parametrize("nodes", [2, pytest.param(3, marks=pytest.mark.slow),
                                   pytest.param(4, marks=pytest.mark.slow)])
def test_tables_1_and_2(quadrature, nodes):
    """Imaginary parts within 2e-4; real parts within 1 % where the table prints more than 1e-4,
    below 1e-4 where it prints less (the paper's round-off floor)."""
    element = Element(nodes, rep.QUADRATURES[quadrature])
    for dt, (re, im) in zip(rep.DTS, rep.PAPER[quadrature][str(nodes)]):
        T = rep.top_transition(vt.CRITICAL_SPIN, dt, form=FORMS["primal"](), element=element)
        e = rep.transverse_exponent(T, element.length(dt))
        assert abs(e.imag - im) <= 2e-4, (dt, e, im)
        if abs(re) > 1e-4:
            assert abs(e.real - re) <= 0.01 * abs(re), (dt, e, re)
        else:
            assert abs(e.real) < 1e-4, (dt, e)


@pytest.mark.parametrize("quadrature, a, b", [("exact", 2 / 3, 1 / 3), ("reduced", 0.5, 0.5)])
def test_two_node_exponents_are_eqs_7_8_and_7_9(quadrature, a, b):
    """lambda = (B + iC) / |B + iC| mu with mu = (A +- sqrt(D)) / |B + iC| (eqs 7.6-7.9), at and
    above the critical spin."""
    element = Element(2, rep.QUADRATURES[quadrature])
    mgd = vt.MASS * vt.GRAVITY * vt.D
    for spin in (vt.CRITICAL_SPIN, 1.3 * vt.CRITICAL_SPIN):
        for dt in (0.05, 0.3):
            A = vt.J_TRANSVERSE / dt + a * mgd * dt / 2
            B = vt.J_TRANSVERSE / dt - b * mgd * dt / 2
            C = spin * vt.J_AXIAL / 2
            norm = np.hypot(B, C)
            mu = (A + np.sqrt(complex(A**2 - B**2 - C**2)) * np.array([1, -1])) / norm
            expected = np.log((B + 1j * C) / norm * mu) / dt
            expected = expected[np.lexsort((expected.real, expected.imag.round(9)))]
            T = rep.top_transition(spin, dt, form=FORMS["primal"](), element=element)
            e = np.asarray(stability.exponents(T, dt))
            e = e[e.imag > 1e-6]
            e = e[np.lexsort((e.real, e.imag.round(9)))]
            np.testing.assert_allclose(e, expected, atol=1e-6)


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow)
                                  if n in ("primal_symmetric", "mixed", "mixed_unsymmetric", "three_field")
                                  else n
                                  for n in sorted(FORMS)])
def test_paper_transition_matrix_equals_the_implicit_function_jacobian(name):
    """Eq 6.8 (condensed primal) or eq 6.12 (mixed, three-field) equals d z_2 / d z_1 of the
    solved element map, differentiated through Newton by the implicit function theorem."""
    body = vt.build()
    form = FORMS[name]()
    p_hat = body.mass_matrix(jnp.eye(3)) @ jnp.array([0.0, 0.0, 1.2 * vt.CRITICAL_SPIN])
    ref, _ = ConstantVelocityReference().start(body, 0.0, jnp.eye(3), jnp.zeros(3), p_hat)
    element, dt = Element(3), 0.1
    z1 = jnp.concatenate([p_hat, jnp.zeros(3)])

    @jax.jit
    def both(z1):
        T = stability.transition_matrix(form, body, ref, element, dt, z1)
        return T, jax.jacfwd(lambda z: element_map(form, body, ref, element, dt, z)[0])(z1)

    T, T_ift = both(z1)
    np.testing.assert_allclose(T, T_ift, atol=1e-12 * float(jnp.abs(T).max()))
    # symplectic forms preserve phase volume: det T = 1 about this steady motion
    assert abs(float(jnp.linalg.det(T)) - 1.0) < 1e-10


@pytest.mark.slow     # test_cli's vertical-top reproduction checks the same boundaries by default
def test_stability_boundaries_of_eq_7_10():
    dts = [0.05, 0.4, 1.0]
    exact = rep.boundary(FORMS["primal"](), Element(2, ExactQuadrature()), dts)
    np.testing.assert_allclose(exact, vt.exact_boundaries(jnp.asarray(dts))[0], rtol=1e-9)
    for form, quadrature in (("primal", ReducedQuadrature()), ("mixed", ExactQuadrature())):
        np.testing.assert_allclose(rep.boundary(FORMS[form](), Element(2, quadrature), dts),
                                   vt.CRITICAL_SPIN, rtol=1e-9)


# primal about the steady rotation by default; the mixed form's bounded march (which test_cli's
# tour checks by default: predicted and measured growth about 0) and the per-element references
# run with -m slow
@pytest.mark.parametrize("name, march", [("primal", "steady"),
                                         pytest.param("mixed", "steady", marks=pytest.mark.slow),
                                         pytest.param("mixed", "constant_velocity",
                                                      marks=pytest.mark.slow)])
def test_long_march_follows_its_one_element_map(name, march):
    """A march of a slightly tilted top is the linear map of one element applied n times: eq 6.8 /
    6.12 for elements about the steady rotation of eq 7.1 (increments carried over), the jacfwd
    Jacobian of the whole step for references built per element. 1.01 Omega_c and dt = 0.5 lie
    between the physical and the primal exact-integration boundaries (`top-long-run`)."""
    form, element, n = FORMS[name](), Element(2), 40
    spin = top_long_run.SPIN_RATIO * vt.CRITICAL_SPIN
    body = vt.build()
    eps = 1e-8
    state0 = initial_state(body, lie.exp(jnp.array([eps, 0.0, 0.0])), jnp.array([0.0, 0.0, spin]))
    reference = (top_long_run.steady_rotation(spin) if march == "steady"
                 else ConstantVelocityReference())
    sol = solve_tfe(body, state0, dt=top_long_run.DT, n_elements=n, form=form, element=element,
                    reference=reference, tol=1e-14)
    assert sol.messages() == ["success"]
    R_o = lie.exp(jnp.array([0.0, 0.0, spin * float(sol.ts[-1])]))      # eq 7.1 at the end
    r_n = lie.log(sol.R[-1] @ R_o.T)
    h_ss = body.mass_matrix(jnp.eye(3)) @ jnp.array([0.0, 0.0, spin])
    q0 = jnp.array([eps, 0.0, 0.0])
    if march == "steady":
        T = rep.top_transition(spin, top_long_run.DT, form=form, element=element)
        z0 = jnp.concatenate([form.to_form(body, q0, state0.p_hat) - form.to_form(body, 0 * q0, h_ss), q0])
    else:
        T = top_long_run.step_transition(form, element, spin, top_long_run.DT)
        z0 = jnp.concatenate([state0.p_hat - h_ss, q0])
        r_n = R_o.T @ r_n       # step_transition's variables are seen from the turning frame
    expected = (np.linalg.matrix_power(np.asarray(T), n) @ np.asarray(z0))[3:]
    growth = np.abs(expected).max() / eps
    if name == "mixed" and march == "steady":
        assert growth < 10      # bounded, like the top itself (its tilt peaks at ~7 eps)
    else:
        assert growth > 10      # rates 0.26 and 0.13 / s over 20 s
    np.testing.assert_allclose(r_n, expected, atol=1e-3 * np.abs(expected).max())
