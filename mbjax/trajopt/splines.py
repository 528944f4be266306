"""Motor-torque histories as uniform cubic B-splines, saturated at the motors' torque limit."""

import equinox as eqx
import jax
import jax.numpy as jnp
from jax import Array


def bspline_basis(t: Array, duration: float, n_knots: int) -> Array:
    """Weights (n_knots,) of the uniform cubic B-spline with n_knots control points spanning
    [0, duration] (n_knots - 3 segments), at time t (clamped into [0, duration])."""
    n_seg = n_knots - 3
    s = jnp.clip(t / duration, 0.0, 1.0) * n_seg
    i = jnp.clip(jnp.floor(s), 0, n_seg - 1)
    u = s - i
    w = jnp.stack([(1 - u) ** 3, 3 * u**3 - 6 * u**2 + 4, -3 * u**3 + 3 * u**2 + 3 * u + 1, u**3]) / 6
    idx = i.astype(jnp.int32) + jnp.arange(4)
    return jnp.zeros(n_knots, w.dtype).at[idx].add(w)


class TorqueSpline(eqx.Module):
    """tau(t) = limit tanh(s(t) / limit), s a cubic B-spline with control values `knots`
    (n_knots, 3) over [0, duration]: smooth, and inside +-limit by construction, so gradient
    descent on the knots never needs a constraint."""

    knots: Array
    limit: Array
    duration: float = eqx.field(static=True)

    def unsaturated(self, t: Array) -> Array:
        return bspline_basis(t, self.duration, self.knots.shape[0]) @ self.knots

    def __call__(self, wrist, t: Array, theta: Array, theta_dot: Array) -> Array:
        return self.limit * jnp.tanh(self.unsaturated(t) / self.limit)

    @classmethod
    def fit(cls, ts: Array, torques: Array, n_knots: int, duration: float, limit: float) -> "TorqueSpline":
        """The least-squares spline through torque samples (ts, torques (len(ts), 3)), which
        must lie inside +-limit."""
        torques = jnp.asarray(torques, dtype=float)
        s = limit * jnp.arctanh(jnp.clip(torques / limit, -0.999, 0.999))
        basis = jax.vmap(lambda t: bspline_basis(t, duration, n_knots))(jnp.asarray(ts, dtype=float))
        knots = jnp.linalg.lstsq(basis, s)[0]
        return cls(knots=knots, limit=jnp.asarray(limit, dtype=float), duration=duration)

    @classmethod
    def constant(cls, torque: Array, n_knots: int, duration: float, limit: float) -> "TorqueSpline":
        """The spline holding `torque` (|torque| < limit) for the whole duration."""
        torque = jnp.asarray(torque, dtype=float)
        s = limit * jnp.arctanh(torque / limit)
        return cls(knots=jnp.tile(s, (n_knots, 1)), limit=jnp.asarray(limit, dtype=float),
                   duration=duration)
