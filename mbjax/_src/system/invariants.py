"""The invariants of a system's exact motion, whose drift along a simulation measures its error.

A passive system (no control, no external load, no prescribed motion) conserves its energy, or
with damping can only lose it; a free-floating tree also conserves its angular momentum about
the gravity axis (all of it without gravity) and its linear momentum less the weight's impulse
M g t. `simulate` compares each invariant along the saved states with its value at the start,
relative to a scale of the motion (the largest kinetic energy for the energy, the sum of the
bodies' momentum magnitudes for the momentum: `drifts`), and reports the largest ratio as
`Solution.drift` and `Status.INACCURATE` where it exceeds rtol, or without a tolerance
`DEFAULT_DRIFT_LIMIT`; `solve_tfe` does so by default, against `DRIFT_LIMIT`.
"""

import equinox as eqx
import jax.numpy as jnp
from jax import Array

# the names of a momentum's components, for the status's words
ANGULAR = ("angular momentum x", "angular momentum y", "angular momentum z")
LINEAR = ("linear momentum x", "linear momentum y", "linear momentum z")


class Invariants(eqx.Module):
    """k quantities at one state (batched over a trajectory by `jax.vmap`).

    values: the quantities; scale: the magnitude each drift is measured against (non-negative);
    conserved: where False the quantity is not held to anything (a momentum whose root joint is
    damped); decreasing: where True only a rise counts as drift (the energy of a damped
    system); names: what each quantity is, for the status's words ("energy", "angular
    momentum", ...)."""

    values: Array
    scale: Array
    conserved: Array
    decreasing: Array
    names: tuple[str, ...] | None = eqx.field(static=True, default=None)

    def __check_init__(self):
        if jnp.shape(self.values) != jnp.shape(self.scale):
            raise ValueError(f"values and scale must have one shape, got "
                             f"{jnp.shape(self.values)} and {jnp.shape(self.scale)}")

    def labels(self) -> tuple[str, ...]:
        """The quantities' names, "invariant k" where none was given."""
        n = jnp.shape(self.values)[-1]
        return self.names if self.names is not None else tuple(f"invariant {k}"
                                                               for k in range(n))


def energy_invariant(energy: Array, kinetic: Array, dissipative) -> Invariants:
    """The energy, measured against the kinetic energy; with `dissipative` it may fall."""
    return Invariants(values=jnp.atleast_1d(energy), scale=jnp.atleast_1d(jnp.abs(kinetic)),
                      conserved=jnp.ones(1, bool),
                      decreasing=jnp.atleast_1d(jnp.asarray(dissipative, bool)),
                      names=("energy",))


def along_gravity(H: Array, gravity: Array) -> Array:
    """The conserved part of an angular momentum H about a fixed point under uniform gravity
    (and no other load): its component along gravity, since the weight's moment c x M g is
    normal to g; all of H without gravity."""
    has_gravity = jnp.any(gravity != 0)
    axis = gravity / jnp.where(has_gravity, jnp.linalg.norm(gravity), 1.0)
    return jnp.where(has_gravity, axis * (axis @ H), H)


def join(*parts: Invariants) -> Invariants:
    """Several systems' or several kinds' invariants as one."""
    return Invariants(*(jnp.concatenate([getattr(p, name) for p in parts])
                        for name in ("values", "scale", "conserved", "decreasing")),
                      names=sum((p.labels() for p in parts), ()))


def drifts(history: Invariants) -> Array:
    """|I(t) - I(t_0)| / max_t scale(t) for a trajectory's invariants (leading axis: time),
    shape (T, k); a `decreasing` one counts only its rises, one not `conserved` is 0."""
    change = history.values - history.values[:1]
    change = jnp.where(history.decreasing[0], jnp.maximum(change, 0.0), jnp.abs(change))
    scale = jnp.maximum(jnp.max(history.scale, axis=0), jnp.finfo(change.dtype).eps)
    return jnp.where(history.conserved[0], change / scale, 0.0)
