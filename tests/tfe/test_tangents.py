"""Autodiff tangents against finite differences, the paper's closed forms (eqs 7.2, 7.5-7.6)
and eq A.47 / A.49."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax import lie
from mbjax.scenes import vertical_top as vt
from mbjax.tfe import (Body, ConstantReference, ConstantVelocityReference, Element, ExactQuadrature,
                       PrimalSymmetric, PrimalUnsymmetric, ReducedQuadrature)
from mbjax._src.tfe import FORMS
from mbjax._src.tfe.tangents import H, element_tangent, pointwise_tangent

RNG = np.random.default_rng(4)


@pytest.mark.parametrize("r", [(0.3, -0.7, 0.5), (1e-3, 2e-3, -1e-3), (2.0, 1.0, -1.5)])
def test_H_closed_form_matches_autodiff_and_eq_A49(r):
    r, b = jnp.array(r), jnp.array([1.2, 0.4, -0.9])
    H_ad = jax.jacfwd(lambda r: lie.gamma(r).T @ b)(r)
    G = lie.gamma(r)
    np.testing.assert_allclose(H(r, b), H_ad, atol=1e-9 if r[0] == 1e-3 else 1e-14)
    np.testing.assert_allclose(H_ad, H_ad.T + G.T @ lie.hat(b) @ G, atol=1e-14)     # eq A.49


def steady_top(spin=vt.CRITICAL_SPIN):
    body = vt.build()
    p_hat = body.mass_matrix(jnp.eye(3)) @ jnp.array([0.0, 0.0, spin])
    ref, _ = ConstantVelocityReference().start(body, 0.0, jnp.eye(3), jnp.zeros(3), p_hat)
    return body, ref, p_hat


def test_primal_tangents_of_the_spinning_top_are_eq_7_2():
    body, ref, p_hat = steady_top()
    J = jnp.diag(jnp.array([vt.J_TRANSVERSE, vt.J_TRANSVERSE, vt.J_AXIAL]))
    L = jnp.diag(jnp.array([1.0, 1.0, 0.0])) * vt.MASS * vt.GRAVITY * vt.D           # eq 7.3
    h_x = lie.hat(p_hat)
    zero = jnp.zeros(3)
    for t in (0.0, 0.37):      # the reference turns, but the tangent about it does not change
        T_hat = eqx.filter_jit(pointwise_tangent)(PrimalUnsymmetric(), body, ref, zero, zero, t)
        np.testing.assert_allclose(T_hat, jnp.block([[J, -h_x], [jnp.zeros((3, 3)), L]]), atol=1e-12)
        T_sym = eqx.filter_jit(pointwise_tangent)(PrimalSymmetric(), body, ref, zero, zero, t)
        np.testing.assert_allclose(T_sym, jnp.block([[J, -h_x / 2], [h_x / 2, L]]), atol=1e-12)


# exact quadrature by default; the reduced rule (covered by default through eqs 7.8-7.9 and
# Table 2) runs with -m slow
@pytest.mark.parametrize("quadrature, a, b", [(ExactQuadrature(), 2 / 3, 1 / 3),
                                              pytest.param(ReducedQuadrature(), 0.5, 0.5,
                                                           marks=pytest.mark.slow)],
                         ids=["exact", "reduced"])
def test_two_node_element_tangent_is_eq_7_5(quadrature, a, b):
    """K_BB of eq 7.5 on the transverse rotations (x, y): a complex entry alpha + i beta is the
    2x2 block [[alpha, -beta], [beta, alpha]] acting on psi = psi_x + i psi_y.

    Integrating eq 7.4 by hand puts +-iC on the diagonal of the unsymmetric form's K_BB and not
    on the symmetric one's (the s_dot s cross terms cancel there): eq 7.5 prints the two
    matrices under each other's names. Both have the same transition eigenvalues (eq 7.7)."""
    body, ref, _ = steady_top()
    dt = 0.13
    mgd = vt.MASS * vt.GRAVITY * vt.D
    A = vt.J_TRANSVERSE / dt + a * mgd * dt / 2                                        # eq 7.6
    B = vt.J_TRANSVERSE / dt - b * mgd * dt / 2
    C = vt.CRITICAL_SPIN * vt.J_AXIAL / 2
    I2, i2 = np.eye(2), np.array([[0.0, -1.0], [1.0, 0.0]])
    element = Element(2, quadrature)
    for form, K_expected in (
            (PrimalUnsymmetric(), [[A * I2 + C * i2, -B * I2 + C * i2],
                                   [-B * I2 - C * i2, A * I2 - C * i2]]),
            (PrimalSymmetric(), [[A * I2, -B * I2 + C * i2], [-B * I2 - C * i2, A * I2]])):
        Q = jnp.zeros((2, 3))
        K = eqx.filter_jit(jax.jacfwd(lambda Q: form.nodal_residual(body, ref, element, dt, Q)))(Q)
        K_BB = np.asarray(K).reshape(6, 6)[np.ix_([0, 1, 3, 4], [0, 1, 3, 4])]
        np.testing.assert_allclose(K_BB, np.block(K_expected), rtol=1e-12, atol=1e-12)


def free_body():
    """6-dof body: O' off the centre of mass (S != 0), gravity, a general inertia."""
    c = np.array([0.1, -0.2, 0.3])
    J_cm = np.array([[2.0, 0.1, 0.0], [0.1, 1.5, -0.2], [0.0, -0.2, 1.0]])
    m = 3.0
    J = J_cm + m * (c @ c * np.eye(3) - np.outer(c, c))
    return Body(m, J, com=c, gravity=(0.0, 0.0, -9.81))


@pytest.mark.parametrize("name", sorted(FORMS))
@pytest.mark.parametrize("reference", [ConstantReference(), ConstantVelocityReference()],
                         ids=["constant", "constant_velocity"])
def test_element_tangent_matches_finite_differences(name, reference):
    body = free_body()
    form = FORMS[name]()
    R1 = lie.exp(jnp.array([0.4, -0.3, 0.8]))
    p_hat1 = body.mass_matrix(R1) @ jnp.array([1.0, -2.0, 3.0, 0.5, 0.1, -0.4])
    ref, _ = reference.start(body, 0.0, R1, jnp.array([0.1, 0.2, 0.3]), p_hat1)
    element, dt = Element(3), 0.05
    z1 = jnp.concatenate([form.to_form(body, jnp.zeros(6), p_hat1), jnp.zeros(6)])
    U = form.guess(body, ref, element, z1) + 0.05 * jnp.asarray(RNG.standard_normal(
        form.n_unknowns(element, 6)))
    K = eqx.filter_jit(element_tangent)(form, body, ref, element, dt, U, z1)
    eps = 1e-6
    residual = jax.jit(jax.vmap(lambda U: form.residual(body, ref, element, dt, U, z1)))
    E = eps * jnp.eye(U.size)
    fd = ((residual(U + E) - residual(U - E)) / (2 * eps)).T
    np.testing.assert_allclose(K, fd, atol=1e-6 * float(jnp.abs(K).max()))


def test_symmetric_primal_kinetic_tangent_is_symmetric():
    """Eq B.16: the kinetic part of T_p is symmetric (no forces here), at a general state."""
    body = Body(3.0, free_body().inertia, com=(0.1, -0.2, 0.3), gravity=(0.0, 0.0, 0.0))
    R1 = lie.exp(jnp.array([0.4, -0.3, 0.8]))
    ref, _ = ConstantVelocityReference().start(
        body, 0.0, R1, jnp.zeros(3), body.mass_matrix(R1) @ jnp.array([1.0, -2.0, 3.0, 0.5, 0.1, -0.4]))
    q, q_dot = jnp.asarray(RNG.standard_normal(6)) * 0.3, jnp.asarray(RNG.standard_normal(6))
    T = eqx.filter_jit(pointwise_tangent)(PrimalSymmetric(), body, ref, q, q_dot, 0.2)
    np.testing.assert_allclose(T, T.T, atol=1e-12 * float(jnp.abs(T).max()))
    T_hat = eqx.filter_jit(pointwise_tangent)(PrimalUnsymmetric(), body, ref, q, q_dot, 0.2)
    assert float(jnp.abs(T_hat - T_hat.T).max()) > 1e-2 * float(jnp.abs(T_hat).max())
