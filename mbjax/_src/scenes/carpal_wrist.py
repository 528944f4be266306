"""A Carpal Wrist carrying a tool: the robot of Canfield 1997 at the scale of a surgical or small
industrial wrist, with the scenarios the tests, the tour, the reproduction and the notebooks use.

The tool's centre of mass sits off the axis (TOOL_COM) and its inertia is not axisymmetric, so the
physical mirror plate and the chapter's printed rotation give different dynamics.

- `free_motion`: zero torque, no gravity, released with THETA_DOT0 from HOME: energy is conserved
  and the motion stays inside the workspace for FREE_DURATION (the integrator accuracy study).
- `servo`: a joint PD servo (stiffness SERVO_K, damping SERVO_D, gravity feed-forward) holding
  HOME, released from HOME + SERVO_OFFSET under gravity: the step-size stability study.
- START and GOAL: two tool poses (plunge, slope) for trajectory synthesis, DURATION apart;
  `synthesis_problem` poses the move as a `mbjax.trajopt.Problem` under TORQUE_LIMIT.
"""

import equinox as eqx
import jax.numpy as jnp
import numpy as np

from mbjax._src.wrist import CarpalWrist, WristSystem, kinematics, servo as servo_law

BASE_RADIUS = 0.06                           # [m]
LINK_LENGTH = 0.10                           # [m]
TOOL_MASS = 1.5                              # [kg]
TOOL_INERTIA = np.diag([4e-3, 3e-3, 1e-3])   # [kg m^2] about the tool's centre of mass, in D
TOOL_COM = np.array([0.01, -0.005, 0.08])    # [m] from the distal-plate centre, in D
HOME_PLUNGE = 0.075                          # [m]: theta_i = pi/2 + acos(0.75) = 2.29 rad

THETA_DOT0 = np.array([0.6, -0.4, 0.16])     # [rad/s]
FREE_DURATION = 0.4                          # [s]
SERVO_K = 60.0                               # [N m / rad]
SERVO_D = 0.4                                # [N m s / rad]
SERVO_OFFSET = np.array([0.05, -0.03, 0.02])  # [rad]
SERVO_DURATION = 1.0                         # [s]

START = (0.070, np.array([0.25, -0.10]))     # (plunge [m], slope): beta = 30.8 deg
GOAL = (0.080, np.array([-0.20, 0.25]))      # beta = 35.5 deg, on the other side
DURATION = 0.5                               # [s]
TORQUE_LIMIT = 1.8                           # [N m]: below the baseline's peak (1.96 N m)


def wrist(rotation_model: str = "physical", gravity: float = 9.81) -> CarpalWrist:
    """The scene's wrist: BASE_RADIUS, LINK_LENGTH and the tool (TOOL_MASS, TOOL_INERTIA, TOOL_COM).

    Args:
        rotation_model: "physical" (the mirror plate) or "chapter" (Canfield 1997's printed
            rotation).
        gravity: the acceleration of gravity [m/s^2].

    Returns:
        The `CarpalWrist`.
    """
    return CarpalWrist(BASE_RADIUS, LINK_LENGTH, tool_mass=TOOL_MASS, tool_inertia=TOOL_INERTIA,
                       tool_com=TOOL_COM, gravity=gravity, rotation_model=rotation_model)


def home(w: CarpalWrist | None = None) -> jnp.ndarray:
    """The joint angles at the home pose (beta = 0, plunge HOME_PLUNGE).

    Args:
        w: the wrist; None for `wrist()`.

    Returns:
        theta [rad], shape (3,).
    """
    w = wrist() if w is None else w
    return w.solve_inverse_kinematics(HOME_PLUNGE, jnp.zeros(2))[0]


def free_motion(rotation_model: str = "physical"):
    """The free-motion scenario: torque-free, gravity-free motion from HOME released with THETA_DOT0.

    Args:
        rotation_model: "physical" or "chapter" (see `wrist`).

    Returns:
        system: the `WristSystem`, no control.
        theta0: the home pose [rad], shape (3,).
        theta_dot0: THETA_DOT0 [rad/s], shape (3,).
    """
    w = wrist(rotation_model, gravity=0.0)
    return WristSystem(w), home(w), jnp.asarray(THETA_DOT0)


def servo():
    """The servo scenario: a joint PD servo holding HOME under gravity, released from HOME + SERVO_OFFSET.

    Returns:
        system: the `WristSystem` with the servo (SERVO_K, SERVO_D, gravity feed-forward).
        theta0: the offset start [rad], shape (3,).
        theta_dot0: zeros, shape (3,).
    """
    w = wrist()
    law = servo_law(w, home(w), SERVO_K, SERVO_D)
    return WristSystem(w, law), home(w) + jnp.asarray(SERVO_OFFSET), jnp.zeros(3)


def build():
    """The scene's default: the free motion (`free_motion()`).

    Returns:
        system: the `WristSystem`.
        theta0: the home pose [rad], shape (3,).
        theta_dot0: THETA_DOT0 [rad/s], shape (3,).
    """
    return free_motion()


def _synthesis_running(q, v, u, *, limit):
    return jnp.concatenate([0.3 * u / limit, 1e-3 * v])


def _synthesis_terminal(q, v, *, wrist, goal_plunge, goal_slope):
    plunge, slope = kinematics.midplane(wrist, q)
    return jnp.concatenate([1e3 * jnp.atleast_1d(plunge - goal_plunge) / wrist.link_length,
                            1e3 * (slope - goal_slope), 10.0 * v])


def synthesis_problem(w: CarpalWrist | None = None, steps: int = 100):
    """The move START -> GOAL at rest in DURATION, |tau_i| <= TORQUE_LIMIT, as a trajopt problem.

    RK4, `steps` knots of held torques; least-squares residuals: along the way the torques
    scaled by the limit (0.3) and a trace of the speed (1e-3), at the end the midplane chart's
    miss (1e3 per link length in plunge, 1e3 in slope) and the speed (10).

    Args:
        w: the wrist; None for `wrist()`.
        steps: the number of knots.

    Returns:
        The `mbjax.trajopt.Problem`, its controls the three joint torques.
    """
    from mbjax._src.trajopt import Problem

    w = wrist() if w is None else w
    theta0 = w.solve_inverse_kinematics(*START)[0]
    return Problem(WristSystem(w), theta0, jnp.zeros(3), dt=DURATION / steps, horizon=steps,
                   running=eqx.Partial(_synthesis_running, limit=jnp.asarray(TORQUE_LIMIT)),
                   terminal=eqx.Partial(_synthesis_terminal, wrist=w,
                                        goal_plunge=jnp.asarray(GOAL[0]),
                                        goal_slope=jnp.asarray(GOAL[1])),
                   lower=-TORQUE_LIMIT, upper=TORQUE_LIMIT)


def synthesis_guess(problem) -> jnp.ndarray:
    """A first guess for `synthesis_problem`: the feed-forward torques along the minimum-jerk tool path.

    The inverse dynamics along the path (`mbjax.wrist.feedforward_torques`) at the middle of
    each step, clipped to the torque limit.

    Args:
        problem: the synthesis problem.

    Returns:
        The torques [N m], shape (horizon, 3).

    Raises:
        equinox.EquinoxRuntimeError: the tool path leaves the workspace.
    """
    from mbjax._src.synthesis.baseline import ToolPath, feedforward_torques

    ts = (np.arange(problem.horizon) + 0.5) * problem.dt
    tau = feedforward_torques(problem.system.model, ToolPath(START, GOAL, DURATION), ts)
    return jnp.clip(jnp.asarray(tau), -TORQUE_LIMIT, TORQUE_LIMIT)
