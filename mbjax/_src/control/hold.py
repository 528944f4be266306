"""Sampled controls: a value per step, held over the step (MuJoCo's `ctrl`, a digital controller).

`simulate` calls `hold` at the start of every step, so a sampled control gives every stage of the
step (RK4's four, an implicit step's Newton iterations) the value of the step's start. A function
of time alone cannot do this: a step's last stage falls on the next sample's time.
"""

import math

import equinox as eqx
import jax.numpy as jnp
from jax import Array

from mbjax._src.control.base import AbstractControl, Constant, as_control

# Times within this fraction of a step of a sample time count as on it (the step grid t0 + k dt
# is computed in floating point).
_GRID_TOLERANCE = 1e-6


def _number(x, name: str) -> float:
    """A finite real number, or an error naming ZeroOrderHold's argument."""
    try:
        value = float(x)
    except (TypeError, ValueError) as error:
        raise TypeError(f"ZeroOrderHold's {name} must be a real number, got {x!r:.60}") from error
    if not math.isfinite(value):
        raise ValueError(f"ZeroOrderHold's {name} must be finite, got {value}")
    return value


class ZeroOrderHold(AbstractControl):
    """A control history on a step grid: tau(t) = values[k] on [t0 + k dt, t0 + (k + 1) dt).

    values[0] holds before t0 and values[-1] after the last interval. Inside `simulate`, every
    stage of a step sees the value of the step's start (`hold`). The values are a
    differentiable leaf.

    Args:
        values (Array): the samples, shape (K, m) (a 1-D history of K samples is taken as (K, 1)); a
            history of wrenches for `external=` is (K, n_bodies, 6).
        dt: the sample interval [s], positive (normally the simulation's step).
        t0: the time [s] of the first sample, values[0].

    Raises:
        ValueError: values is empty or dt is not positive.
    """

    values: Array
    dt: float = eqx.field(static=True)
    t0: float = eqx.field(static=True)

    def __init__(self, values, dt: float, t0: float = 0.0):
        values = jnp.asarray(values, dtype=float)
        if values.ndim == 1:
            values = values[:, None]
        if values.ndim < 2 or values.shape[0] < 1:
            raise ValueError(f"values must be K >= 1 samples, shape (K,) or (K, ...), got shape "
                             f"{values.shape}")
        dt, t0 = _number(dt, "dt"), _number(t0, "t0")
        if not dt > 0:
            raise ValueError(f"dt must be positive, got {dt}")
        self.values = values
        self.dt = float(dt)
        self.t0 = float(t0)

    def index(self, t: Array) -> Array:
        """The sample index in effect at time t.

        Args:
            t: time [s], a scalar.

        Returns:
            k, clipped to 0 ... K - 1 (int32); times within 1e-6 of a step of a sample time
                count as on it.
        """
        k = jnp.floor((t - self.t0) / self.dt + _GRID_TOLERANCE)
        return jnp.clip(k, 0, self.values.shape[0] - 1).astype(jnp.int32)

    def __call__(self, t, q, v):
        return self.values[self.index(t)]

    def hold(self, t, q, v):
        return Constant(self(t, q, v))


class SampleAndHold(AbstractControl):
    """Any control sampled at the start of each step of `simulate` and held over it.

    A feedback law run at the simulation rate, as MuJoCo applies `ctrl`. Called directly, it is
    the law itself.

    Args:
        control (AbstractControl | Callable | Array): the law to sample (an `AbstractControl`, a
            callable (t, q, v) -> tau or a constant array).
    """

    control: AbstractControl

    def __init__(self, control):
        self.control = as_control(control)

    def __call__(self, t, q, v):
        return self.control(t, q, v)

    def hold(self, t, q, v):
        return Constant(self.control(t, q, v))
