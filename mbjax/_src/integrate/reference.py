"""Adaptive, error-controlled reference solutions through diffrax (an optional dependency:
`pip install "mbjax[reference]"`)."""

import importlib

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.integrate.solution import Solution

from mbjax._src.system.status import Status, raise_on_failure
from mbjax._src.system.system import AbstractSystem


def solve_reference(system: AbstractSystem, q0: Array, v0: Array, ts, *, rtol: float = 1e-11,
                    atol: float = 1e-11, solver=None, max_steps: int = 1_000_000,
                    throw: bool = False) -> Solution:
    """An adaptive, error-controlled reference solution through diffrax.

    Integrates q_dot = kinematics(q, u), u_dot = acceleration(t, q, u) with an adaptive
    embedded Runge-Kutta method and a PID step-size controller, saving at `ts`. Coordinates are
    projected (e.g. quaternions normalized) at the save times only, so the solver sees a
    smooth vector field.

    Args:
        system: the system to integrate, an `AbstractSystem`.
        q0: initial configuration, shape (nq,).
        v0: initial velocity coordinates, shape (nv,).
        ts (Array): save times [s], shape (T,), T >= 2, increasing; ts[0] is the initial time.
        rtol: the step-size controller's relative tolerance.
        atol: its absolute tolerance, in the state's units.
        solver (diffrax.AbstractSolver | None): a diffrax solver; None for `diffrax.Dopri8()`.
        max_steps: the most steps of each interval between save times.
        throw: raise an error naming the failure instead of returning its status (as
            `simulate`).

    Returns:
        A `Solution` with ts, qs (T, nq), us (T, nv) and the status SOLVER_FAILED where an
            interval's solve failed (too many steps, say).

    Raises:
        ImportError: diffrax is not installed (`pip install "mbjax[reference]"`).
        ValueError: ts (when concrete) is not at least two increasing times.
        equinox.EquinoxRuntimeError: with throw=True, the solve failed.

    Intervals:
        Each interval between save times is one `diffeqsolve` (in a `lax.scan`), from the state
        the previous one reached: saving at given times inside one solve holds run-time checks of
        those times (host callbacks), which keep the compiled program out of the persistent
        compilation cache; here `ts` is checked once, in NumPy.

    Warning:
        Use it for references, not for rotation vectors through |r| = 2 pi: there the coordinate
        rate Gamma^-1 is singular and only fixed-step drivers, which rescale after each step,
        pass.
    """
    _diffrax()
    if not isinstance(ts, jax.core.Tracer):
        times = np.asarray(ts, dtype=float)
        if times.ndim != 1 or times.size < 2 or not np.all(np.diff(times) > 0):
            raise ValueError(f"ts must be at least two increasing times, got {ts!r}")
    return raise_on_failure(_solve(system, q0, v0, ts, rtol, atol, solver, max_steps), throw,
                            "mbjax.integrate.solve_reference")


def _diffrax():
    """diffrax, imported where a reference is asked for, or an ImportError saying how to get it."""
    try:
        return importlib.import_module("diffrax")
    except ImportError as error:
        raise ImportError("mbjax.integrate.solve_reference runs diffrax's adaptive solvers: "
                          'pip install "mbjax[reference]" (or pip install diffrax)') from error


@eqx.filter_jit
def _solve(system, q0, v0, ts, rtol, atol, solver, max_steps):
    diffrax = _diffrax()
    ts = jnp.asarray(ts)
    term = diffrax.ODETerm(
        lambda t, y, args: (system.kinematics(y[0], y[1]), system.acceleration(t, y[0], y[1])))

    def interval(y, t01):
        sol = diffrax.diffeqsolve(
            term, diffrax.Dopri8() if solver is None else solver, t0=t01[0], t1=t01[1],
            dt0=None, y0=y, saveat=diffrax.SaveAt(t1=True),
            stepsize_controller=diffrax.PIDController(rtol=rtol, atol=atol),
            max_steps=max_steps, throw=False)
        y1 = jax.tree.map(lambda a: a[-1], sol.ys)
        return y1, (y1, sol.result != diffrax.RESULTS.successful)

    y0 = (jnp.asarray(q0), jnp.asarray(v0))
    _, ((q, u), failed) = jax.lax.scan(interval, y0, jnp.stack([ts[:-1], ts[1:]], 1))
    qs = jax.vmap(system.project)(jnp.concatenate([y0[0][None], q]))
    status = jnp.where(jnp.any(failed), int(Status.SOLVER_FAILED), 0).astype(jnp.int32)
    return Solution(ts=ts, qs=qs, vs=jnp.concatenate([y0[1][None], u]), status=status)
