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

from mbjax._src.control import Constant
from mbjax._src.integrate import RK4
from mbjax._src.integrate.base import AbstractIntegrator
from mbjax._src.lie.inputs import check_unit_quaternions
from mbjax._src.system.system import AbstractSystem


class Problem(eqx.Module):
    """A discrete optimal-control problem over a system's controls, to pass to `solve`.

    The unknowns are the controls u_0 ... u_{N-1} on the system's actuated coordinates, one per
    step of length dt, held over the step; the problem minimizes the running costs' sum times dt
    plus the terminal cost, subject to the system's dynamics stepped by `integrator` and the
    bounds on the controls.

    Args:
        system: any mbjax system with a control (`TreeSystem`, `FlexibleSystem`, `WristSystem`,
            `RigidBody`, a `ClosedSystem` of a tree, ...); its control is replaced by the
            unknowns u_k.
        q0 (Array): initial configuration, shape (nq,).
        v0 (Array): initial velocity, shape (nv,).
        dt: the step and control interval, seconds (keyword only).
        horizon: the number of steps N (keyword only).
        running: cost rate running(q, v, u), a scalar or a vector of residuals; or a tuple of
            such functions, their sum (keyword only; see Costs, below).
        terminal: final cost terminal(q, v), likewise (keyword only).
        lower (float | Array | None): lower bound on each actuated force, a scalar or shape
            (nu,); None for none.
        upper (float | Array | None): upper bound, likewise.
        integrator: the step's integrator (`RK4()` by default).

    Raises:
        TypeError: naming the malformed argument: a system that is not an mbjax system or has
            no control, an integrator that is not an instance, costs that are not callables.
        ValueError: naming the malformed argument: a state of the wrong shape, a non-positive
            dt or horizon, bounds of the wrong shape, lower above upper.

    Formulation:
        The unknowns are the controls u_0 ... u_{N-1}, one value per step of length dt held over
        the step (a zero-order hold, as a digital controller and MuJoCo's `ctrl` apply them), on
        the system's actuated velocity coordinates (its `actuation`, all of them by default). The
        state is x = (q, v), and the discrete problem is

        ```text
        minimize    sum_k running(q_k, v_k, u_k) dt + terminal(q_N, v_N)
        subject to  x_{k+1} = step(x_k, u_k)       (one step of `integrator` from t_k = k dt)
                    lower <= u_k <= upper,
        ```

        where `step` runs the system with the constant control u_k, as `mbjax.simulate` would (its
        `hold`, and after the step its `constrain`: a closed loop's projection). Running costs are
        rates, weighted by dt as in Crocoddyl's integrated action models, so a problem's optimum
        does not depend on how finely its horizon is cut. Costs are any JAX functions: weights held
        in an equinox module are differentiable like the model's parameters.

    Manifolds:
        States live on the system's configuration manifold (a floating base's quaternion, a
        continuous joint's angle): second-order solvers linearize in its tangent space, a deviation
        being dx = difference(x_ref, x) = (system.difference(q_ref, q), v - v_ref), of length ndx =
        2 nv for a tree (Crocoddyl's `StateMultibody`), and move along it with integrate(x, dx) =
        (retract(q, dq), v + dv). On Euclidean coordinates both are plain subtraction and addition.

    Costs:
        A cost function returns either a scalar, taken as it is, or a vector of residuals r, meaning
        the least-squares cost 1/2 |r|^2 (weights folded into r). The second form is what
        second-order solvers want: its Hessian is taken as J^T J with J = dr/d(x, u) (Gauss-Newton,
        as Crocoddyl's residual models do), positive semidefinite wherever the trajectory is, where
        a scalar cost's exact Hessian (an end-effector distance, say) can be indefinite far from the
        optimum. A tuple of cost functions is their sum (the residuals stacked).
        `mbjax.trajopt.state_residual`, `frame_residual` and `control_residual` write Crocoddyl's
        common costs.
    """

    system: AbstractSystem
    q0: Array
    v0: Array
    running: Callable
    terminal: Callable
    lower: Array
    upper: Array
    integrator: AbstractIntegrator
    dt: float = eqx.field(static=True)
    horizon: int = eqx.field(static=True)
    ndq: int = eqx.field(static=True)   # a configuration deviation's length (nv for a tree)
    bounded: bool = eqx.field(static=True)   # whether lower or upper was given

    def __init__(self, system: AbstractSystem, q0, v0, *, dt: float, horizon: int,
                 running: Callable, terminal: Callable, lower=None, upper=None,
                 integrator: AbstractIntegrator = RK4()):
        if not isinstance(system, AbstractSystem):
            raise TypeError(f"system must be an mbjax system (TreeSystem, ...), got "
                            f"{type(system).__name__}")
        if not isinstance(integrator, AbstractIntegrator):
            raise TypeError(f"integrator must be an instance such as RK4(), got {integrator!r}")
        if not (isinstance(horizon, int | np.integer) and horizon >= 1):
            raise ValueError(f"horizon must be a positive int (the number of steps), got {horizon!r}")
        if not (isinstance(dt, int | float | np.integer | np.floating | np.ndarray | jax.Array)
                and not isinstance(dt, bool) and np.ndim(dt) == 0
                and np.isrealobj(dt) and float(dt) > 0 and np.isfinite(dt)):
            raise ValueError(f"dt must be a positive number, finite, got {dt!r}")
        running, terminal = (Sum(tuple(c)) if isinstance(c, list | tuple) else c
                             for c in (running, terminal))
        if not (callable(running) and callable(terminal)):
            raise TypeError("running(q, v, u) and terminal(q, v) must be callables returning "
                            "a scalar cost or a vector of residuals")
        self.system = system
        self.q0, self.v0 = jnp.asarray(q0, dtype=float), jnp.asarray(v0, dtype=float)
        if self.q0.ndim != 1 or self.v0.ndim != 1:
            raise ValueError(f"q0 and v0 must be vectors, got shapes {self.q0.shape} and "
                             f"{self.v0.shape}")
        system.with_control(None)                   # raises for a system without a control
        for name, x, size in zip(("q0", "v0"), (self.q0, self.v0), system.state_sizes(), strict=True):
            if size is not None and x.shape != (size,):
                raise ValueError(f"{name} must have shape ({size},) for this system, got {x.shape}")
        check_unit_quaternions(self.q0, system.quaternions(), "q0")
        self.running, self.terminal = running, terminal
        self.integrator = integrator
        self.dt, self.horizon = float(dt), int(horizon)
        self.ndq = jax.eval_shape(system.difference, self.q0, self.q0).shape[0]
        nu = self.nu
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
        """x_{k+1}: one step of the integrator from t_k = k dt with the control held at u."""
        q, v = self.split(x)
        t = jnp.asarray(k, x.dtype) * self.dt
        system = self.system.with_control(Constant(u)).hold(t, q, v)
        q1, v1, _ = self.integrator.step(system, t, q, v, jnp.asarray(self.dt, x.dtype))
        q1, v1 = system.constrain(t + self.dt, q1, v1)
        return jnp.concatenate([q1, v1])

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

    def step_jacobians(self, x: Array, u: Array, k, x_next: Array):
        """(A, B, e): the step's Jacobians in the tangent spaces, and its gap.

        With F(dx, u) = difference(x_next, step(x (+) dx, u)), A = dF/ddx and B = dF/du at
        dx = 0 and e = F(0, u), the step's defect against the knot x_next (zero along a
        rollout). One forward-mode pass for both: one pass per argument would trace the step
        twice, which costs more compilation than it saves (see benchmarks/README.md).
        """
        def gap(dx, u):
            out = self.difference(x_next, self.step(self.integrate(x, dx), u, k))
            return out, out

        (A, B), e = jax.jacfwd(gap, argnums=(0, 1), has_aux=True)(
            jnp.zeros(self.ndx, x.dtype), u)
        return A, B, e

    def stage_cost(self, x: Array, u: Array) -> Array:
        """running(q, v, u) dt (1/2 |r|^2 dt for residuals r)."""
        return _value(self.running(*self.split(x), u)) * self.dt

    def final_cost(self, x: Array) -> Array:
        return _value(self.terminal(*self.split(x)))

    def _about(self, x: Array, fn: Callable) -> Callable:
        """fn(q, v, ...) as a function of the deviation (dq, dv, ...) about x."""
        q, v = self.split(x)
        return lambda dq, dv, *rest: fn(self.system.retract(q, dq), v + dv, *rest)

    def stage_expansion(self, x: Array, u: Array):
        """(l_x, l_u, l_xx, l_ux, l_uu) of the stage cost at (x, u) in the tangent space:
        exact, or Gauss-Newton for residuals (see Costs, in `Problem`)."""
        zero_q, zero_v = jnp.zeros(self.ndq, x.dtype), jnp.zeros(self.nv, x.dtype)
        running = self._about(x, self.running)
        if _is_residual(running, zero_q, zero_v, u):
            (Jq, Jv, Ju), r = _jacobian_and_value(running, zero_q, zero_v, u)
            Jx, dt = jnp.concatenate([Jq, Jv], axis=1), self.dt
            return (Jx.T @ r * dt, Ju.T @ r * dt, Jx.T @ Jx * dt, Ju.T @ Jx * dt, Ju.T @ Ju * dt)

        def cost(dx, u):
            return _value(running(dx[:self.ndq], dx[self.ndq:], u)) * self.dt

        dx = jnp.zeros(self.ndx, x.dtype)
        (lx, lu), ((lxx, _), (lux, luu)) = (jax.grad(cost, argnums=(0, 1))(dx, u),
                                            jax.hessian(cost, argnums=(0, 1))(dx, u))
        return lx, lu, lxx, lux, luu

    def final_expansion(self, x: Array):
        """(V_x, V_xx) of the terminal cost at x in the tangent space, as `stage_expansion`."""
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
        return jnp.sum(jax.vmap(self.stage_cost)(xs[:-1], us)) + self.final_cost(xs[-1])

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


def _value(c: Array) -> Array:
    """A cost function's output as a cost: itself, or 1/2 |r|^2 for residuals r."""
    c = jnp.asarray(c)
    if c.ndim > 1:
        raise ValueError(f"a cost must return a scalar or a vector of residuals, got shape {c.shape}")
    return 0.5 * c @ c if c.ndim == 1 else c


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


class Sum(eqx.Module):
    """A sum of cost functions: their residuals stacked where each returns residuals, else the
    sum of their values (a residual vector r counting 1/2 |r|^2)."""

    terms: tuple

    def __call__(self, *args) -> Array:
        values = [jnp.asarray(term(*args)) for term in self.terms]
        if all(v.ndim == 1 for v in values):
            return jnp.concatenate(values)
        return sum(_value(v) for v in values)
