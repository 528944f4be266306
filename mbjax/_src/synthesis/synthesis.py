"""Gradient-based trajectory synthesis for the Carpal Wrist (Canfield 1997's stated purpose, §6.1:
'use the simulation environment as part of an optimization routine solving trajectory synthesis
problems').

The unknowns are the motors' torque histories, cubic B-splines saturated at the torque limit
(`mbjax.control.CubicSpline` with a limit). The objective is the effort int |tau|^2 dt plus penalties that bring the tool to
the goal pose at rest at t = duration:

    J = |(p(T) - p*) / l|^2 / tol^2 + |g(T) - g*|^2 / tol^2 + |theta_dot(T)|^2 / omega_tol^2
        + w int |tau|^2 dt / (limit^2 T),

with (p, g) the midplane chart of the final pose. Each evaluation of J runs the simulator
(`simulate`, RK4); its gradient is forward mode through the rollout's `lax.scan`; optax's Adam
takes the steps, and the whole descent is one `lax.scan`, so `synthesize` compiles once.
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.integrate import RK4, simulate
from mbjax._src.system.status import Flags, flags, WithStatus, raise_on_failure
from mbjax._src.synthesis.descent import adam_descent
from mbjax._src.control import CubicSpline
from mbjax._src.wrist import WristSystem, kinematics


class Synthesis(WithStatus):
    """The result of `synthesize`.

    Attributes:
        spline: the torque `mbjax.control.CubicSpline`, a control for `WristSystem`.
        losses: the objective at each iteration, shape (iterations,).
        theta_final: the final input angles [rad], shape (3,).
        theta_dot_final: their final rates [rad/s], shape (3,).
        final_pose_error: `pose_error` of the final pose against the goal.
        effort: int |tau|^2 dt [N^2 m^2 s].
        peak_torque: the peak |tau_i| [N m].
        status: the final rollout's `Status` flags.
    """

    spline: CubicSpline
    losses: Array
    theta_final: Array
    theta_dot_final: Array
    final_pose_error: Array
    effort: Array
    peak_torque: Array
    status: Flags = eqx.field(converter=flags)


def rollout(wrist, law, theta0: Array, duration: float, steps: int, integrator=RK4()):
    """The final (theta, theta_dot, status) of the wrist driven by `law` from rest at theta0."""
    sol = simulate(WristSystem(wrist, law), integrator, theta0, jnp.zeros_like(theta0),
                   dt=duration / steps, t1=duration, saveat=np.array([duration]))
    return sol.qs[-1], sol.vs[-1], sol.status


def effort(law, duration: float, samples: int = 400) -> tuple[Array, Array]:
    """(int |tau|^2 dt by the trapezoidal rule, peak |tau_i|) of an open-loop torque law."""
    ts = jnp.linspace(0.0, duration, samples + 1)
    tau = jax.vmap(lambda t: law(t, jnp.zeros(3), jnp.zeros(3)))(ts)
    sq = jnp.sum(tau**2, axis=1)
    return jnp.trapezoid(sq, ts), jnp.max(jnp.abs(tau))


def goal_pose(wrist, goal) -> kinematics.Pose:
    """The Pose of goal = (plunge, slope)."""
    return kinematics.pose_from_chart(wrist, jnp.asarray(goal[0], dtype=float), jnp.asarray(goal[1], dtype=float))


@eqx.filter_jit
def synthesize(wrist, theta0: Array, goal, *, duration: float, torque_limit: float, n_knots: int = 12,
               steps: int = 50, iterations: int = 400, learning_rate: float = 0.02,
               pose_tolerance: float = 1e-3, speed_tolerance: float = 1e-2, effort_weight: float = 0.1,
               integrator=RK4(), init: CubicSpline | None = None, throw: bool = False) -> Synthesis:
    """Torque splines that move the wrist from rest at theta0 to rest at goal = (plunge, slope)
    in `duration` with least effort, |tau_i| <= torque_limit (the objective in docs/details.md).

    Gradient-based trajectory synthesis, Canfield 1997's stated purpose (§6.1: 'use the
    simulation environment as part of an optimization routine solving trajectory synthesis
    problems'). The unknowns are the motors' torque histories, cubic B-splines saturated at the
    torque limit (`mbjax.control.CubicSpline` with a limit). Each evaluation of the objective J
    runs the simulator (`mbjax.simulate`, RK4 by default); optax's Adam takes the steps, and
    the whole descent is one `lax.scan`, so `synthesize` compiles once. The gradient is forward
    mode through the rollout (`jax.jacfwd` over the 3 n_knots spline values). The result's
    figures come from the same discrete rollout; re-simulate `spline` with a finer or
    higher-order integrator to see the continuous-time miss (`mbjax reproduce carpal-wrist`).

    Args:
        wrist: the `CarpalWrist`.
        theta0: the input angles at rest at t = 0 [rad], shape (3,).
        goal: (plunge [m], slope shape (2,)), the pose to reach at rest.
        duration: the manoeuvre's duration T [s]; static.
        torque_limit: the motors' saturation |tau_i| [N m].
        n_knots: spline knots per motor.
        steps: steps of `integrator` per rollout.
        iterations: Adam steps.
        learning_rate: Adam's initial learning rate (cosine-decayed to a tenth).
        pose_tolerance: tol, the scale of the final pose miss in the objective.
        speed_tolerance: omega_tol, the scale of the final speed [rad/s].
        effort_weight: w, the weight of the effort term.
        integrator: the rollouts' integrator (`mbjax.integrate.RK4()` by default).
        init: the starting spline; None: the constant torque that holds theta0 against
            gravity. The feed-forward baseline as a spline (`CubicSpline.fit`) starts far better.
        throw: raise on a failed final rollout instead of reporting it in `status`, as
            `mbjax.simulate` does.

    Returns:
        A `Synthesis`: the spline, the losses, the final state, the figures of merit and the
            final rollout's status (a non-finite state, a singular configuration).

    Raises:
        equinox.EquinoxRuntimeError: with throw=True, the final rollout failed.

    More on the objective: the documentation site's Details page (docs/details.md).
    """
    theta0 = jnp.asarray(theta0, dtype=float)
    goal_p, goal_g = (jnp.asarray(x, dtype=float) for x in goal)
    if init is None:
        hold = wrist.eom_terms(theta0, jnp.zeros_like(theta0))[2]
        init = CubicSpline.constant(jnp.clip(hold, -0.9 * torque_limit, 0.9 * torque_limit),
                                    n_knots, duration, torque_limit)
    shape = init.knots.shape

    def spline_of(x):
        return CubicSpline(x.reshape(shape), init.duration, init.limit)

    def objective(x):
        spline = spline_of(x)
        theta, theta_dot, _ = rollout(wrist, spline, theta0, duration, steps, integrator)
        plunge, slope = kinematics.midplane(wrist, theta)
        miss = (((plunge - goal_p) / wrist.link_length) ** 2 + jnp.sum((slope - goal_g) ** 2)) / pose_tolerance**2
        rest = jnp.sum(theta_dot**2) / speed_tolerance**2
        work = effort(spline, duration)[0] / (init.limit**2 * duration)
        return miss + rest + effort_weight * work

    x, losses = adam_descent(objective, init.knots.ravel(), learning_rate=learning_rate,
                             iterations=iterations, final_fraction=0.1)
    spline = spline_of(x)
    theta, theta_dot, status = rollout(wrist, spline, theta0, duration, steps, integrator)
    work, peak = effort(spline, duration)
    error = kinematics.pose_error(wrist, kinematics.forward_kinematics(wrist, theta), goal_pose(wrist, goal))
    return raise_on_failure(
        Synthesis(spline=spline, losses=losses, theta_final=theta, theta_dot_final=theta_dot,
                  final_pose_error=error, effort=work, peak_torque=peak, status=status),
        throw, "mbjax.wrist.synthesize")
