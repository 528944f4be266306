"""A status says what tripped it (issue 43): the joint whose limit, the time, the copy; and bad
rotations and mismatched data are refused where they enter."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from mbjax import Status, simulate
from mbjax.flex import Beam, beam_body, craig_bampton
from mbjax.integrate import RK4
from mbjax.model import chain
from mbjax.rigid import TreeSystem
from mbjax.trajopt import ILQR, Problem, solve
from tests.conftest import example_robots

LIMIT = 0.5


def test_a_limit_is_named_by_its_joint_and_the_time_it_was_first_exceeded():
    """The middle joint of a hanging chain, started at 0.3 rad and 3 rad/s with limits of
    +-0.5 rad, passes its upper limit first: the words name it and the first saved state
    beyond it, found here from the saved states themselves."""
    model = eqx.tree_at(lambda m: (m.lower, m.upper), chain(3),
                        (jnp.full(3, -LIMIT), jnp.full(3, LIMIT)))
    sol = simulate(TreeSystem(model), RK4(), jnp.array([0.0, 0.3, 0.0]),
                   jnp.array([0.0, 3.0, 0.0]), dt=0.01, t1=1.0)
    beyond = np.abs(np.asarray(sol.qs)) > LIMIT
    step, joint = np.argwhere(beyond)[0]
    assert Status(int(sol.status)) == Status.LIMIT_EXCEEDED and bool(sol.ok)
    assert sol.messages() == [f"limit exceeded (joint '{model.joint_names[joint]}' position out of range; "
                              f"first at t = {float(sol.ts[step]):.4g} s)"]


def test_a_quaternion_start_that_is_not_a_unit_quaternion_is_refused():
    system = TreeSystem(chain(2, joint_types="spherical"))
    q0 = jnp.array([1.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0])     # the second of norm 2
    with pytest.raises(ValueError, match=r"q0\[4:8\] \(the quaternion of joint 'joint1'\) must be a "
                                         r"unit quaternion .* got norm 2"):
        simulate(system, RK4(), q0, jnp.zeros(6), dt=0.01, t1=0.1)
    sol = simulate(system, RK4(), q0.at[4].set(1.0), jnp.zeros(6), dt=0.01, t1=0.1)
    assert sol.messages() == ["success"]
    with pytest.raises(ValueError, match=r"q0\[4:8\] \(the quaternion of joint 'joint1'\)"):
        Problem(system, q0, jnp.zeros(6), dt=0.01, horizon=3,
                running=lambda q, v, u: jnp.sum(u**2), terminal=lambda q, v: jnp.sum(v**2))


def test_a_basis_built_for_another_beam_is_refused():
    beam = Beam(1.0, 7e10, 2.6e10, 2700.0, 1e-4, 1e-9, 1e-9, 2e-9, n_elements=4)
    other = Beam(1.0, 7e10, 2.6e10, 2700.0, 1e-4, 1e-9, 1e-9, 2e-9, n_elements=6)
    basis = craig_bampton(other, n_modes=2)
    with pytest.raises(ValueError, match="basis has shapes for 7 nodes .* but beam has 5"):
        beam_body(beam, basis)
    with pytest.raises(ValueError, match=r"damping must be the modal damping matrix of shape "
                                         r"\(2, 2\)"):
        beam_body(beam, craig_bampton(beam, n_modes=2), damping=jnp.ones(2))


def test_a_solution_prints_its_status_in_words():
    """`print(sol)` shows the words and the cause, one line; a batch counts its runs."""
    model = eqx.tree_at(lambda m: (m.lower, m.upper), chain(3),
                        (jnp.full(3, -LIMIT), jnp.full(3, LIMIT)))
    starts = jnp.array([[0.0, 0.3, 0.0], [0.0, 0.0, 0.0]])
    sols = jax.vmap(lambda q: simulate(TreeSystem(model), RK4(), q, jnp.array([0.0, 3.0, 0.0]),
                                       dt=0.01, t1=1.0))(starts)
    first = jax.tree.map(lambda x: x[0], sols)
    assert str(first) == "Solution: " + first.messages()[0]
    assert str(first).startswith("Solution: limit exceeded (joint 'joint1' position out of range")
    assert str(sols).startswith("Solution, 2 runs: ")
    assert sum(int(part.split()[0]) for part in str(sols)[len("Solution, 2 runs: "):].split("; ")
               if part[0].isdigit()) == 2


def test_a_status_prints_its_flags_in_words_and_computes_as_an_integer_array():
    """`sol.status` printed 32; now its words, as diffrax's RESULTS, while it still computes as
    the integer array it is, eagerly, under jit and under vmap."""
    model = eqx.tree_at(lambda m: (m.lower, m.upper), chain(3),
                        (jnp.full(3, -LIMIT), jnp.full(3, LIMIT)))

    def run(q0):
        return simulate(TreeSystem(model), RK4(), q0, jnp.array([0.0, 3.0, 0.0]), dt=0.01, t1=1.0)

    sol = run(jnp.array([0.0, 0.3, 0.0]))
    assert repr(sol.status) == str(sol.status) == "Flags<limit exceeded>"
    assert int(sol.status) == Status.LIMIT_EXCEEDED and bool(sol.status == Status.LIMIT_EXCEEDED)
    assert int(sol.status & Status.LIMIT_EXCEEDED) and not int(sol.status & Status.NONFINITE)
    assert np.asarray(sol.status).dtype.kind == "i" and jnp.asarray(sol.status).shape == ()
    marked = sol.status | Status.INACCURATE
    assert str(marked) == "Flags<limit exceeded, inaccurate>" and int(marked) == 96
    jitted = jax.jit(run)(jnp.array([0.0, 0.3, 0.0]))
    assert str(jitted.status) == "Flags<limit exceeded>"
    assert int(jax.jit(lambda status: jnp.where(status == 0, 1, status))(sol.status)) == 32
    batch = jax.vmap(run)(jnp.array([[0.0, 0.3, 0.0], [0.0, 0.0, 0.0]]))
    assert batch.status.shape == (2,) and str(batch.status).startswith(
        "Flags<shape (2,): limit exceeded; ")
    assert str(batch.status[0]) == "Flags<limit exceeded>"
    assert np.asarray(batch.status).tolist() == [int(s) for s in batch.status]
    # the results whose drivers add flags after the run (trajopt's and the time elements' checks)
    problem = Problem(TreeSystem(model), jnp.zeros(3), jnp.zeros(3), dt=0.05, horizon=4,
                      running=lambda q, v, u: jnp.sum(u**2),
                      terminal=lambda q, v: jnp.sum(q**2))
    assert str(solve(problem, ILQR(iterations=1)).status).startswith("Flags<")


def test_home_lies_inside_every_limit_of_every_example_robot():
    """`Model.home()` is inside [lower, upper] on every URDF of example-robot-data (the Panda's
    elbow, whose range excludes zero, among those it moves), and equals `neutral()` where zero
    is inside."""
    import warnings

    from mbjax.model import load_urdf
    from mbjax_harness.reproduce import urdf_corpus
    paths = example_robots()
    moved = []
    for path in paths:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                model = load_urdf(path)
            except ValueError:        # no movable joint: nothing to place
                continue
        home, neutral = np.asarray(model.home()), np.asarray(model.neutral())
        lower, upper = np.asarray(model.lower), np.asarray(model.upper)
        assert np.all((home >= lower) & (home <= upper)), urdf_corpus.name(path)
        outside = (neutral < lower) | (neutral > upper)
        np.testing.assert_array_equal(home[~outside], neutral[~outside])
        if outside.any():
            moved.append(urdf_corpus.name(path))
    assert any("panda" in name for name in moved), moved
