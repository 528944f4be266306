"""Adaptive, error-controlled reference solutions through diffrax."""

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
from jax import Array

from mbjax.integrate.solution import Solution, Status
from mbjax.integrate.system import AbstractSystem


@eqx.filter_jit
def solve_reference(system: AbstractSystem, q0: Array, u0: Array, ts, *, rtol: float = 1e-11,
                    atol: float = 1e-11, solver=None, max_steps: int = 1_000_000) -> Solution:
    """Integrate q_dot = kinematics(q, u), u_dot = acceleration(t, q, u) with an adaptive
    embedded Runge-Kutta method (default diffrax.Dopri8) and a PID step-size controller,
    saving at `ts` (ts[0] is the initial time). Coordinates are projected (e.g. quaternions
    normalized) at the save times only, so the solver sees a smooth vector field.

    Use it for references, not for rotation vectors through |r| = 2 pi: there the coordinate
    rate Gamma^-1 is singular and only fixed-step drivers, which rescale after each step, pass.
    """
    ts = jnp.asarray(ts)
    term = diffrax.ODETerm(
        lambda t, y, args: (system.kinematics(y[0], y[1]), system.acceleration(t, y[0], y[1])))
    sol = diffrax.diffeqsolve(
        term, diffrax.Dopri8() if solver is None else solver, t0=ts[0], t1=ts[-1], dt0=None,
        y0=(jnp.asarray(q0), jnp.asarray(u0)), saveat=diffrax.SaveAt(ts=ts),
        stepsize_controller=diffrax.PIDController(rtol=rtol, atol=atol),
        max_steps=max_steps, throw=False)
    qs = jax.vmap(system.project)(sol.ys[0])
    failed = sol.result != diffrax.RESULTS.successful
    status = jnp.where(failed, int(Status.SOLVER_FAILED), 0).astype(jnp.int32)
    return Solution(ts=ts, qs=qs, us=sol.ys[1], status=status)

