"""Control histories as uniform cubic B-splines, optionally saturated at a limit."""

import equinox as eqx
import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.control.base import AbstractControl, checked_limit, saturate


def bspline_basis(t: Array, duration: float, n_knots: int, t0: float = 0.0) -> Array:
    """The weights of a uniform cubic B-spline's control points at time t.

    Args:
        t: time [s], a scalar; clamped into [t0, t0 + duration].
        duration: the span of the spline [s], n_knots - 3 segments.
        n_knots: the number of control points, at least 4.
        t0: the start of the span [s].

    Returns:
        The weights, shape (n_knots,): s(t) = weights @ knots.
    """
    n_seg = n_knots - 3
    s = jnp.clip((t - t0) / duration, 0.0, 1.0) * n_seg
    i = jnp.clip(jnp.floor(s), 0, n_seg - 1)
    u = s - i
    w = jnp.stack([(1 - u) ** 3, 3 * u**3 - 6 * u**2 + 4, -3 * u**3 + 3 * u**2 + 3 * u + 1, u**3]) / 6
    idx = i.astype(jnp.int32) + jnp.arange(4)
    return jnp.zeros(n_knots, w.dtype).at[idx].add(w)


class CubicSpline(AbstractControl):
    """A control history as a uniform cubic B-spline in time, optionally saturated.

    tau(t) = s(t) over [t0, t0 + duration] (constant outside), or limit tanh(s(t) / limit) when
    `limit` is given: smooth, and inside +-limit by construction, so gradient descent on the
    knots needs no constraint. C2 in time; the knots are the spline's control points, not
    values it passes through (`fit` finds the knots of given samples). It ignores the state.

    Args:
        knots (Array): the control points, shape (n_knots, m), n_knots >= 4 (a 1-D array is taken as
            (n_knots, 1)); a differentiable leaf.
        duration: the span of the spline [s], positive.
        limit (float | Array | None): saturation level, a scalar or shape (m,), in the control's
            units; None for none.
        t0: the start of the span [s].

    Raises:
        ValueError: knots has fewer than 4 rows or more than 2 dimensions, or duration is not
            positive.
    """

    knots: Array
    limit: Array | None
    duration: float = eqx.field(static=True)
    t0: float = eqx.field(static=True)

    def __init__(self, knots, duration: float, limit=None, t0: float = 0.0):
        knots = jnp.asarray(knots, dtype=float)
        if knots.ndim == 1:
            knots = knots[:, None]
        if knots.ndim != 2 or knots.shape[0] < 4:
            raise ValueError(f"knots must be (n_knots >= 4, m), got shape {knots.shape}")
        if not float(duration) > 0:
            raise ValueError(f"duration must be positive, got {duration}")
        self.knots = knots
        self.limit = checked_limit(limit, "CubicSpline")
        self.duration = float(duration)
        self.t0 = float(t0)

    def unsaturated(self, t: Array) -> Array:
        """The spline s(t) before saturation.

        Args:
            t: time [s], a scalar.

        Returns:
            s(t), shape (m,).
        """
        return bspline_basis(t, self.duration, self.knots.shape[0], self.t0) @ self.knots

    def __call__(self, t, q=None, v=None):
        return saturate(self.unsaturated(t), self.limit)

    @classmethod
    def fit(cls, ts, values, n_knots: int, duration: float, limit=None, t0: float = 0.0) -> "CubicSpline":
        """The least-squares spline through samples of a history.

        Args:
            ts: sample times [s], shape (S,).
            values: samples, shape (S, m); inside +-limit when a limit is given (they are
                mapped through limit artanh(values / limit), clipped at 0.999 of the limit).
            n_knots: the spline's number of control points, at least 4.
            duration: the span of the spline [s].
            limit: saturation level, or None.
            t0: the start of the span [s].

        Returns:
            The `CubicSpline` whose knots fit the samples in the least-squares sense.
        """
        values = jnp.asarray(values, dtype=float)
        if limit is not None:
            values = limit * jnp.arctanh(jnp.clip(values / limit, -0.999, 0.999))
        basis = jax.vmap(lambda t: bspline_basis(t, duration, n_knots, t0))(jnp.asarray(ts, dtype=float))
        return cls(jnp.linalg.lstsq(basis, values)[0], duration, limit, t0)

    @classmethod
    def constant(cls, value, n_knots: int, duration: float, limit=None, t0: float = 0.0) -> "CubicSpline":
        """The spline holding a constant value for the whole duration.

        Args:
            value: the value to hold, a scalar or shape (m,); strictly inside +-limit when a
                limit is given.
            n_knots: the spline's number of control points, at least 4.
            duration: the span of the spline [s].
            limit: saturation level, or None.
            t0: the start of the span [s].

        Returns:
            The `CubicSpline` equal to value on [t0, t0 + duration].
        """
        value = jnp.atleast_1d(jnp.asarray(value, dtype=float))
        limit = checked_limit(limit, "CubicSpline.constant")
        if limit is not None and not isinstance(value, jax.core.Tracer) \
                and bool(jnp.any(jnp.abs(value) >= limit)):
            raise ValueError(f"CubicSpline.constant's value {value} must lie strictly inside "
                             f"+-limit {limit} (the spline saturates there)")
        s = value if limit is None else limit * jnp.arctanh(value / limit)
        return cls(jnp.tile(s, (n_knots, 1)), duration, limit, t0)
