"""Solves that say what to change, and problem data that does not recompile (issue 61).

A result that did not converge names the likely remedy in `messages()`, with the public
arguments that apply it; a problem whose target is array data (`eqx.Partial` of a module-level
cost, as the README writes it) reuses the compiled solve for a new target. Compilation is
counted by JAX's own monitoring events: a trace (`jaxpr_trace_duration`) is a program missing
from the in-memory cache, whether or not XLA then finds it in the persistent cache, and a
backend compile (`backend_compile_duration`) is one XLA builds."""

import inspect
import re

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from jax import monitoring

import mbjax
from mbjax import Status
from mbjax.model import chain
from mbjax.rigid import TreeSystem, frame_pose
from mbjax.trajopt import (CROCODDYL_SCHEDULE, ILQR, MultipleShooting, Problem, Result,
                           Shooting, solve)

jax.config.update("jax_enable_x64", True)

EVENTS = ("/jax/core/compile/jaxpr_trace_duration", "/jax/core/compile/backend_compile_duration")
_events = []


def _listen(event, duration, **kwargs):
    if event in EVENTS:
        _events.append(event)


@pytest.fixture(scope="module", autouse=True)
def _counting():
    """JAX's compile events, recorded while this module runs."""
    monitoring.register_event_duration_secs_listener(_listen)
    yield
    monitoring.unregister_event_duration_listener(_listen)

MODEL = chain(2)
Q0, V0 = jnp.array([0.3, -0.2]), jnp.zeros(2)
HORIZON = 25


def _target(q0: float) -> jax.Array:
    """Where the first joint's angle q0 puts the second body (a target within reach)."""
    return frame_pose(MODEL, jnp.array([q0, 0.0]), "body1")[1]


def _running(q, v, u):
    return jnp.concatenate([1e-2 * v, 1e-2 * u])


def _terminal(q, v, target):
    return jnp.concatenate([10.0 * (frame_pose(MODEL, q, "body1")[1] - target), v])


def _reach(target) -> Problem:
    """The README's pattern: the target bound as data by `eqx.Partial`, not closed over."""
    return Problem(TreeSystem(MODEL), Q0, V0, dt=0.02, horizon=HORIZON, running=_running,
                   terminal=eqx.Partial(_terminal, target=target))


def _programs(fn):
    """(fn(), the programs traced and compiled while it ran)."""
    start = len(_events)
    out = jax.block_until_ready(fn())
    new = _events[start:]
    return out, {"traced": new.count(EVENTS[0]), "compiled": new.count(EVENTS[1])}


US0 = jnp.zeros((HORIZON, 2))          # one guess for every solve, so the warm start reuses it


@pytest.fixture(scope="module")
def first():
    """The first target's solve, and what it compiled."""
    target = _target(0.9)
    problem = _reach(target)
    result, programs = _programs(lambda: solve(problem, ILQR(), US0))
    return target, result, programs


def _off(result, target) -> float:
    return float(jnp.linalg.norm(frame_pose(MODEL, result.qs[-1], "body1")[1] - target))


def _names_public_arguments(message: str) -> None:
    """Every `Solver(argument=` and `Problem(argument=` a message names is a real argument, and
    so is every bare `argument=` (solve's or Problem's)."""
    owners = {"ILQR": ILQR, "MultipleShooting": MultipleShooting, "Shooting": Shooting,
              "Problem": Problem}
    for owner, argument in re.findall(r"\b(\w+)\((\w+)=", message):
        assert argument in inspect.signature(owners[owner]).parameters, (owner, argument)
    bare = {*inspect.signature(solve).parameters, *inspect.signature(Problem).parameters}
    for argument in re.findall(r"\b(\w+)=(?=[,) ])", message):
        assert argument in bare, argument
    assert "CROCODDYL_SCHEDULE" not in message or hasattr(mbjax.trajopt, "CROCODDYL_SCHEDULE")


def test_a_new_target_reuses_the_compiled_solve(first):
    """The second target's problem (built first: `Problem` traces its system's chart) solves
    without tracing or compiling a program, and reaches its own target."""
    target, result, programs = first
    assert programs["traced"] >= 1          # the counter counts (compiled may be 0: XLA may
                                            # find the program in the persistent cache)
    assert result.messages() == ["success"] and _off(result, target) < 1e-2
    second = _target(-0.4)
    problem = _reach(second)
    again, programs = _programs(lambda: solve(problem, ILQR(), US0))
    assert programs == {"traced": 0, "compiled": 0}
    assert again.messages() == ["success"] and _off(again, second) < 1e-2
    assert _off(again, target) > 0.1


def test_an_unconverged_solve_names_the_iterations_and_the_warm_start(first):
    """ILQR(iterations=2) runs out: the message names ILQR(iterations=...) and the warm start,
    and the warm start, solve(problem, solver, result.us), converges without a compile."""
    target, _, _ = first
    problem = _reach(target)
    short = solve(problem, ILQR(iterations=2), US0)
    [message] = short.messages()
    assert message.startswith("not converged (iterations=2 ran out, the cost fell ")
    assert "ILQR(iterations=...)" in message and "solve(problem, solver, result.us)" in message
    _names_public_arguments(message)
    assert str(short) == f"Result: {message}"
    warm, programs = _programs(lambda: solve(problem, ILQR(), short.us))
    assert programs == {"traced": 0, "compiled": 0} and warm.messages() == ["success"]


def _result(status, iterations=10, limit=10, regularization=1e-9, step_lengths=None,
            solver="ILQR", hint=None, inaccurate_by=0, resolution=float("nan")) -> Result:
    """A result as a solver would return it, with a cost history falling by 1% an iteration
    (inaccurate_by=1: the steps do not resolve the motion)."""
    costs = np.full(limit + 1, np.nan)
    costs[:iterations + 1] = 0.99 ** np.arange(iterations + 1)
    steps = np.full(limit, np.nan)
    steps[:iterations] = 1.0 if step_lengths is None else step_lengths
    if hint is None:
        hint = ILQR()._hint() if solver == "ILQR" else ""
    return Result(qs=np.zeros((3, 1)), vs=np.zeros((3, 1)), us=np.zeros((2, 1)),
                  cost=costs[iterations], costs=costs, iterations=iterations,
                  feedback=np.zeros((2, 1, 2)), status=int(status),
                  regularization=regularization, step_lengths=steps, solver=solver, hint=hint,
                  inaccurate_by=inaccurate_by, resolution=resolution)


def test_short_steps_name_the_regularization_schedule():
    """Iterations run out on short accepted steps: the default schedule's advice is Crocoddyl's
    (which raises the regularization after short steps) or MultipleShooting; on that schedule
    already, more iterations."""
    [message] = _result(Status.NOT_CONVERGED, step_lengths=0.01).messages()
    assert message == (
        "not converged (iterations=10 ran out on short steps (median step length 0.01 over the "
        "last 2): try ILQR(**mbjax.trajopt.CROCODDYL_SCHEDULE), a regularization schedule that "
        "raises it after short steps, or MultipleShooting() for a long horizon or an unstable "
        "rollout)")
    _names_public_arguments(message)
    scheduled = _result(Status.NOT_CONVERGED, step_lengths=0.01,
                        hint=ILQR(**CROCODDYL_SCHEDULE)._hint()).messages()[0]
    assert "CROCODDYL_SCHEDULE" not in scheduled and "ILQR(iterations=...)" in scheduled
    # full steps: more iterations, as for a solver that records no step lengths
    assert _result(Status.NOT_CONVERGED).messages() == [
        "not converged (iterations=10 ran out, the cost fell 2% over the last 2: raise "
        "ILQR(iterations=...), or go on from this result: solve(problem, solver, result.us))"]
    assert "raise Shooting(iterations=...)" in _result(Status.NOT_CONVERGED,
                                                        solver="Shooting").messages()[0]


def test_a_stalled_solve_names_a_nearer_first_guess_and_multiple_shooting():
    [message] = _result(Status.NOT_CONVERGED, iterations=7, regularization=1e11).messages()
    assert message == (
        "not converged (no step lowered the cost: the regularization reached 1e+11 after 7 "
        "iterations; try a first guess nearer a solution (us0=, states0=), MultipleShooting() "
        "from states, or cost weights of similar scales)")
    _names_public_arguments(message)


def test_nonfinite_and_inaccurate_name_a_finer_step():
    nonfinite = _result(Status.NOT_CONVERGED | Status.NONFINITE, iterations=3,
                        regularization=1e-3).messages()[0]
    assert "nonfinite (the cost or the trajectory became inf or NaN: try a finer " \
           "Problem(dt=...)" in nonfinite
    _names_public_arguments(nonfinite)
    inaccurate = _result(Status.INACCURATE, inaccurate_by=1, resolution=1.7).messages()
    assert inaccurate == ["inaccurate (the steps do not resolve the motion: step x rate reached "
                          "1.7 > 1; try a finer Problem(dt=...), with horizon= raised to keep "
                          "the duration)"]
    _names_public_arguments(inaccurate[0])


def test_a_batch_names_each_members_remedy():
    """Each member of a batched result gets its own advice (`messages()` flattens the batch)."""
    results = jax.tree.map(lambda *x: np.stack(x), _result(0), _result(Status.NOT_CONVERGED))
    words = results.messages()
    assert words[0] == "success" and "raise ILQR(iterations=...)" in words[1]
