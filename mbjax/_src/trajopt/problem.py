"""A trajectory-optimisation problem for any system: its dynamics, controls, horizon, costs and
control bounds.

`Problem`'s docstring states the discrete problem, how states on a configuration manifold are
differenced, and the two forms of a cost (a scalar, or residuals for Gauss-Newton).
"""

from collections.abc import Callable

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.integrate import RK4
from mbjax._src.integrate.base import AbstractIntegrator
from mbjax._src.lie.inputs import check_unit_quaternions
from mbjax._src.system.system import AbstractSystem
from mbjax._src.trajopt.costs import _value, as_cost
from mbjax._src.trajopt.knots import Knot, Schedule


class Problem(eqx.Module):
    """A discrete optimal-control problem over a system's controls, to pass to `solve`.

    The unknowns are the controls u_0 ... u_{N-1} on the system's actuated coordinates, one per
    step of length dt, held over the step; the problem minimizes the running costs' sum times dt
    plus the terminal cost, subject to the system's dynamics stepped by `integrator` and the
    bounds on the controls.

    Args:
        system (AbstractSystem | Sequence[Knot | Impulse]): any mbjax system with a control
            (`TreeSystem`, `FlexibleSystem`, `WristSystem`, `RigidBody`, a `ClosedSystem` of a
            tree, ...), whose control is replaced by the unknowns u_k; or one knot per step, a
            multi-phase problem (see Phases in docs/details.md).
        q0 (Array): initial configuration, shape (nq,).
        v0 (Array): initial velocity, shape (nv,).
        dt: the step and control interval, seconds (keyword only).
        horizon: the number of steps N (keyword only); None for the number of knots.
        running: cost rate running(q, v, u), a scalar or a vector of residuals; or a tuple of
            such functions, their sum (keyword only; see Costs in docs/details.md); None with
            knots, which carry their own.
        terminal: final cost terminal(q, v), likewise (keyword only).
        lower (float | Array | None): lower bound on each actuated force, a scalar or shape
            (nu,); None for none.
        upper (float | Array | None): upper bound, likewise.
        integrator: the step's integrator (`RK4()` by default).

    Raises:
        TypeError: naming the malformed argument: a system that is not an mbjax system or has
            no control, a knot that is not a `Knot` or `Impulse`, an integrator that is not an
            instance, costs that are not callables.
        ValueError: naming the malformed argument: a state of the wrong shape, a non-positive
            dt or horizon, a horizon other than the number of knots, a running cost beside
            knots, knots of different numbers of controls, bounds of the wrong shape, lower
            above upper.

    More on formulation, manifolds, phases, costs: the documentation site's Details page
    (docs/details.md).
    """

    system: AbstractSystem
    knots: Schedule
    q0: Array
    v0: Array
    terminal: Callable
    lower: Array
    upper: Array
    integrator: AbstractIntegrator
    dt: float = eqx.field(static=True)
    horizon: int = eqx.field(static=True)
    ndq: int = eqx.field(static=True)   # a configuration deviation's length (nv for a tree)
    bounded: bool = eqx.field(static=True)   # whether lower or upper was given
    controlled: tuple = eqx.field(static=True)   # (phase, index) of the first knot with a control

    def __init__(self, system, q0, v0, *, dt: float, horizon: int | None = None,
                 running: Callable | None = None, terminal: Callable, lower=None, upper=None,
                 integrator: AbstractIntegrator = RK4()):
        knots = None
        if isinstance(system, list | tuple):
            if running is not None:
                raise ValueError("running: each knot of a multi-phase problem carries its own "
                                 "running cost (Knot(system, running)); pass running=None")
            if horizon is not None and horizon != len(system):
                raise ValueError(f"horizon must be the number of knots ({len(system)}) or None, "
                                 f"got {horizon!r}")
            knots = Schedule(system, dt)
            steps = [k for k in system if k.controlled() is not None]
            if not steps:
                raise ValueError("knots must include at least one Knot(system, running): a "
                                 "problem of impulses alone has nothing to control")
            sizes = {k.controlled().n_controls for k in steps}
            if len(sizes) > 1:
                raise ValueError(f"knots: every Knot's system must have the same number of "
                                 f"controls, got {sorted(sizes)}")
            first = next(k for k, knot in enumerate(system) if knot.controlled() is not None)
            system, horizon = system[first].controlled(), len(system)
        if not isinstance(system, AbstractSystem):
            raise TypeError(f"system must be an mbjax system (TreeSystem, ...) or a sequence of "
                            f"knots (Knot, Impulse), got {type(system).__name__}")
        if not isinstance(integrator, AbstractIntegrator):
            raise TypeError(f"integrator must be an instance such as RK4(), got {integrator!r}")
        if not (isinstance(horizon, int | np.integer) and horizon >= 1):
            raise ValueError(f"horizon must be a positive int (the number of steps), got {horizon!r}")
        if not (isinstance(dt, int | float | np.integer | np.floating | np.ndarray | jax.Array)
                and not isinstance(dt, bool) and np.ndim(dt) == 0
                and np.isrealobj(dt) and float(dt) > 0 and np.isfinite(dt)):
            raise ValueError(f"dt must be a positive number, finite, got {dt!r}")
        terminal = as_cost(terminal, "terminal(q, v)")
        self.q0, self.v0 = jnp.asarray(q0, dtype=float), jnp.asarray(v0, dtype=float)
        if self.q0.ndim != 1 or self.v0.ndim != 1:
            raise ValueError(f"q0 and v0 must be vectors, got shapes {self.q0.shape} and "
                             f"{self.v0.shape}")
        system.with_control(None)                   # raises for a system without a control
        for name, x, size in zip(("q0", "v0"), (self.q0, self.v0), system.state_sizes(), strict=True):
            if size is not None and x.shape != (size,):
                raise ValueError(f"{name} must have shape ({size},) for this system, got {x.shape}")
        check_unit_quaternions(self.q0, system.quaternions(), "q0")
        if knots is None:                 # a problem of one system: each step the same knot
            knots, first = Schedule([Knot(system, running)] * horizon, dt), 0
        # the system whose control the unknowns are (the first step's: every step's has the
        # same controls), for the state's manifold and the controls' number
        self.system, self.knots, self.terminal = system, knots, terminal
        self.controlled = (knots.phase[first], knots.index[first])
        self.integrator = integrator
        self.dt, self.horizon = float(dt), int(horizon)
        self.ndq = jax.eval_shape(system.difference, self.q0, self.q0).shape[0]
        nu = system.n_controls
        self.bounded = lower is not None or upper is not None
        bounds = []
        for name, value, default in (("lower", lower, -jnp.inf), ("upper", upper, jnp.inf)):
            value = jnp.full(nu, default) if value is None else jnp.asarray(value, dtype=float)
            if value.shape not in ((), (nu,)):
                raise ValueError(f"{name} must be a scalar or have one entry per actuated "
                                 f"coordinate ({nu}), got shape {value.shape}")
            bounds.append(jnp.broadcast_to(value, (nu,)))
        self.lower, self.upper = bounds
        if not isinstance(self.lower, jax.core.Tracer) and np.any(np.asarray(self.lower)
                                                                  > np.asarray(self.upper)):
            raise ValueError(f"lower must not exceed upper, got {self.lower} and {self.upper}")

    @property
    def running(self) -> Callable:
        """The first step's running cost (every step's, for a problem of one system)."""
        return self.knots.knot(*self.controlled).running

    @property
    def vectorized(self) -> bool:
        """Whether every phase's knots are vmapped (no contact solves: `AbstractKnot.
        vectorizable`): the costs of such a problem are taken over a rollout, vmapped, rather
        than priced as each step goes (one contact solve a knot for the step and its costs)."""
        return all(t.vectorizable() for t in self.knots.templates)

    @property
    def nq(self) -> int:
        """Length of q."""
        return self.q0.shape[0]

    @property
    def nv(self) -> int:
        """Length of v."""
        return self.v0.shape[0]

    @property
    def nx(self) -> int:
        """Length of the state x = (q, v)."""
        return self.nq + self.nv

    @property
    def nu(self) -> int:
        """Number of controls per step (the system's actuated coordinates)."""
        return self.system.n_controls

    @property
    def x0(self) -> Array:
        """The initial state (q0, v0), shape (nx,)."""
        return jnp.concatenate([self.q0, self.v0])

    def split(self, x: Array) -> tuple[Array, Array]:
        """(q, v) of a state x."""
        return x[..., :self.nq], x[..., self.nq:]

    def step(self, x: Array, u: Array, k) -> Array:
        """x_{k+1}: knot k's transition from x_k under the control u (a step of the integrator
        from t_k with the control held at u, or a knot's impulse)."""
        t = jnp.asarray(self.knots.times, x.dtype)[k]
        return self.knots.switch(k, self._transition, x, u, t)

    def step_cost(self, x: Array, u: Array, k) -> tuple[Array, Array]:
        """(x_{k+1}, knot k's running cost at (x_k, u)) from one solve of the knot's dynamics:
        a stance's contact costs read the forces its step solved (`Knot.advance`), rather than
        solving them again as `cost` does.

        Args:
            x: the state x_k, shape (nx,).
            u: the control, shape (nu,).
            k: the knot's index (may be traced).

        Returns:
            (x_{k+1}, the stage cost), shapes (nx,) and ().
        """
        t = jnp.asarray(self.knots.times, x.dtype)[k]
        return self.knots.switch(k, self._step_cost, x, u, t)

    def _step_cost(self, knot, x: Array, u: Array, t) -> tuple[Array, Array]:
        q, v = self.split(x)
        q1, v1, forces = knot.advance(self.integrator, t, q, v, u, jnp.asarray(self.dt, x.dtype))
        cost = _value(knot.cost(t, q, v, u, forces)) * jnp.asarray(knot.weight(self.dt), x.dtype)
        return jnp.concatenate([q1, v1]), cost

    def _transition(self, knot, x: Array, u: Array, t) -> Array:
        q, v = self.split(x)
        q1, v1 = knot.transition(self.integrator, t, q, v, u, jnp.asarray(self.dt, x.dtype))
        return jnp.concatenate([q1, v1])

    def _map(self, fn: Callable, *args):
        """fn(knot k, *args[k]) for every knot k, over each phase's knots in turn, so that each
        phase compiles once (`Schedule.map`)."""
        return self.knots.map(fn, *args)

    @property
    def n_phases(self) -> int:
        """The number of distinct phases, each compiled once: 1 for a problem of one system;
        alike knots, but for their arrays, make one phase."""
        return self.knots.n_phases

    def _phases(self) -> list:
        """A knot of each phase (its first)."""
        return [self.knots.knot(p, 0) for p in range(self.knots.n_phases)]

    def jumps(self) -> np.ndarray | None:
        """Which steps jump by design, one bool per knot: an `Impulse` (the velocity changes in
        no time); None where none does."""
        jumps = np.asarray([self.knots.templates[p].jumps() for p in self.knots.phase])
        return jumps if jumps.any() else None

    def times(self, dtype=float) -> Array:
        """Each knot's time t_k, shape (N,): k dt, an impulse taking none."""
        return jnp.asarray(self.knots.times, dtype)

    @property
    def ndx(self) -> int:
        """Length of a state deviation dx = difference(x_ref, x): ndq + nv."""
        return self.ndq + self.nv

    def integrate(self, x: Array, dx: Array) -> Array:
        """The state x (+) dx: the configuration moved along dq on its manifold, v + dv.

        Args:
            x: a state, shape (nx,).
            dx: a deviation, shape (ndx,).

        Returns:
            The state, shape (nx,).
        """
        q, v = self.split(x)
        q1 = self.system.project(self.system.retract(q, dx[:self.ndq]))
        return jnp.concatenate([q1, v + dx[self.ndq:]])

    def difference(self, x0: Array, x1: Array) -> Array:
        """The deviation dx with x0 (+) dx = x1.

        Args:
            x0: the reference state, shape (nx,).
            x1: a state, shape (nx,).

        Returns:
            dx, shape (ndx,).
        """
        (q0, v0), (q1, v1) = self.split(x0), self.split(x1)
        return jnp.concatenate([self.system.difference(q0, q1), v1 - v0])

    def linearize(self, xs: Array, us: Array) -> tuple:
        """The dynamics' and running costs' expansion about a trajectory, in the tangent space.

        Per step k: A = dF/ddx and B = dF/du at dx = 0, with F(dx, u) = difference(x_{k+1},
        step(x_k (+) dx, u)), and the gap e = F(0, u_k) (zero along a rollout); and the stage
        cost's (l_x, l_u, l_xx, l_ux, l_uu), exact or Gauss-Newton for residuals (see Costs in
        docs/details.md). One forward-mode pass for A and B: one per argument would trace the step
        twice, which costs more compilation than it saves (see benchmarks/README.md).

        Args:
            xs: states, shape (N + 1, nx).
            us: controls, shape (N, nu).

        Returns:
            ((A, B, e), (l_x, l_u, l_xx, l_ux, l_uu)), each with a first axis of N.
        """
        return self._map(self._stage, xs[:-1], us, self.times(xs.dtype), xs[1:])

    def _stage(self, knot, x: Array, u: Array, t, x_next: Array):
        """A knot's ((A, B, e), (l_x, l_u, l_xx, l_ux, l_uu)). A knot's residual costs may
        depend on its dynamics (a stance's contact forces in a friction cone): in a knot that
        solves contacts (not `AbstractKnot.vectorizable`) the step and the residuals are
        differentiated in one forward-mode pass over (dx, u), rather than one pass for the step
        and one per argument for the costs."""
        zero_q, zero_v = jnp.zeros(self.ndq, x.dtype), jnp.zeros(self.nv, x.dtype)
        running = self._about(x, lambda q, v, u, forces=None: knot.cost(t, q, v, u, forces))
        if knot.vectorizable() or not _is_residual(running, zero_q, zero_v, u):
            return self._jacobians(knot, x, u, t, x_next), self._expansion(knot, x, u, t)

        def both(dx, u):          # the costs read the forces the step solved (`Knot.advance`)
            q, v = self.split(self.integrate(x, dx))
            q1, v1, forces = knot.advance(self.integrator, t, q, v, u,
                                          jnp.asarray(self.dt, x.dtype))
            gap = self.difference(x_next, jnp.concatenate([q1, v1]))
            out = (gap, running(dx[:self.ndq], dx[self.ndq:], u, forces))
            return out, out

        ((A, B), (Jx, Ju)), (e, r) = jax.jacfwd(both, argnums=(0, 1), has_aux=True)(
            jnp.zeros(self.ndx, x.dtype), u)
        dt = jnp.asarray(knot.weight(self.dt), x.dtype)
        return (A, B, e), (Jx.T @ r * dt, Ju.T @ r * dt, Jx.T @ Jx * dt, Ju.T @ Jx * dt,
                           Ju.T @ Ju * dt)

    def defects(self, xs: Array, us: Array) -> Array:
        """Each step's gap e_k = difference(x_{k+1}, step(x_k, u_k)), shape (N, ndx): zero along
        a rollout, a multiple-shooting iterate's defects elsewhere."""
        return self._map(lambda knot, x, u, t, y: self.difference(
            y, self._transition(knot, x, u, t)), xs[:-1], us, self.times(xs.dtype), xs[1:])

    def _jacobians(self, knot, x: Array, u: Array, t, x_next: Array):
        def gap(dx, u):
            out = self.difference(x_next, self._transition(knot, self.integrate(x, dx), u, t))
            return out, out

        (A, B), e = jax.jacfwd(gap, argnums=(0, 1), has_aux=True)(
            jnp.zeros(self.ndx, x.dtype), u)
        return A, B, e

    def _stage_cost(self, knot, x: Array, u: Array, t) -> Array:
        """running(q, v, u) dt (1/2 |r|^2 dt for residuals r); an impulse's not times dt."""
        return _value(knot.cost(t, *self.split(x), u)) * jnp.asarray(knot.weight(self.dt), x.dtype)

    def final_cost(self, x: Array) -> Array:
        return _value(self.terminal(*self.split(x)))

    def _about(self, x: Array, fn: Callable) -> Callable:
        """fn(q, v, ...) as a function of the deviation (dq, dv, ...) about x."""
        q, v = self.split(x)
        return lambda dq, dv, *rest: fn(self.system.retract(q, dq), v + dv, *rest)

    def _expansion(self, knot, x: Array, u: Array, t):
        """(l_x, l_u, l_xx, l_ux, l_uu) of a knot's stage cost at (x, u), time t, in the
        tangent space."""
        zero_q, zero_v = jnp.zeros(self.ndq, x.dtype), jnp.zeros(self.nv, x.dtype)
        running = self._about(x, lambda q, v, u: knot.cost(t, q, v, u))
        dt = jnp.asarray(knot.weight(self.dt), x.dtype)
        if _is_residual(running, zero_q, zero_v, u):
            (Jq, Jv, Ju), r = _jacobian_and_value(running, zero_q, zero_v, u)
            Jx = jnp.concatenate([Jq, Jv], axis=1)
            return (Jx.T @ r * dt, Ju.T @ r * dt, Jx.T @ Jx * dt, Ju.T @ Jx * dt, Ju.T @ Ju * dt)

        def cost(dx, u):
            return _value(running(dx[:self.ndq], dx[self.ndq:], u)) * dt

        dx = jnp.zeros(self.ndx, x.dtype)
        (lx, lu), ((lxx, _), (lux, luu)) = (jax.grad(cost, argnums=(0, 1))(dx, u),
                                            jax.hessian(cost, argnums=(0, 1))(dx, u))
        return lx, lu, lxx, lux, luu

    def final_expansion(self, x: Array):
        """(V_x, V_xx) of the terminal cost at x in the tangent space, as `linearize`."""
        zero_q, zero_v = jnp.zeros(self.ndq, x.dtype), jnp.zeros(self.nv, x.dtype)
        terminal = self._about(x, self.terminal)
        if _is_residual(terminal, zero_q, zero_v):
            (Jq, Jv), r = _jacobian_and_value(terminal, zero_q, zero_v)
            J = jnp.concatenate([Jq, Jv], axis=1)
            return J.T @ r, J.T @ J

        def cost(dx):
            return _value(terminal(dx[:self.ndq], dx[self.ndq:]))

        dx = jnp.zeros(self.ndx, x.dtype)
        return jax.grad(cost)(dx), jax.hessian(cost)(dx)

    def rollout(self, us: Array) -> Array:
        """The states under a control sequence.

        Args:
            us: controls, shape (N, nu).

        Returns:
            The states x_0 ... x_N, shape (N + 1, nx).
        """
        def f(x, uk):
            u, k = uk
            x1 = self.step(x, u, k)
            return x1, x1
        _, xs = jax.lax.scan(f, self.x0, (us, jnp.arange(self.horizon)))
        return jnp.concatenate([self.x0[None], xs])

    def cost(self, xs: Array, us: Array) -> Array:
        """The objective of a trajectory (xs from `rollout`)."""
        return (jnp.sum(self._map(self._stage_cost, xs[:-1], us, self.times(xs.dtype)))
                + self.final_cost(xs[-1]))

    def objective(self, us: Array) -> Array:
        """The objective as a function of the controls alone (single shooting).

        Args:
            us: controls, shape (N, nu).

        Returns:
            The cost, a scalar.
        """
        return self.cost(self.rollout(us), us)

    def initial_controls(self, us0=None) -> Array:
        """us0 (N, nu), or zeros, inside the bounds."""
        us = (jnp.zeros((self.horizon, self.nu)) if us0 is None
              else jnp.asarray(us0, dtype=float))
        if us.shape != (self.horizon, self.nu):
            raise ValueError(f"us0 must be (horizon, nu) = ({self.horizon}, {self.nu}), got "
                             f"shape {us.shape}")
        return jnp.clip(us, self.lower, self.upper)

    def initial_states(self, states, us: Array) -> Array:
        """The knots' first states: `states` (N + 1, nx) with its first replaced by x0 and its
        configurations projected (unit quaternions), or the rollout of us where None."""
        if states is None:
            return self.rollout(us)
        xs = jnp.asarray(states, dtype=float)
        if xs.shape != (self.horizon + 1, self.nx):
            raise ValueError(f"states0 must be (horizon + 1, nq + nv) = ({self.horizon + 1}, "
                             f"{self.nx}), got shape {xs.shape}")
        q, v = self.split(xs)
        xs = jnp.concatenate([jax.vmap(self.system.project)(q), v], axis=1)
        return xs.at[0].set(self.x0)


def _is_residual(fn: Callable, *args) -> bool:
    return len(jax.eval_shape(fn, *args).shape) == 1


def _jacobian_and_value(fn: Callable, *args):
    """(dfn/d each arg, fn(*args)): one forward-mode pass per argument, so that the tangents of
    one argument do not travel through what only another touches (a cost's kinematics of q
    are not pushed along the v and u directions)."""
    def with_value(i):
        def partial(x):
            out = fn(*args[:i], x, *args[i + 1:])
            return out, out
        return jax.jacfwd(partial, has_aux=True)(args[i])
    jacobians, values = zip(*(with_value(i) for i in range(len(args))), strict=True)
    return jacobians, values[0]
