"""Model-predictive control: a trajectory optimisation re-solved over a receding horizon at every
control tick from the measured state, warm-started from the previous solution (`MPC`), and the
closed loop of such a controller and a plant, one jitted program (`closed_loop`)."""

from collections.abc import Callable

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.control import Constant
from mbjax._src.integrate import RK4
from mbjax._src.integrate.base import AbstractIntegrator
from mbjax._src.system.status import Flags, flags, Status, WithStatus
from mbjax._src.system.system import AbstractSystem
from mbjax._src.trajopt.ilqr import CROCODDYL_SCHEDULE, ILQR
from mbjax._src.trajopt.knots import AbstractKnot, Knot, Schedule
from mbjax._src.trajopt.problem import Problem
from mbjax._src.trajopt.result import AbstractIterativeSolver


class Plan(eqx.Module):
    """A receding-horizon controller's state: the last solve's trajectory and gains, which the
    next tick shifts to warm-start its solve and which set the control until then.

    Args:
        t: the time of the plan's first knot [s].
        xs: the states x_0 ... x_N, shape (N + 1, nq + nv).
        us: the controls u_0 ... u_{N-1}, shape (N, nu).
        feedback: the gains K_k of u = u_k + K_k difference(x_k, x), shape (N, nu, ndx).
    """

    t: Array
    xs: Array
    us: Array
    feedback: Array


class Tick(eqx.Module):
    """What one tick's solve reports.

    Args:
        iterations: the solver's iterations.
        cost: the horizon's cost after them.
        status: the solve's `Status` flags (NOT_CONVERGED is expected under an iteration cap).
    """

    iterations: Array
    cost: Array
    status: Flags = eqx.field(converter=flags)


class Cycle(eqx.Module):
    """A periodic schedule of knots, a gait's cycle, for a receding horizon: `window(t, n)` is
    the n knots from time t on, the cycle repeated, as `MPC`'s problem(t, q, v) builds its
    horizon. The knots must be alike but for their arrays (a stance's contacts in the air as
    `active=False`, targets, weights), so that every window is one phase and compiles once,
    whatever t is (t may be traced).

    Args:
        knots: one cycle's knots, `Knot`s alike but for their arrays.
        dt: the knots' step [s].

    Raises:
        TypeError: a knot that is not a `Knot`.
        ValueError: no knots, or knots that are not alike (they would make several phases).
    """

    schedule: Schedule
    dt: float = eqx.field(static=True)

    def __init__(self, knots, dt: float):
        knots = list(knots)
        for i, knot in enumerate(knots):
            if not isinstance(knot, AbstractKnot) or knot.jumps():
                raise TypeError(f"knots[{i}] must be a Knot(system, running) (impulses take no "
                                f"time and have no place in a cycle of steps), got "
                                f"{type(knot).__name__}")
        self.schedule = Schedule(knots, dt)
        if len(self.schedule.templates) > 1:
            first = self.schedule.phase.index(1)
            raise ValueError(f"knots must be alike but for their arrays (one phase); knots[0] "
                             f"and knots[{first}] differ in their structure or static data: "
                             f"write every knot over the same contacts and costs, those not "
                             f"in use inactive or weighted 0")
        self.dt = float(dt)

    @property
    def period(self) -> int:
        """The number of knots in the cycle."""
        return len(self.schedule.phase)

    def window(self, t, n: int) -> list:
        """The n knots from time t on (the knot of t, rounded to the step, first).

        Args:
            t: the time [s], may be traced.
            n: the number of knots (static).

        Returns:
            The knots, a list for `Problem`.
        """
        offset = jnp.round(jnp.asarray(t) / self.dt).astype(int)
        return [self.schedule.knot(0, (offset + k) % self.period) for k in range(n)]


def _zero(q, v, u):
    return jnp.zeros((), q.dtype)


class MPC(eqx.Module):
    """A receding-horizon (model-predictive) controller.

    At each tick it builds the horizon's problem from the measured state, warm-starts the
    solver from the previous plan shifted by the knots the horizon moved since (its states and
    controls, the last repeated: Crocoddyl's infeasible start, FDDP), runs at most the solver's
    `iterations`, and keeps the new plan. Until the next tick the control is the plan's, with its
    feedback gains: u = clip(u_k + K_k difference(x_k, x)) at the plan's knot k of the current
    time. The plan is carried explicitly (`init`, `tick`, `control` are pure functions of it),
    so a closed loop is one jitted, vmappable program (`closed_loop`), differentiable in forward
    mode (`jax.jvp`, `jax.jacfwd`: the solver's iterations are a `lax.while_loop`).

    Args:
        problem: problem(t, q, v) -> the `Problem` over the horizon from the state (q, v) at
            time t: its targets, contact schedule and references at the knots t + k dt. Its
            structure (horizon, dt, shapes) must not depend on its arguments; its arrays may.
        solver: the solver of each tick, an `AbstractIterativeSolver` whose `iterations` is the
            cap per tick; by default `ILQR(iterations=1, **CROCODDYL_SCHEDULE)`, one FDDP
            iteration as Crocoddyl's MPC loops run it.
        shift: the knots the horizon moves per tick (static); the control period is shift
            times the problem's dt.

    Raises:
        TypeError: problem is not callable, or solver not an iterative solver instance.
        ValueError: shift is not a positive int.
    """

    problem: Callable
    solver: AbstractIterativeSolver
    shift: int = eqx.field(static=True)

    def __init__(self, problem: Callable, solver: AbstractIterativeSolver | None = None,
                 shift: int = 1):
        if not callable(problem):
            raise TypeError(f"problem must be a function (t, q, v) -> Problem, got {problem!r}")
        solver = ILQR(iterations=1, **CROCODDYL_SCHEDULE) if solver is None else solver
        if not isinstance(solver, AbstractIterativeSolver):
            raise TypeError(f"solver must be an iterative solver instance such as "
                            f"ILQR(iterations=1), got {solver!r}")
        if not (isinstance(shift, int | np.integer) and not isinstance(shift, bool)
                and shift >= 1):
            raise ValueError(f"shift must be a positive int (knots per tick), got {shift!r}")
        self.problem, self.solver, self.shift = problem, solver, int(shift)

    def horizon(self, t, q: Array, v: Array) -> Problem:
        """The horizon's problem from (q, v) at time t, checked to be a `Problem`."""
        problem = self.problem(jnp.asarray(t, dtype=float), q, v)
        if not isinstance(problem, Problem):
            raise TypeError(f"problem(t, q, v) must return a mbjax.trajopt.Problem, got "
                            f"{type(problem).__name__}")
        if problem.horizon <= self.shift:
            raise ValueError(f"the horizon ({problem.horizon} knots) must be longer than shift "
                             f"({self.shift})")
        return problem

    def period(self, t, q: Array, v: Array) -> float:
        """The control period, shift times the problem's dt [s], of the horizon's problem
        from (q, v) at time t."""
        return self.shift * self.horizon(t, jnp.asarray(q, float), jnp.asarray(v, float)).dt

    def init(self, t, q: Array, v: Array, us0: Array | None = None,
             solver: AbstractIterativeSolver | None = None) -> Plan:
        """The first plan: the horizon's problem from (q, v) at time t solved from us0.

        Args:
            t: the time [s].
            q: configuration, shape (nq,).
            v: velocity, shape (nv,).
            us0: the first guess, shape (horizon, nu); None for zeros.
            solver: the first solve's solver, usually one run to convergence (a cold start);
                None for the controller's own.

        Returns:
            The `Plan`.
        """
        q, v = jnp.asarray(q, float), jnp.asarray(v, float)
        problem = self.horizon(t, q, v)
        solver = self.solver if solver is None else solver
        result = solver.solve(problem, problem.initial_controls(us0))
        return Plan(jnp.asarray(t, float), result.xs, result.us, result.feedback)

    def tick(self, plan: Plan, t, q: Array, v: Array) -> tuple[Plan, Tick]:
        """One control tick: the horizon from (q, v) at time t solved warm from `plan` shifted.

        The warm start is the plan moved on by the knots between its time and t (`shift` a
        tick; none on a first tick at the plan's own time), its last knot repeated, its first
        state replaced by the measured one.

        Args:
            plan: the previous tick's plan (or `init`'s).
            t: the time [s].
            q: the measured configuration, shape (nq,).
            v: the measured velocity, shape (nv,).

        Returns:
            (the new plan, the solve's `Tick` report).
        """
        q, v = jnp.asarray(q, float), jnp.asarray(v, float)
        problem = self.horizon(t, q, v)
        moved = jnp.round((t - plan.t) / problem.dt).astype(int)
        xs, us = _shifted(plan.xs, moved), _shifted(plan.us, moved)
        solver = self.solver
        state = jax.lax.while_loop(solver.running, lambda s: solver.step(problem, s),
                                   solver.init(problem, problem.initial_controls(us), xs))
        result = solver.result(problem, state)
        new = Plan(jnp.asarray(t, float), result.xs, result.us, result.feedback)
        return new, Tick(result.iterations, result.cost, result.status)

    def control(self, plan: Plan, t, q: Array, v: Array) -> Array:
        """The control at time t in the state (q, v): the plan's control at its knot k of t
        (the last of the period after the plan's start) with its feedback,
        clip(u_k + K_k difference(x_k, x)) within the problem's bounds.

        Args:
            plan: the current plan.
            t: the time [s].
            q: configuration, shape (nq,).
            v: velocity, shape (nv,).

        Returns:
            The control, shape (nu,).
        """
        q, v = jnp.asarray(q, float), jnp.asarray(v, float)
        problem = self.horizon(plan.t, q, v)     # its dt, bounds and manifold
        k = jnp.clip(jnp.floor((t - plan.t) / problem.dt + 1e-9).astype(int), 0, self.shift - 1)
        x = jnp.concatenate([q, v])
        u = plan.us[k] + plan.feedback[k] @ problem.difference(plan.xs[k], x)
        return jnp.clip(u, problem.lower, problem.upper)


def _shifted(x: Array, shift) -> Array:
    """x moved `shift` entries forward along its first axis (shift may be traced), its last
    entry repeated."""
    n = x.shape[0]
    return x[jnp.clip(jnp.arange(n) + shift, 0, n - 1)]


class ClosedLoop(WithStatus):
    """The run of `closed_loop`: the plant's states at the ticks, the controls and each tick's
    solve.

    Args:
        ts: the ticks' times, shape (ticks + 1,) [s].
        qs: the plant's configurations at the ticks, shape (ticks + 1, nq).
        vs: its velocities, shape (ticks + 1, nv).
        us: the control applied at each tick (the plan's first, with its feedback), shape
            (ticks, nu).
        iterations: each tick's solver iterations, shape (ticks,).
        costs: each tick's horizon cost, shape (ticks,).
        solves: each tick's solve status, shape (ticks,).
        status: the closed loop's `Status`: NONFINITE where the plant's state or a solve blew
            up, and the plant's own flags at the ticks under the control last applied
            (`AbstractSystem.check`: LIMIT_EXCEEDED, a stance's PULLING or SLIPPING, a contact
            system's PENETRATING, ...).
    """

    ts: Array
    qs: Array
    vs: Array
    us: Array
    iterations: Array
    costs: Array
    solves: Array
    status: Flags = eqx.field(converter=flags)


def closed_loop(controller: MPC, plant: AbstractSystem, q0: Array, v0: Array, *, ticks: int,
                dt: float, integrator: AbstractIntegrator = RK4(), plan: Plan | None = None,
                t0: float = 0.0) -> ClosedLoop:
    """Run a controller against a plant: `ticks` control ticks, the plant stepped between them.

    At each tick the controller solves its horizon from the plant's state (`MPC.tick`); then the
    plant steps through the control period with its own integrator and step dt, its control
    replaced by the controller's (`MPC.control`, held over each of the plant's steps, the
    feedback read at each). The plant may differ from the controller's model (a payload, a
    friction coefficient, an external push): it is any mbjax system with a control of the
    problem's size. One program: jit it (it is), vmap it over controllers or plants
    (`equinox.filter_vmap`), differentiate it in forward mode.

    Args:
        controller: the `MPC`.
        plant: the system simulated, its control replaced by the controller's.
        q0: the plant's initial configuration, shape (nq,).
        v0: its initial velocity, shape (nv,).
        ticks: the number of control ticks (static).
        dt: the plant's step [s]; the control period must be a whole number of them (static).
        integrator: the plant's integrator.
        plan: the first plan, from `controller.init` (a solve to convergence, say); None to
            start from `controller.init(t0, q0, v0)` with the controller's own solver.
        t0: the start time [s].

    Returns:
        The `ClosedLoop`.

    Raises:
        TypeError: a controller that is not an `MPC`, or a plant that is not an mbjax system.
        ValueError: ticks not a positive int, dt not positive, or the control period not a
            whole number of plant steps.
    """
    if not isinstance(controller, MPC):
        raise TypeError(f"controller must be a mbjax.trajopt.MPC, got {type(controller).__name__}")
    if not isinstance(plant, AbstractSystem):
        raise TypeError(f"plant must be an mbjax system (TreeSystem, ContactSystem, ...), got "
                        f"{type(plant).__name__}")
    if not isinstance(integrator, AbstractIntegrator):
        raise TypeError(f"integrator must be an instance such as RK4(), got {integrator!r}")
    if not (isinstance(ticks, int | np.integer) and not isinstance(ticks, bool) and ticks >= 1):
        raise ValueError(f"ticks must be a positive int, got {ticks!r}")
    if not (np.ndim(dt) == 0 and float(dt) > 0 and np.isfinite(float(dt))):
        raise ValueError(f"dt must be a positive number (the plant's step), got {dt!r}")
    q0, v0 = jnp.asarray(q0, float), jnp.asarray(v0, float)
    period = controller.period(t0, q0, v0)
    substeps = int(round(period / float(dt)))
    if substeps < 1 or abs(substeps * float(dt) - period) > 1e-9 * period:
        raise ValueError(f"dt ({dt}) must divide the control period ({period} s, shift times the "
                         f"problem's dt) a whole number of times")
    return _closed_loop(controller, plant, q0, v0, plan, integrator, jnp.asarray(t0, float),
                        ticks, float(dt), substeps)


def follow(controller: MPC, plan: Plan, plant: AbstractSystem, t, q: Array, v: Array, *,
           dt: float, steps: int, integrator: AbstractIntegrator = RK4()):
    """The plant driven by a plan through `steps` of its steps from (q, v) at time t: the
    control `controller.control(plan, ...)` read at each step and held over it.

    Args:
        controller: the `MPC` whose control law applies the plan.
        plan: the plan.
        plant: the system simulated, its control replaced by the controller's.
        t: the start [s].
        q: configuration, shape (nq,).
        v: velocity, shape (nv,).
        dt: the plant's step [s].
        steps: the number of steps (static).
        integrator: the plant's integrator.

    Returns:
        (q, v) after the steps and the controls applied, shape (steps, nu).
    """
    step = Knot(plant, _zero)           # the plant's step under a held control

    def substep(carry, j):
        q, v = carry
        s = t + j * dt
        u = controller.control(plan, s, q, v)
        return step.transition(integrator, s, q, v, u, jnp.asarray(dt, q.dtype)), u

    (q, v), us = jax.lax.scan(substep, (jnp.asarray(q, float), jnp.asarray(v, float)),
                              jnp.arange(steps))
    return q, v, us


@eqx.filter_jit
def _closed_loop(controller: MPC, plant: AbstractSystem, q0, v0, plan, integrator, t0,
                 ticks: int, dt: float, substeps: int) -> ClosedLoop:
    plan = controller.init(t0, q0, v0) if plan is None else plan

    def one_tick(carry, i):
        plan, q, v = carry
        t = t0 + i * (substeps * dt)
        plan, report = controller.tick(plan, t, q, v)
        q, v, us = follow(controller, plan, plant, t, q, v, dt=dt, steps=substeps,
                          integrator=integrator)
        # the plant's own flags (limits, contacts) under the control last applied
        flags = plant.with_control(Constant(us[-1])).check(t + substeps * dt, q, v)
        return (plan, q, v), (q, v, us[0], report, flags)

    (_, _, _), (qs, vs, us, reports, flags) = jax.lax.scan(one_tick, (plan, q0, v0),
                                                           jnp.arange(ticks))
    qs, vs = jnp.concatenate([q0[None], qs]), jnp.concatenate([v0[None], vs])
    finite = jnp.all(jnp.isfinite(qs)) & jnp.all(jnp.isfinite(vs))
    blew_up = ~finite | jnp.any(reports.status & int(Status.NONFINITE) != 0)
    status = (jnp.where(blew_up, int(Status.NONFINITE), 0)
              | jax.lax.reduce(flags.astype(jnp.int32), np.int32(0), jax.lax.bitwise_or, (0,)))
    ts = t0 + jnp.arange(ticks + 1) * (substeps * dt)
    return ClosedLoop(ts=ts, qs=qs, vs=vs, us=us, iterations=reports.iterations,
                      costs=reports.cost, solves=reports.status, status=status)
