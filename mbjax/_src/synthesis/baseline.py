"""The inverse-dynamics feed-forward baseline for trajectory synthesis: a smooth tool-space path
through `inverse_kinematics` and `inverse_dynamics` (Canfield 1997 eq 6.16 used as the chapter
intends, 'when the manipulator path is known, the required moment for each motor can be
determined').

The path is a quintic (minimum-jerk) blend, at rest at both ends, in the wrist's nonsingular
midplane chart (plunge, slope): (alpha, beta) would be singular at the home pose.
"""

import equinox as eqx
import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.wrist import kinematics


def min_jerk(s: Array) -> Array:
    """10 s^3 - 15 s^4 + 6 s^5: 0 to 1 with zero rate and curvature at both ends."""
    s = jnp.clip(s, 0.0, 1.0)
    return s**3 * (10 - 15 * s + 6 * s**2)


class ToolPath(eqx.Module):
    """A tool path in the midplane chart: plunge and slope blended from `start` to `goal` by the
    quintic (minimum-jerk) profile, at rest at both ends.

    Args:
        start (tuple[float, Array]): (plunge [m], slope shape (2,)) at t = 0.
        goal (tuple[float, Array]): (plunge [m], slope shape (2,)) at t = duration.
        duration: the blend's duration [s]; static.
    """

    start_plunge: Array
    start_slope: Array
    goal_plunge: Array
    goal_slope: Array
    duration: float = eqx.field(static=True)

    def __init__(self, start, goal, duration: float):
        self.start_plunge, self.goal_plunge = (jnp.asarray(x[0], dtype=float) for x in (start, goal))
        self.start_slope, self.goal_slope = (jnp.asarray(x[1], dtype=float) for x in (start, goal))
        self.duration = float(duration)

    def chart(self, t: Array) -> tuple[Array, Array]:
        """(plunge [m], slope shape (2,)) at time t [s] (held at the ends outside [0, duration])."""
        s = min_jerk(t / self.duration)
        return (self.start_plunge + s * (self.goal_plunge - self.start_plunge),
                self.start_slope + s * (self.goal_slope - self.start_slope))

    def joint_motion(self, wrist, t: Array) -> tuple[Array, Array, Array, Array]:
        """The joint motion along the path, its derivatives in t by autodiff.

        Args:
            wrist: the `CarpalWrist`.
            t: time [s], a scalar.

        Returns:
            (theta [rad], theta_dot [rad/s], theta_ddot [rad/s^2], each shape (3,);
                reachable, a boolean scalar).
        """
        def theta(time):
            return kinematics.solve_inverse_kinematics(wrist, *self.chart(time))[0]

        def rate(time):
            return jax.jvp(theta, (time,), (jnp.ones_like(time),))
        (q, q_dot), (_, q_ddot) = jax.jvp(rate, (t,), (jnp.ones_like(t),))
        return q, q_dot, q_ddot, kinematics.solve_inverse_kinematics(wrist, *self.chart(t))[1]


class FeedForward(eqx.Module):
    """The open-loop torque tau_ff(t) = inverse_dynamics along `path` (ignores the state)."""

    path: ToolPath

    def __call__(self, wrist, t: Array, theta: Array, theta_dot: Array) -> Array:
        q, q_dot, q_ddot, _ = self.path.joint_motion(wrist, jnp.asarray(t, dtype=theta.dtype))
        return wrist.inverse_dynamics(q, q_dot, q_ddot)


@eqx.filter_jit
def feedforward_torques(wrist, path: ToolPath, ts: Array) -> Array:
    """The feed-forward motor torques along a tool path: inverse kinematics, then the
    inverse dynamics of eq 6.16.

    Args:
        wrist: the `CarpalWrist`.
        path: the `ToolPath`.
        ts: times [s], shape (k,).

    Returns:
        tau_ff [N m], shape (k, 3).

    Raises:
        equinox.EquinoxRuntimeError: the path leaves the workspace.
    """
    q, q_dot, q_ddot, ok = jax.vmap(lambda t: path.joint_motion(wrist, t))(jnp.asarray(ts, dtype=float))
    tau = jax.vmap(wrist.inverse_dynamics)(q, q_dot, q_ddot)
    return eqx.error_if(tau, ~jnp.all(ok), "the tool path leaves the Carpal Wrist's workspace")
