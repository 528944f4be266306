"""Newton per element and time marching (Borri 1990 §5): convergence orders against the closed
form (eq 8.8), a free 6-dof body against its closed form, quadratic Newton convergence, status
on failure, gradients by the implicit function theorem against finite differences."""

import functools
from functools import partial

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax import lie
from mbjax._src.integrate import Status
from mbjax.rigid import torque_free_motion
from mbjax.scenes import torque_free_body as tfb
from mbjax.tfe import (Body, ConstantReference, ConstantVelocityReference, Element,
                       ExactQuadrature, ReducedQuadrature, Reference, initial_state, solve_tfe)
from mbjax._src.tfe import FORMS, State, element_map

QUADRATURES = {"exact": ExactQuadrature(), "reduced": ReducedQuadrature()}
REFERENCES = {"constant": ConstantReference(), "constant_velocity": ConstantVelocityReference()}

TORQUE_FREE = Body(1.0, jnp.diag(jnp.array([tfb.J_TRANSVERSE, tfb.J_TRANSVERSE, tfb.J_AXIAL])),
                   gravity=(0.0, 0.0, 0.0), fixed_point=True)
STATE0 = initial_state(TORQUE_FREE, jnp.eye(3), jnp.array(tfb.OMEGA0))


@eqx.filter_jit
def one_element(form, element, reference, dt):
    """Rotation error after one element from the exact initial state (the local error)."""
    ref, q1 = reference.start(TORQUE_FREE, 0.0, STATE0.R, STATE0.x, STATE0.p_hat)
    z1 = jnp.concatenate([form.to_form(TORQUE_FREE, q1, STATE0.p_hat), q1])
    z2, info = element_map(form, TORQUE_FREE, ref, element, dt, z1)
    h = element.length(dt)
    R2 = lie.exp(z2[3:]) @ ref.at(h)[0]
    return tfb.rotation_error_matrix(R2, h), info.converged


def fitted_order(form, nodes, reference, quadrature="exact"):
    element = Element(nodes, QUADRATURES[quadrature])
    reference = REFERENCES[reference]
    dts = np.array([0.04, 0.02, 0.01]) / (nodes - 1)
    errors = []
    for dt in dts:
        err, converged = one_element(form, element, reference, dt)
        assert converged
        errors.append(float(err))
    return np.polyfit(np.log(dts), np.log(errors), 1)[0]


@pytest.mark.parametrize("nodes", [2, 3, 4])
@pytest.mark.parametrize("name", ["primal", pytest.param("mixed", marks=pytest.mark.slow)])
def test_local_error_order_is_2n_minus_1(name, nodes):
    """End values of an n-node element are superconvergent: global order 2(n - 1), so the error
    of one element is O(h^(2n - 1))."""
    order = fitted_order(FORMS[name](), nodes, "constant")
    assert abs(order - (2 * nodes - 1)) < 0.3, order


# Every form, node count, quadrature and reference; the 2-node mixed forms have a constant trial
# field, for which reduced quadrature is the same as exact, so those cases are not repeated.
EVERY_CASE = [(name, nodes, quadrature, reference) for name in sorted(FORMS) for nodes in (2, 3, 4)
              for quadrature in ("exact", "reduced") for reference in REFERENCES
              if not (quadrature == "reduced" and nodes == 2
                      and name in ("mixed", "mixed_unsymmetric", "three_field"))]


@pytest.mark.slow
@pytest.mark.parametrize("name, nodes, quadrature, reference", EVERY_CASE)
def test_local_error_order_every_form(name, nodes, quadrature, reference):
    order = fitted_order(FORMS[name](), nodes, reference, quadrature)
    assert order > 2 * nodes - 1 - 0.35, order


def free_body_closed_form(t, m, c, J_a, J_t, Omega0, x0, v_cm0, g):
    """O' is c (body frame) from the centre of mass, which falls freely while the body turns
    torque-free about it (eq 8.8)."""
    R = torque_free_motion(J_a, J_t, jnp.eye(3), Omega0, t)[0]
    x_cm0 = x0 + c
    return R, x_cm0 + v_cm0 * t + 0.5 * g * t**2 - R @ c


@pytest.mark.parametrize("name", ["primal", "mixed", pytest.param("three_field", marks=pytest.mark.slow)])
def test_free_body_with_offset_reference_point_matches_closed_form(name):
    """6 dof, S != 0: translation and rotation couple through M6 and S_1 (eqs 3.8, B.8)."""
    m, c, J_a, J_t = 2.0, jnp.array([0.2, -0.1, 0.3]), 0.8, 1.5
    J = jnp.diag(jnp.array([J_t, J_t, J_a])) + m * (c @ c * jnp.eye(3) - jnp.outer(c, c))
    g = jnp.array([0.0, 0.0, -9.81])
    body = Body(m, J, com=c, gravity=g)
    Omega0, x0, v_cm0 = jnp.array([1.0, 0.5, 4.0]), jnp.array([0.0, 0.0, 1.0]), jnp.array([1.0, 0.0, 3.0])
    v0 = v_cm0 - jnp.cross(Omega0, c)              # velocity of O' (R0 = I)
    sol = solve_tfe(body, initial_state(body, jnp.eye(3), Omega0, x0, v0), dt=0.02,
                    n_elements=14, form=FORMS[name](), element=Element(4))
    assert sol.messages() == ["success"]
    R, x = jax.vmap(partial(free_body_closed_form, m=m, c=c, J_a=J_a, J_t=J_t, Omega0=Omega0,
                            x0=x0, v_cm0=v_cm0, g=g))(sol.ts)
    rot_err = jax.vmap(lambda A, B: jnp.linalg.norm(lie.log(A @ B.T)))(sol.R, R)
    assert float(rot_err.max()) < 1e-8          # order 6 at 0.06 s elements
    assert float(jnp.abs(sol.x - x).max()) < 1e-8
    # invariants: linear momentum l = l0 + m g t, angular momentum about the centre of mass
    np.testing.assert_allclose(sol.p_hat[:, 3:], sol.p_hat[0, 3:] + m * g * sol.ts[:, None], atol=1e-9)


def test_newton_converges_quadratically():
    """Residual norms before each iteration: r_{k+1} <= C r_k^2 once in the basin."""
    form, element = FORMS["mixed"](), Element(4)
    ref, _ = ConstantReference().start(TORQUE_FREE, 0.0, STATE0.R, STATE0.x, STATE0.p_hat)
    z1 = jnp.concatenate([STATE0.p_hat, jnp.zeros(3)])
    _, info = jax.jit(lambda z: element_map(form, TORQUE_FREE, ref, element, 0.05, z, tol=0.0,
                                            max_iter=6))(z1)
    r = np.asarray(info.history)
    r = r[np.isfinite(r) & (r > 1e-13)]
    assert len(r) >= 4
    assert not bool(info.converged)            # tol = 0 cannot be met: reported, not hidden
    np.testing.assert_array_less(r[1:], 10.0 * r[:-1] ** 2)
    assert np.log(r[3]) / np.log(r[2]) > 1.7    # the number of correct digits doubles


def test_status_reports_newton_failure_and_blow_up():
    sol = solve_tfe(TORQUE_FREE, STATE0, dt=0.05, n_elements=3, form=FORMS["primal"](),
                    element=Element(2), max_iter=1)
    # the first element's Newton stopped short: the words say when
    assert sol.messages() == ["not converged (first at t = 0.05 s)"] and not bool(sol.ok)
    bad = State(STATE0.R, STATE0.x, STATE0.p_hat.at[0].set(jnp.nan))
    sol = solve_tfe(TORQUE_FREE, bad, dt=0.05, n_elements=3, form=FORMS["primal"](),
                    element=Element(2), max_iter=1)
    assert int(sol.status) & int(Status.NONFINITE)


# two 3-node primal elements 0.05 s between nodes from STATE0, by the strings "constant" with
# "exact" quadrature and "constant_velocity" with "reduced" before they were replaced: the final
# rotation, momentum and Newton iterations per element
OLD_MARCHES = {
    (ConstantReference(), ExactQuadrature()): (
        [[-0.28755143586941606, -0.3395579894461636, 0.8955526469910723],
         [-0.7645307379277806, -0.4818306175869679, -0.4281728701346739],
         [0.5768942038996755, -0.8077992496648161, -0.1210514343075688]],
        [18.749999999999993, 1.824874153436944e-15, 15.0], [6, 6]),
    (ConstantVelocityReference(), ReducedQuadrature()): (
        [[-0.2844365498176817, -0.33840746686198825, 0.8969817364360695],
         [-0.7603594867731386, -0.49022813022558176, -0.4260631774861795],
         [0.5839086401158174, -0.8032165129699359, -0.11787252983844172]],
        [18.750000000000004, 9.2519996387361e-16, 14.999999999999991], [4, 4]),
}


@pytest.mark.parametrize("reference, quadrature", list(OLD_MARCHES), ids=["constant-exact",
                                                                           "velocity-reduced"])
def test_reference_and_quadrature_strategies_march_as_the_strings_did(reference, quadrature):
    R, p_hat, iterations = OLD_MARCHES[reference, quadrature]
    sol = solve_tfe(TORQUE_FREE, STATE0, dt=0.05, n_elements=2, form=FORMS["primal"](),
                    element=Element(3, quadrature), reference=reference)
    np.testing.assert_allclose(sol.R[-1], R, rtol=0, atol=1e-12)
    np.testing.assert_allclose(sol.p_hat[-1], p_hat, rtol=0, atol=1e-12)
    assert np.asarray(sol.iterations).tolist() == iterations


def test_a_prescribed_reference_starts_as_the_one_built_from_the_state():
    """`Reference.start` shifts the motion and carries the increments over; from the state it was
    built from, they are zero and it is `ConstantVelocityReference().start`'s."""
    built, q1 = ConstantVelocityReference().start(TORQUE_FREE, 0.0, STATE0.R, STATE0.x, STATE0.p_hat)
    assert isinstance(built, Reference) and not np.any(q1)
    ref, q = built.start(TORQUE_FREE, 0.0, STATE0.R, STATE0.x, STATE0.p_hat)
    np.testing.assert_allclose(ref.R1, built.R1, atol=1e-15)
    np.testing.assert_allclose(q, 0.0, atol=1e-15)
    later, q = built.start(TORQUE_FREE, 0.1, STATE0.R, STATE0.x, STATE0.p_hat)
    np.testing.assert_allclose(later.R1, built.at(0.1)[0], atol=1e-15)
    # STATE0 is 0.1 s behind the reference there: its increment is the turn back, -0.1 omega
    np.testing.assert_allclose(q, -0.1 * built.omega, atol=1e-12)


def test_bad_arguments_get_clear_errors():
    for old in ("constant", "constant_velocity", "spline"):
        with pytest.raises(TypeError, match=r"reference must be a reference strategy, "
                                            r"ConstantReference\(\), ConstantVelocityReference\(\)"):
            solve_tfe(TORQUE_FREE, STATE0, dt=0.1, n_elements=2, reference=old)
    with pytest.raises(TypeError, match=r"an instance: ConstantReference\(\)"):
        solve_tfe(TORQUE_FREE, STATE0, dt=0.1, n_elements=2, reference=ConstantReference)
    with pytest.raises(ValueError, match="n_elements"):
        solve_tfe(TORQUE_FREE, STATE0, dt=0.1, n_elements=0)
    with pytest.raises(TypeError, match="tfe.Element"):
        solve_tfe(TORQUE_FREE, STATE0, dt=0.1, n_elements=2, element=3)
    with pytest.raises(ValueError, match="mass must be positive"):
        Body(-1.0, jnp.eye(3))
    with pytest.raises(ValueError, match="com must be a finite 3-vector"):
        Body(1.0, jnp.eye(3), com=(0.0, 1.0))
    with pytest.raises(ValueError, match="positive-definite"):
        Body(1.0, -jnp.eye(3))


def _final(form, Omega0, J_t):
    """Final rotation and kinetic energy after 4 solved 2-node elements of a body spinning about
    a fixed point, as a function of the initial spin and the transverse inertia."""
    body = Body(1.0, jnp.diag(jnp.stack([J_t, J_t, jnp.ones_like(J_t)])), gravity=(0.0, 0.0, 0.0),
                fixed_point=True)
    sol = solve_tfe(body, initial_state(body, jnp.eye(3), Omega0), dt=0.05, n_elements=4,
                    form=form, element=Element(2))
    return jnp.concatenate([sol.R[-1].ravel(), sol.energy(body)[-1:]])


@functools.cache
def ift_functions(name):
    """(final, its forward-mode and its reverse-mode Jacobian), each jitted once per module and
    shared by the two tests below."""
    final = partial(_final, FORMS[name]())
    return (jax.jit(final), jax.jit(jax.jacfwd(final, argnums=(0, 1))),
            jax.jit(jax.jacrev(final, argnums=(0, 1))))


@pytest.mark.parametrize("name", ["primal", pytest.param("mixed", marks=pytest.mark.slow)])
def test_gradients_through_the_implicit_function_theorem_match_finite_differences(name):
    """d(final kinetic energy and rotation)/d(initial spin and inertia) through 4 solved elements,
    forward and reverse mode, against central differences."""
    final, jacfwd, jacrev = ift_functions(name)
    Omega0, J_t = jnp.array([1.0, 0.3, 1.5]), jnp.array(1.875)
    jac_fwd = jacfwd(Omega0, J_t)
    jac_rev = jacrev(Omega0, J_t)
    eps = 1e-6
    fd_Omega = jnp.stack([(final(Omega0 + eps * e, J_t) - final(Omega0 - eps * e, J_t)) / (2 * eps)
                          for e in jnp.eye(3)], axis=1)
    fd_J = (final(Omega0, J_t + eps) - final(Omega0, J_t - eps)) / (2 * eps)
    for jac in (jac_fwd, jac_rev):
        np.testing.assert_allclose(jac[0], fd_Omega, atol=1e-7)
        np.testing.assert_allclose(jac[1], fd_J, atol=1e-7)


def test_zero_rotation_gradient_is_finite():
    """A body at rest: every increment is exactly zero, where Gamma's series branches take over.
    Reverse mode through the same solve as the test above (its compilation is reused): every
    entry finite, and the energy's gradient (J Omega0) exactly zero."""
    _, _, jacrev = ift_functions("primal")
    jac_Omega, jac_J = jacrev(jnp.zeros(3), jnp.array(1.875))
    assert bool(jnp.all(jnp.isfinite(jac_Omega)) & jnp.all(jnp.isfinite(jac_J)))
    np.testing.assert_allclose(jac_Omega[-1], 0.0, atol=1e-14)
