"""A neural controller for the Carpal Wrist trained through the differentiable simulator (seed 003
§6.1: 'the simulation environment can be used to train a neural network control system').

The controller is a small equinox MLP mapping (theta - theta*, theta_dot, theta*) to motor torques,
saturated at the torque limit; theta* = inverse kinematics of the target pose. Training rolls out
a batch of random (start, target) pairs with `simulate` (vmapped), and descends with optax's Adam on
the mean of the tracking cost

    J = mean_k |y(t_k) - y*|^2 / tol^2 + |theta_dot(T)|^2 / omega_tol^2 + w int |tau|^2 dt / (limit^2 T),

y = (p / l, g) the pose in the midplane chart, t_k the saved times: reverse mode through the
rollouts, one jitted `lax.scan` over the iterations. Success on held-out targets: the final pose
within `kinematics.pose_error` < `success_tolerance`.
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optax
from jax import Array

from mbjax.integrate import RK4, simulate
from mbjax.wrist import WristSystem, kinematics


class NeuralController(eqx.Module):
    """tau = limit tanh(MLP(theta - theta*, theta_dot / omega_scale, theta* - theta_centre))."""

    mlp: eqx.nn.MLP
    limit: Array
    target: Array
    theta_centre: Array
    omega_scale: float = eqx.field(static=True, default=5.0)

    def __init__(self, key, limit: float, theta_centre, width: int = 32, depth: int = 2,
                 omega_scale: float = 5.0):
        self.mlp = eqx.nn.MLP(9, 3, width, depth, activation=jnp.tanh, key=key)
        self.limit = jnp.asarray(limit, dtype=float)
        self.theta_centre = jnp.asarray(theta_centre, dtype=float)
        self.target = self.theta_centre
        self.omega_scale = omega_scale

    def aimed_at(self, target: Array) -> "NeuralController":
        """The same network steering to joint target theta*."""
        return eqx.tree_at(lambda c: c.target, self, jnp.asarray(target, dtype=float))

    def __call__(self, wrist, t: Array, theta: Array, theta_dot: Array) -> Array:
        x = jnp.concatenate([theta - self.target, theta_dot / self.omega_scale,
                             self.target - self.theta_centre])
        return self.limit * jnp.tanh(self.mlp(x))


def sample_poses(key, n: int, plunge_range, max_slope: float) -> tuple[Array, Array]:
    """n poses (plunge, slope) uniform in plunge and in the slope disk |g| <= max_slope."""
    kp, kr, ka = jax.random.split(key, 3)
    plunge = jax.random.uniform(kp, (n,), minval=plunge_range[0], maxval=plunge_range[1])
    radius = max_slope * jnp.sqrt(jax.random.uniform(kr, (n,)))
    angle = jax.random.uniform(ka, (n,), maxval=2 * jnp.pi)
    return plunge, radius[:, None] * jnp.stack([jnp.cos(angle), jnp.sin(angle)], axis=1)


class Episodes(eqx.Module):
    """A batch of (start theta, target theta, target plunge, target slope)."""

    start: Array
    target: Array
    target_plunge: Array
    target_slope: Array


def make_episodes(wrist, key, n: int, plunge_range=(0.065, 0.085), max_slope: float = 0.35) -> Episodes:
    """Random start and target poses in the workspace (knees-out inverse kinematics)."""
    k1, k2 = jax.random.split(key)
    ik = jax.vmap(lambda p, g: kinematics.solve_inverse_kinematics(wrist, p, g))
    (p0, g0), (p1, g1) = sample_poses(k1, n, plunge_range, max_slope), sample_poses(k2, n, plunge_range, max_slope)
    (start, ok0), (target, ok1) = ik(p0, g0), ik(p1, g1)
    if not bool(jnp.all(ok0 & ok1)):
        raise ValueError("sampled poses outside the workspace: narrow plunge_range or max_slope")
    return Episodes(start=start, target=target, target_plunge=p1, target_slope=g1)


def episode_cost(controller, wrist, start, target, plunge, slope, *, duration, steps, saves,
                 pose_tolerance, speed_tolerance, effort_weight):
    """The cost J of one episode and its final pose error (see the module docstring)."""
    law = controller.aimed_at(target)
    sol = simulate(WristSystem(wrist, law), RK4(), start, jnp.zeros_like(start), dt=duration / steps,
                   t1=duration, saveat=np.linspace(0.0, duration, saves + 1))
    p, g = jax.vmap(lambda q: kinematics.midplane(wrist, q))(sol.qs[1:])
    track = jnp.mean(((p - plunge) / wrist.link_length) ** 2 + jnp.sum((g - slope) ** 2, axis=1))
    tau = jax.vmap(lambda t, q, u: law(wrist, t, q, u))(sol.ts, sol.qs, sol.us)
    work = jnp.mean(jnp.sum(tau**2, axis=1)) / law.limit**2
    cost = (track / pose_tolerance**2 + jnp.sum(sol.us[-1] ** 2) / speed_tolerance**2
            + effort_weight * work)
    final = kinematics.pose_error(wrist, kinematics.forward_kinematics(wrist, sol.qs[-1]),
                                  kinematics.pose_from_chart(wrist, plunge, slope))
    return cost, final


@eqx.filter_jit
def train_controller(controller: NeuralController, wrist, episodes: Episodes, *, iterations: int = 300,
                     learning_rate: float = 3e-3, duration: float = 0.6, steps: int = 60, saves: int = 12,
                     pose_tolerance: float = 0.02, speed_tolerance: float = 1.0,
                     effort_weight: float = 0.1):
    """(trained controller, loss per iteration): Adam on the batch-mean episode cost."""
    trainable = jax.tree.map(lambda _: False, controller)          # only the network's weights
    trainable = eqx.tree_at(lambda c: c.mlp, trainable, jax.tree.map(eqx.is_inexact_array, controller.mlp))
    params, static = eqx.partition(controller, trainable)
    cost_kw = dict(duration=duration, steps=steps, saves=saves, pose_tolerance=pose_tolerance,
                   speed_tolerance=speed_tolerance, effort_weight=effort_weight)

    def loss(p):
        c = eqx.combine(p, static)
        costs, _ = jax.vmap(lambda s, t, pl, g: episode_cost(c, wrist, s, t, pl, g, **cost_kw))(
            episodes.start, episodes.target, episodes.target_plunge, episodes.target_slope)
        return jnp.mean(costs)

    optimizer = optax.adam(optax.cosine_decay_schedule(learning_rate, iterations, alpha=0.05))

    def descend(carry, _):
        p, state = carry
        value, grad = jax.value_and_grad(loss)(p)
        updates, state = optimizer.update(grad, state, p)
        return (optax.apply_updates(p, updates), state), value

    (params, _), losses = jax.lax.scan(descend, (params, optimizer.init(params)), None, length=iterations)
    return eqx.combine(params, static), losses


@eqx.filter_jit
def evaluate_controller(controller: NeuralController, wrist, episodes: Episodes, *, duration: float = 0.6,
                        steps: int = 60, success_tolerance: float = 0.02) -> tuple[Array, Array]:
    """(final pose errors, success rate) over `episodes` (held-out targets)."""
    def one(s, t, pl, g):
        return episode_cost(controller, wrist, s, t, pl, g, duration=duration, steps=steps, saves=1,
                            pose_tolerance=1.0, speed_tolerance=1.0, effort_weight=0.0)[1]
    errors = jax.vmap(one)(episodes.start, episodes.target, episodes.target_plunge, episodes.target_slope)
    return errors, jnp.mean(errors < success_tolerance)
