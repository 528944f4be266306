"""A neural controller for the Carpal Wrist trained through the differentiable simulator (Canfield 1997
§6.1: 'the simulation environment can be used to train a neural network control system').

The controller is a joint PD servo with gravity feed-forward C(theta*) (eq 6.16) plus a small
equinox MLP of (theta - theta*, theta_dot, theta*), the sum saturated at the torque limit;
theta* = inverse kinematics of the target pose. The PD part keeps the open-loop unstable wrist
(an inverted pendulum with massless legs) inside its workspace from the first iteration, so
gradients exist; the network learns what the soft servo lacks (speed, the coupling of the legs,
gravity away from theta*). Training rolls out
a batch of random (start, target) pairs with `simulate` (vmapped), and descends with optax's Adam on
the mean over episodes of log(1 + J) (robust=True; the plain mean of J with robust=False), J the
tracking cost

    J = sum_k (t_k / T)^e |y(t_k) - y*|^2 / (tol^2 sum_k (t_k / T)^e) + |theta_dot(T)|^2 / omega_tol^2
        + w mean_k |tau(t_k)|^2 / limit^2,

y = (p / l, g) the pose in the midplane chart, t_k the saved times, weighted towards the end by
(t_k / T)^e, e = end_power = 2 (the start is far from the target by construction). The logarithm
keeps a few far-off episodes from dominating the mean, which otherwise trades the many near misses
for them (training results in benchmarks/README.md). The gradient is reverse mode through the
rollouts by default (`jax.value_and_grad`:
a few forward passes for the network's hundred-odd weights, where `jax.jacfwd` would carry one
tangent per weight), one jitted `lax.scan` over the iterations. Success on held-out targets: the
final pose within `kinematics.pose_error` < `success_tolerance`.
"""

import equinox as eqx
import jax
import jax.flatten_util
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.control import AbstractControl
from mbjax._src.integrate import RK4, simulate
from mbjax._src.synthesis.descent import AbstractGradient, ReverseMode, adam_descent
from mbjax._src.wrist import WristSystem, kinematics


class NeuralController(AbstractControl):
    """A servo plus a small MLP, saturated at the torque limit, steering the wrist to a target:

        tau = limit tanh((kp (theta* - theta) - kd theta_dot + C(theta*)
                          + limit MLP(theta - theta*, theta_dot / omega_scale,
                                      theta* - theta_centre)) / limit).

    The MLP's output layer starts at zero, so the untrained controller is the servo. Aim it with
    `aimed_at`; train it with `train_controller`. A control for `WristSystem`.

    Args:
        key (Array): a `jax.random` key for the MLP's initial weights.
        limit: the torque limit [N m].
        theta_centre (Array): the workspace's centre in input angles [rad], shape (3,) (also the
            initial target).
        width: the MLP's hidden width.
        depth: the MLP's number of hidden layers.
        kp: proportional gain [N m/rad].
        kd: derivative gain [N m s/rad].
        omega_scale: the scale of theta_dot at the MLP's input [rad/s]; static.
        neural: False leaves the MLP term out: the servo alone, the baseline the training is
            compared with; static.
    """

    mlp: eqx.nn.MLP
    limit: Array
    kp: Array
    kd: Array
    target: Array
    gravity_torque: Array
    theta_centre: Array
    omega_scale: float = eqx.field(static=True, default=5.0)
    neural: bool = eqx.field(static=True, default=True)

    def __init__(self, key, limit: float, theta_centre, width: int = 8, depth: int = 1, kp: float = 8.0,
                 kd: float = 0.4, omega_scale: float = 5.0, neural: bool = True):
        mlp = eqx.nn.MLP(9, 3, width, depth, activation=jnp.tanh, key=key)
        last = mlp.layers[-1]           # zero output layer: the untrained controller is the servo
        self.mlp = eqx.tree_at(lambda m: (m.layers[-1].weight, m.layers[-1].bias), mlp,
                               (jnp.zeros_like(last.weight), jnp.zeros_like(last.bias)))
        self.limit, self.kp, self.kd = (jnp.asarray(x, dtype=float) for x in (limit, kp, kd))
        self.theta_centre = jnp.asarray(theta_centre, dtype=float)
        self.target = self.theta_centre
        self.gravity_torque = jnp.zeros_like(self.theta_centre)
        self.omega_scale = omega_scale
        self.neural = neural

    def aimed_at(self, wrist, target: Array, gravity_torque: Array | None = None) -> "NeuralController":
        """The same controller steering to joint target theta*.

        Args:
            wrist: the `CarpalWrist`.
            target: theta* [rad], shape (3,).
            gravity_torque: C(theta*) [N m], shape (3,); None: computed here.

        Returns:
            The aimed `NeuralController`.
        """
        target = jnp.asarray(target, dtype=float)
        if gravity_torque is None:
            gravity_torque = wrist.eom_terms(target, jnp.zeros_like(target))[2]
        return eqx.tree_at(lambda c: (c.target, c.gravity_torque), self, (target, gravity_torque))

    def __call__(self, t: Array, theta: Array, theta_dot: Array) -> Array:
        tau = self.kp * (self.target - theta) - self.kd * theta_dot + self.gravity_torque
        if self.neural:
            x = jnp.concatenate([theta - self.target, theta_dot / self.omega_scale,
                                 self.target - self.theta_centre])
            tau = tau + self.limit * self.mlp(x)
        return self.limit * jnp.tanh(tau / self.limit)


def sample_poses(key, n: int, plunge_range, max_slope: float) -> tuple[Array, Array]:
    """n poses (plunge, slope) uniform in plunge and in the slope disk |g| <= max_slope."""
    kp, kr, ka = jax.random.split(key, 3)
    plunge = jax.random.uniform(kp, (n,), minval=plunge_range[0], maxval=plunge_range[1])
    radius = max_slope * jnp.sqrt(jax.random.uniform(kr, (n,)))
    angle = jax.random.uniform(ka, (n,), maxval=2 * jnp.pi)
    return plunge, radius[:, None] * jnp.stack([jnp.cos(angle), jnp.sin(angle)], axis=1)


class Episodes(eqx.Module):
    """A batch of k training or evaluation episodes, from `make_episodes`.

    Attributes:
        start: start input angles [rad], shape (k, 3).
        target: target input angles [rad], shape (k, 3).
        target_plunge: the targets' plunge [m], shape (k,).
        target_slope: the targets' slope, shape (k, 2).
        gravity_torque: C(target) [N m], shape (k, 3).
    """

    start: Array
    target: Array
    target_plunge: Array
    target_slope: Array
    gravity_torque: Array


def make_episodes(wrist, key, n: int, plunge_range=(0.068, 0.082), max_slope: float = 0.3) -> Episodes:
    """Random start and target poses in the workspace (knees-out inverse kinematics).

    Poses are uniform in plunge and in the slope disk |g| <= max_slope.

    Args:
        wrist (CarpalWrist): the `CarpalWrist`.
        key (Array): a `jax.random` key.
        n: number of episodes.
        plunge_range (tuple[float, float]): (lowest, highest) plunge [m].
        max_slope: the largest slope |g|.

    Returns:
        The `Episodes`.

    Raises:
        ValueError: a sampled pose is outside the workspace (narrow plunge_range or max_slope).
    """
    k1, k2 = jax.random.split(key)
    ik = jax.jit(jax.vmap(lambda p, g: kinematics.solve_inverse_kinematics(wrist, p, g)))
    (p0, g0), (p1, g1) = sample_poses(k1, n, plunge_range, max_slope), sample_poses(k2, n, plunge_range, max_slope)
    (start, ok0), (target, ok1) = ik(p0, g0), ik(p1, g1)
    if not bool(jnp.all(ok0 & ok1)):
        raise ValueError("sampled poses outside the workspace: narrow plunge_range or max_slope")
    gravity = jax.jit(jax.vmap(lambda q: wrist.eom_terms(q, jnp.zeros_like(q))[2]))(target)
    return Episodes(start=start, target=target, target_plunge=p1, target_slope=g1, gravity_torque=gravity)


def episode_cost(controller, wrist, start, target, plunge, slope, gravity, *, duration, steps, saves,
                 pose_tolerance, speed_tolerance, effort_weight, end_power=2.0):
    """The cost J of one episode and its final pose error (see the module docstring)."""
    law = controller.aimed_at(wrist, target, gravity)
    sol = simulate(WristSystem(wrist, law), RK4(), start, jnp.zeros_like(start), dt=duration / steps,
                   t1=duration, saveat=np.linspace(0.0, duration, saves + 1))
    p, g = jax.vmap(lambda q: kinematics.midplane(wrist, q))(sol.qs[1:])
    weight = (sol.ts[1:] / duration) ** end_power
    miss = ((p - plunge) / wrist.link_length) ** 2 + jnp.sum((g - slope) ** 2, axis=1)
    track = jnp.sum(weight * miss) / jnp.sum(weight)
    tau = jax.vmap(law)(sol.ts, sol.qs, sol.vs)
    work = jnp.mean(jnp.sum(tau**2, axis=1)) / law.limit**2
    cost = (track / pose_tolerance**2 + jnp.sum(sol.vs[-1] ** 2) / speed_tolerance**2
            + effort_weight * work)
    final = kinematics.pose_error(wrist, kinematics.forward_kinematics(wrist, sol.qs[-1]),
                                  kinematics.pose_from_chart(wrist, plunge, slope))
    return cost, final


def _batch(episodes: Episodes):
    return (episodes.start, episodes.target, episodes.target_plunge, episodes.target_slope,
            episodes.gravity_torque)


@eqx.filter_jit
def train_controller(controller: NeuralController, wrist, episodes: Episodes, *, iterations: int = 300,
                     learning_rate: float = 3e-3, duration: float = 0.6, steps: int = 30, saves: int = 10,
                     pose_tolerance: float = 0.02, speed_tolerance: float = 1.0,
                     effort_weight: float = 0.1, gradient: AbstractGradient = ReverseMode(),
                     end_power: float = 2.0, robust: bool = True):
    """Train the controller's MLP through the simulator: Adam on the batch mean of the episode
    cost J (the episode cost in docs/details.md).

    Canfield 1997 §6.1: 'the simulation environment can be used to train a neural network
    control system'. Training rolls out a batch of random (start, target) pairs with `simulate`
    (vmapped), and descends with optax's Adam on the mean over episodes of log(1 + J)
    (robust=True; the plain mean of J with robust=False). The controller's PD part keeps the
    open-loop unstable wrist (an inverted pendulum with massless legs) inside its workspace
    from the first iteration, so gradients exist; the network learns what the soft servo lacks
    (speed, the coupling of the legs, gravity away from theta*).

    Reverse-mode gradients by default (`ReverseMode()`): the network's weights outnumber what
    forward mode (`ForwardMode()`) does cheaply (see `adam_descent` in
    `mbjax/_src/synthesis/descent.py`). The whole descent is one jitted
    `lax.scan`.

    Args:
        controller: the `NeuralController` to train (its MLP's weights vary).
        wrist: the `CarpalWrist`.
        episodes: the training `Episodes`.
        iterations: Adam steps.
        learning_rate: Adam's learning rate.
        duration: each episode's duration T [s].
        steps: RK4 steps per episode.
        saves: saved times per episode that the tracking cost sums over.
        pose_tolerance: tol, the scale of the pose miss.
        speed_tolerance: omega_tol, the scale of the final speed [rad/s].
        effort_weight: w, the weight of the effort term.
        gradient: how the gradient is taken, `ReverseMode()` or `ForwardMode()` (static).
        end_power: e, the weight (t_k / T)^e towards the end.
        robust: descend on the mean of log(1 + J) (True) or of J (False).

    Returns:
        (the trained controller, the loss at each iteration, shape (iterations,)).

    Raises:
        TypeError: gradient is not a gradient strategy (a string, say).

    More on the episode cost: the documentation site's Details page (docs/details.md).
    """
    weights, rebuild = jax.flatten_util.ravel_pytree(eqx.filter(controller.mlp, eqx.is_inexact_array))
    static_mlp = eqx.filter(controller.mlp, eqx.is_inexact_array, inverse=True)
    cost_kw = dict(duration=duration, steps=steps, saves=saves, pose_tolerance=pose_tolerance,
                   speed_tolerance=speed_tolerance, effort_weight=effort_weight, end_power=end_power)

    def with_weights(x):
        return eqx.tree_at(lambda c: c.mlp, controller, eqx.combine(rebuild(x), static_mlp))

    def loss(x):
        c = with_weights(x)
        costs, _ = jax.vmap(lambda *e: episode_cost(c, wrist, *e, **cost_kw))(*_batch(episodes))
        return jnp.mean(jnp.log1p(costs)) if robust else jnp.mean(costs)

    weights, losses = adam_descent(loss, weights, learning_rate=learning_rate, iterations=iterations,
                                   final_fraction=0.05, gradient=gradient)
    return with_weights(weights), losses


@eqx.filter_jit
def evaluate_controller(controller: NeuralController, wrist, episodes: Episodes, *, duration: float = 0.6,
                        steps: int = 30, success_tolerance: float = 0.02) -> tuple[Array, Array]:
    """Run the controller on held-out episodes and score the final poses.

    Args:
        controller: the `NeuralController`.
        wrist: the `CarpalWrist`.
        episodes: the evaluation `Episodes` (k of them).
        duration: each episode's duration [s].
        steps: RK4 steps per episode.
        success_tolerance: the `pose_error` below which an episode succeeds.

    Returns:
        (final pose errors, shape (k,); success rate, the fraction below success_tolerance).
    """
    def one(*e):
        return episode_cost(controller, wrist, *e, duration=duration, steps=steps, saves=1,
                            pose_tolerance=1.0, speed_tolerance=1.0, effort_weight=0.0)[1]
    errors = jax.vmap(one)(*_batch(episodes))
    return errors, jnp.mean(errors < success_tolerance)
