"""Control histories as uniform cubic B-splines, optionally saturated at a limit."""

import equinox as eqx
import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.control.base import AbstractControl, saturate


def bspline_basis(t: Array, duration: float, n_knots: int, t0: float = 0.0) -> Array:
    """Weights (n_knots,) of the uniform cubic B-spline with n_knots control points spanning
    [t0, t0 + duration] (n_knots - 3 segments), at time t (clamped into that interval)."""
    n_seg = n_knots - 3
    s = jnp.clip((t - t0) / duration, 0.0, 1.0) * n_seg
    i = jnp.clip(jnp.floor(s), 0, n_seg - 1)
    u = s - i
    w = jnp.stack([(1 - u) ** 3, 3 * u**3 - 6 * u**2 + 4, -3 * u**3 + 3 * u**2 + 3 * u + 1, u**3]) / 6
    idx = i.astype(jnp.int32) + jnp.arange(4)
    return jnp.zeros(n_knots, w.dtype).at[idx].add(w)


class CubicSpline(AbstractControl):
    """tau(t) = s(t), a uniform cubic B-spline with control values `knots` (n_knots, m) over
    [t0, t0 + duration] (constant outside), or limit tanh(s(t) / limit) when `limit` is given:
    smooth, and inside +-limit by construction, so gradient descent on the knots needs no
    constraint. C2 in time; the knots are the spline's control points, not values it passes
    through (`fit` finds the knots of given samples)."""

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
        self.limit = None if limit is None else jnp.asarray(limit, dtype=float)
        self.duration = float(duration)
        self.t0 = float(t0)

    def unsaturated(self, t: Array) -> Array:
        return bspline_basis(t, self.duration, self.knots.shape[0], self.t0) @ self.knots

    def __call__(self, t, q=None, v=None):
        return saturate(self.unsaturated(t), self.limit)

    @classmethod
    def fit(cls, ts, values, n_knots: int, duration: float, limit=None, t0: float = 0.0) -> "CubicSpline":
        """The least-squares spline through samples (ts, values (len(ts), m)), which must lie
        inside +-limit when a limit is given."""
        values = jnp.asarray(values, dtype=float)
        if limit is not None:
            values = limit * jnp.arctanh(jnp.clip(values / limit, -0.999, 0.999))
        basis = jax.vmap(lambda t: bspline_basis(t, duration, n_knots, t0))(jnp.asarray(ts, dtype=float))
        return cls(jnp.linalg.lstsq(basis, values)[0], duration, limit, t0)

    @classmethod
    def constant(cls, value, n_knots: int, duration: float, limit=None, t0: float = 0.0) -> "CubicSpline":
        """The spline holding `value` (inside +-limit) for the whole duration."""
        value = jnp.atleast_1d(jnp.asarray(value, dtype=float))
        s = value if limit is None else limit * jnp.arctanh(value / limit)
        return cls(jnp.tile(s, (n_knots, 1)), duration, limit, t0)
