"""Derivatives of `log`, `gamma_inv` and the quaternion conversions at exactly 0, pi and 2 pi
(issue 23): finite in forward and reverse mode to second order, and right against closed forms
at the exact half turns (trace -1, quaternion w = 0) where the principal branch is chosen."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax._src import lie

X, Y, Z = np.eye(3)
# exact half turns (entries 0 and +-1), the identity, and exact quaternions
HALF_TURNS = {"x": np.diag([1.0, -1, -1]), "y": np.diag([-1.0, 1, -1]), "z": np.diag([-1.0, -1, 1]),
              "x+y": np.array([[0.0, 1, 0], [1, 0, 0], [0, 0, -1]])}
POINTS = {"log": (lambda R: lie.log(R, check=False),
                  [np.eye(3), *HALF_TURNS.values()]),
          "quat_from_matrix": (lie.quat_from_matrix, [np.eye(3), *HALF_TURNS.values()]),
          "rotvec_from_quat": (lie.rotvec_from_quat,
                               [np.array([1.0, 0, 0, 0]), np.array([-1.0, 0, 0, 0]),
                                np.array([0.0, 1, 0, 0]), np.array([0.0, 0.6, 0.8, 0])]),
          "quat_from_rotvec": (lie.quat_from_rotvec,
                               [np.zeros(3), np.pi * X, 2 * np.pi * Y]),
          "gamma_inv": (lie.gamma_inv, [np.zeros(3), np.pi * X, np.pi * (X + Y) / np.sqrt(2)]),
          "exp": (lie.exp, [np.zeros(3), np.pi * Z, 2 * np.pi * X])}


@pytest.mark.parametrize("name", POINTS)
def test_first_and_second_derivatives_are_finite_in_both_modes(name):
    f, points = POINTS[name]

    def scalar(x):
        return jnp.sum(jnp.sin(jnp.ravel(f(x))) + jnp.ravel(f(x)) ** 2)

    derivatives = jax.jit(lambda x: (jax.jacfwd(lambda x: jnp.ravel(f(x)))(x),
                                     jax.jacrev(lambda x: jnp.ravel(f(x)))(x),
                                     jax.jacfwd(jax.grad(scalar))(x),
                                     jax.jacrev(jax.grad(scalar))(x),
                                     jax.jacfwd(jax.jacfwd(scalar))(x)))
    for x in points:
        fwd, rev, h_fr, h_rr, h_ff = derivatives(jnp.asarray(x))
        for d in (fwd, rev, h_fr, h_rr, h_ff):
            assert np.all(np.isfinite(d)), (name, x)
        np.testing.assert_allclose(fwd, rev, atol=1e-12)       # the two modes agree
        np.testing.assert_allclose(h_fr, h_rr, atol=1e-10)
        np.testing.assert_allclose(h_fr, h_ff, atol=1e-10)


def test_log_at_an_exact_half_turn_has_the_principal_branch_derivatives():
    """At R0 = the half turn about x: turning back about x, exp(-t x) R0 is the turn by pi - t,
    so d log = -x; turning the axis, exp(t y) R0 exp(-t y) is the half turn about exp(t y) x, so
    d log = pi y x x = -pi z. Both modes, against these closed forms."""
    R0 = jnp.asarray(HALF_TURNS["x"])
    log = jax.jit(lambda R: lie.log(R, check=False))
    back = -lie.hat(X) @ R0
    axis_turn = lie.hat(Y) @ R0 - R0 @ lie.hat(Y)
    for dR, expected in ((back, -X), (axis_turn, -np.pi * Z)):
        _, d = jax.jvp(log, (R0,), (dR,))
        np.testing.assert_allclose(d, expected, atol=1e-12)
        # reverse mode: <vjp(c), dR> = <c, jvp(dR)> for every cotangent c
        _, vjp = jax.vjp(log, R0)
        for c in np.eye(3):
            np.testing.assert_allclose(jnp.sum(vjp(jnp.asarray(c))[0] * dR), c @ expected,
                                       atol=1e-12)
    # one-sided differences along the turn back (the principal branch is |r| <= pi)
    h = 1e-7
    np.testing.assert_allclose((log(lie.exp(-h * X) @ R0) - log(R0)) / h, -X, atol=1e-6)


def test_rotvec_of_a_quaternion_with_zero_scalar_part():
    """q = (w, 1, 0, 0) normalized is the turn by 2 atan2(1, w) about x: dr/dw = -2 x at w = 0."""
    q0 = jnp.array([0.0, 1.0, 0.0, 0.0])
    _, d = jax.jvp(lie.rotvec_from_quat, (q0,), (jnp.array([1.0, 0, 0, 0]),))
    np.testing.assert_allclose(d, -2 * X, atol=1e-12)
    g = jax.grad(lambda q: lie.rotvec_from_quat(q)[0])(q0)
    np.testing.assert_allclose(g[0], -2.0, atol=1e-12)


@pytest.mark.parametrize(("function", "argument"), [
    (lie.exp, np.ones(4)), (lie.gamma_inv, np.ones(2)), (lie.hat, np.ones((2, 3))),
    (lie.quat_to_matrix, np.ones(3)), (lie.rotvec_from_quat, np.ones(5)),
    (lie.log, np.eye(4)), (lie.quat_from_matrix, np.ones(9)), (lie.vee, np.ones(3))])
def test_a_wrongly_shaped_argument_is_refused_by_name(function, argument):
    with pytest.raises(ValueError, match=rf"mbjax\.lie\.{function.__name__}: \w+ must be .* "
                                         rf"of shape .*got shape {re_shape(argument)}"):
        function(argument)


def test_complex_values_are_refused_and_integers_promoted():
    with pytest.raises(TypeError, match=r"mbjax\.lie\.exp: r must be real"):
        lie.exp(np.array([0.0, 0.0, 1j]))
    R = lie.exp(np.array([0, 0, 1]))                 # ints: the working float precision
    assert R.dtype == jnp.result_type(float)
    np.testing.assert_allclose(R, lie.exp(np.array([0.0, 0.0, 1.0])), atol=0)


def re_shape(x) -> str:
    return str(np.shape(x)).replace("(", r"\(").replace(")", r"\)")


def test_malformed_arguments_are_refused_by_name_or_answered_exactly():
    """Hypothesis over shapes (scalars to 3-D), dtypes (bool, int, float32, complex) and values
    (NaN and infinities included) for every entry point: a wrongly shaped or complex argument
    is an error naming the function and the shape or dtype; a well-shaped real one gives the
    answer of the same values in float64 (booleans and integers promoted; float32 kept).""" 
    from hypothesis import given, settings
    from hypothesis import strategies as st
    from hypothesis.extra import numpy as hnp

    functions = {"exp": (lie.exp, (3,)), "hat": (lie.hat, (3,)), "gamma": (lie.gamma, (3,)),
                 "gamma_inv": (lie.gamma_inv, (3,)), "quat_from_rotvec": (lie.quat_from_rotvec, (3,)),
                 "quat_to_matrix": (lie.quat_to_matrix, (4,)),
                 "rotvec_from_quat": (lie.rotvec_from_quat, (4,)),
                 "log": (lambda R: lie.log(R, check=False), (3, 3))}
    dtypes = st.sampled_from([np.bool_, np.int32, np.float32, np.float64, np.complex128])

    @settings(max_examples=120, deadline=None)
    @given(st.sampled_from(sorted(functions)), dtypes,
           hnp.array_shapes(min_dims=0, max_dims=3, min_side=1, max_side=4), st.data())
    def check(name, dtype, shape, data):
        function, wanted = functions[name]
        if data.draw(st.booleans()):
            shape = wanted
        x = data.draw(hnp.arrays(dtype, shape, elements=hnp.from_dtype(
            np.dtype(dtype), allow_nan=True, allow_infinity=True)
            if np.dtype(dtype).kind in "fc" else None))
        if np.iscomplexobj(x):
            with pytest.raises(TypeError, match=f"mbjax.lie.{name}: .* must be real"):
                function(x)
        elif x.shape != wanted:
            pattern = str(wanted).replace("(", r"\(").replace(")", r"\)")
            with pytest.raises(ValueError, match=rf"mbjax.lie.{name}: .* of shape {pattern}"):
                function(x)
        elif x.dtype == np.float32:                 # the caller's precision is kept
            assert function(x).dtype == jnp.float32
        else:
            out = function(x)
            assert out.dtype == jnp.float64
            expected = function(jnp.asarray(np.asarray(x, np.float64)))
            np.testing.assert_array_equal(out, expected)

    check()
