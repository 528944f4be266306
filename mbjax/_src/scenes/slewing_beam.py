"""A flexible arm slewed rest-to-rest: the classic single-link flexible manipulator (Cannon and
Schmitz 1984), a hub turned by a motor with a slender beam clamped to it, moving in a horizontal
plane, whose tip must arrive without residual vibration.

The beam is an aluminium strip, 1 m long with a 50 x 3 mm section (0.41 kg), bending in the
plane of motion about its thin axis: its clamped bending frequencies are 15.5 and 97 rad/s
(2.5 and 15.5 Hz). mbjax's model is a modal body on a revolute joint, solved by the O(n)
flexible recursion of `mbjax.flex` with its geometric stiffening (the flexible-multibody
paper's eqs 32-33): one flexible body (`mbjax/_src/flex/beam.py`, `N_ELEMENTS` beam elements, Craig-Bampton modes clamped at the hub, the
lowest `n_bending` in-plane bending modes, no axial one) whose rigid inertia includes the hub's
`HUB_INERTIA`. q = (hub angle, modal coordinates), the modes mass-normalized, so the vibration
energy is 1/2 sum(omega_i^2 eta_i^2 + eta_i'^2).

`slew_problem` asks for the hub turned by SLEW in DURATION with least torque and at the end no
vibration energy; `residual_vibration` measures what is left: the tip's largest deflection
while the arm coasts, torque off, for COAST after the manoeuvre.
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.flex import Beam, FlexibleModel, FlexibleSystem, beam_body
from mbjax._src.flex import centreline as flex_centreline
from mbjax._src.integrate import RK4
from mbjax._src.model import Model
from mbjax._src.scenes.spin_up_beam import modes
from mbjax._src.trajopt import Problem

LENGTH, WIDTH, THICKNESS = 1.0, 0.05, 0.003        # [m]
E, G, DENSITY = 7.0e10, 2.6e10, 2700.0             # aluminium [Pa], [Pa], [kg/m^3]
HUB_INERTIA = 0.05                                 # [kg m^2] about the hub's axis
N_ELEMENTS = 8
SLEW, DURATION, DT = np.pi / 2, 1.0, 0.01          # [rad], [s], [s]
COAST = 1.0                                        # [s] of coasting to measure the vibration


def beam() -> Beam:
    """The aluminium strip (1 m, 50 x 3 mm) as N_ELEMENTS beam elements.

    Returns:
        The `mbjax.flex.Beam`, bending in the plane of motion about its thin axis.
    """
    area = WIDTH * THICKNESS
    bending = WIDTH * THICKNESS**3 / 12            # in the plane of motion: about the thin axis
    return Beam(LENGTH, E, G, DENSITY, area, WIDTH**3 * THICKNESS / 12, bending,
                bending + WIDTH**3 * THICKNESS / 12, N_ELEMENTS)


def model(n_bending: int = 2) -> FlexibleModel:
    """The hub and beam: a revolute joint about z carrying the flexible beam along x.

    Args:
        n_bending: the number of in-plane bending modes kept (Craig-Bampton, clamped at the
            hub; no axial mode).

    Returns:
        The `mbjax.flex.FlexibleModel`, q = (hub angle, modal coordinates).
    """
    structure = beam()
    mass = DENSITY * WIDTH * THICKNESS * LENGTH
    body = beam_body(structure, modes(structure, n_bending, 0), nodes=(N_ELEMENTS,))
    # the hub, a disk at the clamp, which does not deform: rigid rotary inertia on the body
    hub = np.diag([0.5, 0.5, 1.0]) * HUB_INERTIA
    body = eqx.tree_at(lambda b: b.rotary, body, body.rotary + hub)
    rigid = Model([-1], ["revolute"], mass=[mass], com=[[LENGTH / 2, 0.0, 0.0]],
                  inertia=[np.diag([1e-9, 1.0, 1.0]) * mass * LENGTH**2 / 12 + hub],
                  axis=[[0.0, 0.0, 1.0]], gravity=(0.0, 0.0, -9.81))
    return FlexibleModel(rigid, {0: body})


def frequencies(arm: FlexibleModel) -> Array:
    """The modes' frequencies (K_r = diag(omega^2) for mass-normalized modes).

    Args:
        arm: the model from `model`.

    Returns:
        The frequencies [rad/s], shape (n_bending,).
    """
    return jnp.sqrt(jnp.diag(arm.bodies.stiffness[0]))


def tip(arm: FlexibleModel, q: Array) -> Array:
    """The tip's transverse deflection in the hub's rotating frame.

    Args:
        arm: the model from `model`.
        q: configuration, shape (nq,).

    Returns:
        The deflection [m], a scalar.
    """
    _, qf = arm.split(q)
    return arm.bodies.node_phi[0, 0, 1] @ qf[0]


def centreline(arm: FlexibleModel, qs, points: int = 11, magnification: float = 1.0) -> np.ndarray:
    """World positions along the beam's centreline, for pictures and animations.

    The modal deflection (times `magnification`) in the hub frame (`mbjax.flex.centreline`),
    turned by the hub angle.

    Args:
        arm: the model from `model`.
        qs: configurations, shape (T, nq).
        points: the number of points along the beam.
        magnification: the factor on the deflection.

    Returns:
        The positions [m], a NumPy array of shape (T, points, 3).
    """
    structure = beam()
    basis = modes(structure, arm.bodies.stiffness.shape[-1], 0)     # the basis `model` was built on
    qs = np.asarray(qs)
    local = np.asarray(flex_centreline(structure, basis, qs[:, 1:], points, magnification))
    c, s = np.cos(qs[:, 0])[:, None], np.sin(qs[:, 0])[:, None]
    return np.stack([c * local[..., 0] - s * local[..., 1], s * local[..., 0] + c * local[..., 1],
                     local[..., 2]], axis=-1)


def _slew_running(q, v, u):
    return u


def _slew_terminal(q, v, *, goal, omega):
    return jnp.concatenate([100.0 * (q[:1] - goal), 10.0 * v[:1], 100.0 * omega * q[1:],
                            100.0 * v[1:]])


def slew_problem(n_bending: int = 2, slew=SLEW, duration: float = DURATION) -> Problem:
    """The rest-to-rest slew without residual vibration, as a trajectory-optimisation problem.

    The hub from rest turned by `slew` to rest in `duration` (RK4, DT, torque held over each
    step), with least effort: the running residual is the hub torque (cost 1/2 u^2 dt); the
    terminal residuals 100 (theta_N - slew), 10 theta'_N and 100 (omega_i eta_i, eta_i') of
    each mode, so that the final cost holds 10^4 times the vibration energy left.

    Args:
        n_bending: the number of bending modes.
        slew: the hub's turn [rad].
        duration: the manoeuvre's duration [s].

    Returns:
        The `mbjax.trajopt.Problem`, its control the hub torque (nu = 1).
    """
    arm = model(n_bending)
    steps = round(duration / DT)
    terminal = eqx.Partial(_slew_terminal, goal=jnp.asarray(slew, float),
                           omega=frequencies(arm))
    return Problem(FlexibleSystem(arm, actuation=[0]), jnp.zeros(arm.nq), jnp.zeros(arm.nv),
                   dt=DT, horizon=steps, running=_slew_running, terminal=terminal,
                   integrator=RK4())


def rigid_guess(problem: Problem) -> Array:
    """The least-effort rest-to-rest torque of the arm taken as rigid.

    A torque falling linearly from 6 J slew / T^2 to its negative, J the hub's and beam's
    inertia about the axis: the first guess, and the baseline whose residual vibration the
    optimum suppresses.

    Args:
        problem: the slew problem.

    Returns:
        The torques [N m], shape (horizon, 1).
    """
    arm = problem.system.model
    second = arm.bodies.second[0]                        # sum m (rho, phi) (rho, phi)^T
    J = arm.bodies.rotary[0, 2, 2] + second[0, 0, 0, 0] + second[1, 0, 1, 0]   # about z
    T = problem.horizon * problem.dt
    t = (jnp.arange(problem.horizon) + 0.5) * problem.dt
    slew = problem.terminal.keywords["goal"]
    return (J * 6 * slew / T**2 * (1 - 2 * t / T))[:, None]


@eqx.filter_jit
def residual_vibration(problem: Problem, xN: Array, coast: float = COAST) -> Array:
    """The residual vibration: the tip's largest transverse deflection while the arm coasts, torque off.

    Args:
        problem: the slew problem.
        xN: the final state (q, v), shape (nq + nv,).
        coast: how long the arm coasts [s].

    Returns:
        The largest deflection [m], a scalar.
    """
    steps = round(coast / problem.dt)

    def step(x, k):
        x = problem.step(x, jnp.zeros(problem.nu, x.dtype), problem.horizon + k)
        return x, tip(problem.system.model, problem.split(x)[0])

    _, deflection = jax.lax.scan(step, xN, jnp.arange(steps))
    return jnp.max(jnp.abs(deflection))
