"""Feedback laws: a PD servo and an MLP policy."""

import equinox as eqx
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.control.base import AbstractControl, checked_limit, saturate


def _index(index, name: str):
    """Coordinate indices as a tuple of ints; an error naming `name` for any that is not a
    whole number (a fraction would be truncated and servo another coordinate)."""
    if index is None:
        return None
    values = np.atleast_1d(np.asarray(index))
    if values.dtype == bool or not (np.issubdtype(values.dtype, np.integer) or (
            np.issubdtype(values.dtype, np.floating) and np.all(values == np.round(values)))):
        raise ValueError(f"PD's {name} must be whole coordinate indices, got {index!r}")
    return tuple(int(i) for i in values)


class PD(AbstractControl):
    """A PD servo: tau = kp (q_ref - q[q_index]) + kd (v_ref - v[v_index]) + feedforward.

    Every array is a differentiable leaf; gains and targets may be scalars or one per servoed
    coordinate, and the gains also matrices: `kp = w**2 * M`, `kd = 2 * w * M` with the mass
    matrix M at q_ref puts every mode of the linearized arm at w rad/s, critically damped, where
    gains scaled by M's diagonal alone can leave a stiff, fast mode that an explicit step does
    not resolve.

    Args:
        kp (float | Array): stiffness, a scalar, shape (m,) or a matrix (m, m) [N m / rad or N / m].
        kd (float | Array): damping, a scalar, shape (m,) or a matrix (m, m)
            [N m s / rad or N s / m].
        q_ref (float | Array): target configuration of the servoed coordinates, a scalar or shape
            (m,).
        v_ref (float | Array): target velocity, a scalar or shape (m,); 0 by default.
        feedforward (float | Array): force added to the feedback (a gravity torque, say), a scalar
            or shape (m,); 0 by default.
        q_index (Sequence[int] | None): the configuration coordinates the servo acts on, m indices;
            None (default) for all of them. They differ from v_index where a joint's configuration
            and velocity coordinates do (after a floating base's 7 and 6).
        v_index (Sequence[int] | None): the velocity coordinates the servo acts on, m indices; given
            together with q_index.

    Raises:
        ValueError: only one of q_index and v_index is given, or they differ in length; when
            called, an index outside the state, a gain or target neither a scalar nor one per
            servoed coordinate, or no indices where nq != nv.
    """

    kp: Array
    kd: Array
    q_ref: Array
    v_ref: Array
    feedforward: Array
    q_index: tuple | None = eqx.field(static=True)
    v_index: tuple | None = eqx.field(static=True)

    def __init__(self, kp, kd, q_ref, v_ref=0.0, feedforward=0.0, *, q_index=None, v_index=None):
        self.kp, self.kd, self.q_ref, self.v_ref, self.feedforward = (
            jnp.asarray(x, dtype=float) for x in (kp, kd, q_ref, v_ref, feedforward))
        self.q_index, self.v_index = _index(q_index, "q_index"), _index(v_index, "v_index")
        if (self.q_index is None) != (self.v_index is None) or (
                self.q_index is not None and len(self.q_index) != len(self.v_index)):
            raise ValueError("q_index and v_index must both be given, with one entry per servoed "
                             f"coordinate; got {self.q_index} and {self.v_index}")

    def __call__(self, t, q, v):
        self._check(q.shape[0], v.shape[0])
        if self.q_index is not None:
            q, v = q[jnp.array(self.q_index)], v[jnp.array(self.v_index)]
        return _gain(self.kp, self.q_ref - q) + _gain(self.kd, self.v_ref - v) + self.feedforward

    def _check(self, nq: int, nv: int) -> None:
        """Indices within the state (a gather would clamp them, servoing another coordinate)
        and every gain and target a scalar or one per servoed coordinate."""
        if self.q_index is None:
            if nq != nv:
                raise ValueError(f"PD without q_index and v_index servoes every coordinate, which "
                                 f"needs nq == nv; this system has nq = {nq}, nv = {nv} (a "
                                 "floating base?): give q_index and v_index")
            m = nq
        else:
            for name, index, n in (("q_index", self.q_index, nq), ("v_index", self.v_index, nv)):
                outside = [i for i in index if not -n <= i < n]
                if outside:
                    raise ValueError(f"PD's {name} {outside} out of range for a state of {n} "
                                     f"coordinates (valid: 0 ... {n - 1})")
            m = len(self.q_index)
        for name in ("kp", "kd", "q_ref", "v_ref", "feedforward"):
            shape = getattr(self, name).shape
            matrix = name in ("kp", "kd") and shape == (m, m)
            if shape not in ((), (1,), (m,)) and not matrix:
                kinds = f"({m},) or ({m}, {m})" if name in ("kp", "kd") else f"({m},)"
                raise ValueError(f"PD's {name} must be a scalar or have shape {kinds}, one per "
                                 f"servoed coordinate, got shape {shape}")


def _gain(k: Array, error: Array) -> Array:
    """A gain times an error: a matrix gain multiplies, a scalar or per-coordinate one scales."""
    return k @ error if k.ndim == 2 else k * error


class MLPPolicy(AbstractControl):
    """A neural-network policy: tau = scale MLP(q, v), saturated at `limit` if given.

    The output layer starts at zero, so the untrained policy is no control at all and can be
    added to a servo (`PD(...) + MLPPolicy(...)`) without disturbing it. The network's weights
    are the trainable leaves.

    Args:
        n_in: the network's inputs, nq + nv of the system (time is added by `time=True`).
        n_out: its outputs, the number of actuated coordinates.
        key (Array): a `jax.random` key for the hidden layers' initialization.
        width: hidden layer width.
        depth: number of hidden layers.
        scale (float): factor on the network's output, in the control's units (N m).
        limit (float | Array | None): saturation level, limit tanh(tau / limit), a scalar or shape
            (n_out,); None for none.
        time: whether the network also takes t as its first input.
        activation (Callable): the hidden layers' activation function.

    Raises:
        ValueError: when called on a state whose size does not match n_in.
    """

    mlp: eqx.nn.MLP
    scale: Array
    limit: Array | None
    time: bool = eqx.field(static=True)

    def __init__(self, n_in: int, n_out: int, *, key, width: int = 32, depth: int = 2, scale=1.0,
                 limit=None, time: bool = False, activation=jnp.tanh):
        for name, value, least in (("n_in", n_in, 1), ("n_out", n_out, 1), ("width", width, 1),
                                   ("depth", depth, 0)):
            if not (isinstance(value, int | np.integer) and not isinstance(value, bool)
                    and value >= least):
                raise ValueError(f"MLPPolicy's {name} must be an int >= {least}, got {value!r}")
        mlp = eqx.nn.MLP(n_in + int(time), n_out, width, depth, activation=activation, key=key)
        last = mlp.layers[-1]
        self.mlp = eqx.tree_at(lambda m: (m.layers[-1].weight, m.layers[-1].bias), mlp,
                               (jnp.zeros_like(last.weight), jnp.zeros_like(last.bias)))
        self.scale = jnp.asarray(scale, dtype=float)
        self.limit = checked_limit(limit, "MLPPolicy")
        self.time = time

    def __call__(self, t, q, v):
        x = jnp.concatenate([jnp.atleast_1d(jnp.asarray(t, q.dtype))[:int(self.time)], q, v])
        if x.shape[0] != self.mlp.in_size:
            raise ValueError(f"MLPPolicy takes {self.mlp.in_size} inputs ((t,) q, v), got "
                             f"{x.shape[0]}: build it with n_in = nq + nv of the system")
        return saturate(self.scale * self.mlp(x), self.limit)
