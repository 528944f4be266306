"""Bad input to `simulate` (issue 23): a clear error naming the argument, never a crash deep in
JAX or a silent wrong answer; integer and float32 states promoted to the working precision."""

import jax.numpy as jnp
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mbjax import simulate
from mbjax.integrate import RK4
from mbjax.model import random_tree
from mbjax.rigid import TreeSystem

MODEL = random_tree(3, seed=0)
SYSTEM = TreeSystem(MODEL)
Q0 = np.array([0.3, -0.2, 0.5])
V0 = np.zeros(MODEL.nv)
STEPS = dict(dt=0.01, t1=0.05)


def _run(system=SYSTEM, integrator=None, q0=Q0, v0=V0, **kw):
    return simulate(system, RK4() if integrator is None else integrator, q0, v0,
                    **{**STEPS, **kw})


def test_integer_float32_and_list_states_give_the_float64_answer():
    reference = _run()
    for q0 in (np.array([0, 0, 1]), Q0.astype(np.float32), list(Q0)):
        expected = _run(q0=np.asarray(q0, dtype=np.float64))
        sol = _run(q0=q0, v0=[0, 0, 0])
        assert sol.qs.dtype == jnp.float64 and sol.status == 0
        np.testing.assert_array_equal(sol.qs, expected.qs)
    assert reference.status == 0


def test_velocities_are_vs_and_us_is_a_deprecated_alias():
    """A `Solution`'s velocities are `vs`, named as `simulate`'s v0 (u names controls, as in
    mbjax.trajopt); the old name still reads them, with a DeprecationWarning that says so."""
    sol = simulate(SYSTEM, RK4(), q0=Q0, v0=V0 + 0.1, **STEPS)
    np.testing.assert_array_equal(sol.vs[0], V0 + 0.1)
    with pytest.warns(DeprecationWarning, match="Solution.us is renamed Solution.vs"):
        np.testing.assert_array_equal(sol.us, sol.vs)


@pytest.mark.parametrize(("kwargs", "error", "names"), [
    (dict(system=MODEL), TypeError, "system .*wrap a Model in TreeSystem"),
    (dict(system=TreeSystem), TypeError, "system .*not the class"),
    (dict(integrator=RK4), TypeError, r"integrator .*RK4\(\), not RK4"),
    (dict(dt="0.01"), TypeError, "dt must be a real number"),
    (dict(t1=np.nan), ValueError, "t1 must be finite"),
    (dict(t1=np.inf), ValueError, "t1 must be finite"),
    (dict(t0=None), TypeError, "t0 must be a real number"),
    (dict(saveat=[]), ValueError, "saveat must be None or a non-empty"),
    (dict(saveat=[0.0, np.nan]), ValueError, "saveat times must be finite"),
    (dict(q0=Q0 + 0j), TypeError, "q0 must be real"),
    (dict(v0="abc"), TypeError, "v0 must be"),
    (dict(q0=np.zeros(4)), ValueError, r"q0 must have shape \(3,\)"),
])
def test_bad_arguments_are_named(kwargs, error, names):
    with pytest.raises(error, match=names):
        _run(**kwargs)


@settings(max_examples=60, deadline=None)
@given(length=st.integers(0, 6).filter(lambda n: n != 3),
       which=st.sampled_from(["q0", "v0"]),
       kind=st.sampled_from(["float", "int", "complex"]))
def test_malformed_states_raise_a_clear_error(length, which, kind):
    value = np.ones(length, dtype={"float": float, "int": int, "complex": complex}[kind])
    name = which
    expected = "must be real" if kind == "complex" else r"must have shape \(3,\)"
    with pytest.raises((TypeError, ValueError), match=rf"{name} {expected}"):
        _run(**{which: value})


@settings(max_examples=40, deadline=None)
@given(st.one_of(st.just(0.0), st.floats(max_value=0.0, allow_nan=False),
                 st.sampled_from([np.nan, np.inf, -np.inf, "x", None, [0.1]])))
def test_malformed_steps_raise_a_clear_error(dt):
    with pytest.raises((TypeError, ValueError), match="dt"):
        _run(dt=dt)
