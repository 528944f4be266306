"""What every driven system shares: a control on its actuated velocity coordinates and external
wrenches on its bodies, with their checks written once.

A control returns one force per actuator. `actuation` says where they act: on the velocity
coordinates it lists (indices, all of them by default), or through an (nv, nu) actuation matrix S
whose columns are each actuator's generalized force per unit control, tau = S u (thrusters on a
floating base, tendons, differential drives; Crocoddyl's `ActuationModelAbstract` with a constant
d tau / d u). An external load returns one world-frame wrench (torque; force) per body,
shape (n, 6), acting at the body's origin, or at a point fixed in the body (`external_point`,
body-frame coordinates, shape (n, 3)).
"""

import abc

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.control.base import AbstractControl, as_control
from mbjax._src.system.system import AbstractSystem


class AbstractDrivenSystem(AbstractSystem):
    """A system driven by `control` (t, q, v) -> forces on its `actuation` coordinates and by
    `external` (t, q, v) -> (n, 6) world-frame wrenches on its n bodies, at their origins or at
    `external_point` (n, 3). Final systems declare the four fields and set them in `__init__`
    with `drive(...)`."""

    control: eqx.AbstractVar[AbstractControl | None]
    external: eqx.AbstractVar[AbstractControl | None]
    external_point: eqx.AbstractVar[Array | None]
    actuation: eqx.AbstractVar[Array | None]

    @property
    @abc.abstractmethod
    def nv(self) -> int:
        """Number of velocity coordinates (what the control's forces act on)."""

    @property
    @abc.abstractmethod
    def n(self) -> int:
        """Number of bodies (what the external wrenches act on)."""

    @property
    def passive(self) -> bool:
        """No control and no external load: the energy is conserved (or falls, with damping)."""
        return self.control is None and self.external is None

    @property
    def n_controls(self) -> int:
        """The number of forces the control returns: the actuation matrix's columns, or nv if
        all coordinates are actuated."""
        return self.nv if self.actuation is None else self.actuation.shape[1]

    def with_control(self, control) -> "AbstractDrivenSystem":
        """The system driven by `control` instead of its own (what trajectory optimisation varies).

        Args:
            control: a callable (t, q, v) -> forces, shape (n_controls,); an
                `mbjax.control` module; a constant array; or None (no control).

        Returns:
            A copy of the system with the new control; the actuation is unchanged.
        """
        return eqx.tree_at(lambda s: s.control, self, as_control(control),
                           is_leaf=lambda x: x is None)

    def applied(self, t: Array, q: Array, v: Array) -> Array:
        """The control's forces on all nv velocity coordinates (zero where unactuated).

        Args:
            t: time [s], a scalar.
            q: configuration, shape (nq,).
            v: velocity, shape (nv,).

        Returns:
            Generalized forces, shape (nv,).

        Raises:
            ValueError: the control returned a shape other than (n_controls,).
            TypeError: the control returned complex or non-numeric forces.
        """
        if self.control is None:
            return jnp.zeros(self.nv, v.dtype)
        tau = jnp.asarray(self.control(t, q, v))
        if jnp.iscomplexobj(tau) or not jnp.issubdtype(tau.dtype, jnp.number):
            raise TypeError(f"the control returned {tau.dtype} forces; they must be real")
        tau = tau.astype(v.dtype)
        if tau.shape != (self.n_controls,):
            raise ValueError(f"the control returned shape {tau.shape}; this system expects "
                             f"({self.n_controls},): " + (
                                 "one force per velocity coordinate" if self.actuation is None
                                 else "one per actuator (column of the actuation matrix)"))
        return tau if self.actuation is None else self.actuation @ tau

    def external_wrenches(self, t: Array, q: Array, v: Array) -> Array | None:
        """The external wrenches as `external` returns them, checked.

        Args:
            t: time [s], a scalar.
            q: configuration, shape (nq,).
            v: velocity, shape (nv,).

        Returns:
            World-frame wrenches (torque [N m]; force [N]), shape (n, 6), acting at the bodies'
            origins or at `external_point`; None without an external load.

        Raises:
            ValueError: `external` returned a shape other than (n, 6).
        """
        if self.external is None:
            return None
        f = jnp.asarray(self.external(t, q, v), v.dtype)
        if f.shape != (self.n, 6):
            raise ValueError(f"external returned shape {f.shape}; it must return one world-frame "
                             f"wrench (torque; force) per body, shape ({self.n}, 6)")
        return f

    def hold(self, t, q, u):
        """The system with its control and external load as they are over one step from (t, q, u)
        (sampled controls frozen); the velocity v is u unless the system says otherwise."""
        return held(self, t, q, u)


def held(system: AbstractDrivenSystem, t: Array, q: Array, v: Array) -> AbstractDrivenSystem:
    """`system` with its control and external loads as they are over one step from (t, q, v)."""
    if system.passive:
        return system
    new = tuple(None if c is None else c.hold(t, q, v) for c in (system.control, system.external))
    return eqx.tree_at(lambda s: (s.control, s.external), system, new, is_leaf=lambda x: x is None)


def drive(control, external, external_point, actuation, *, nv: int, n: int) -> tuple:
    """The four driven-system fields checked, for a system of nv velocity coordinates and n bodies.

    Args:
        control: a callable (t, q, v) -> forces, an `AbstractControl`, a constant array (one
            entry per actuated coordinate) or None.
        external: a callable (t, q, v) -> (n, 6) world-frame wrenches, or None.
        external_point: body-frame points where the external forces act, shape (n, 3) or (3,)
            (the same point for every body), or None (the bodies' origins).
        actuation: indices of the actuated velocity coordinates, a boolean mask of length nv,
            an (nv, nu) actuation matrix of rank nu (generalized force S u), or None (all
            coordinates).
        nv: the system's number of velocity coordinates.
        n: the system's number of bodies.

    Returns:
        (control, external, external_point, actuation), as the system stores them: the
        actuation as its (nv, nu) matrix (the identity's columns for indices), or None.

    Raises:
        TypeError, ValueError: naming the argument that is malformed.
    """
    actuation = check_actuation(actuation, nv)
    control = as_control(control)
    n_act = nv if actuation is None else actuation.shape[1]
    value = getattr(control, "value", None)
    if value is not None and value.shape != (n_act,):
        raise ValueError(f"the constant control (tau) must have shape ({n_act},), got {value.shape}")
    return control, as_control(external), check_points(external_point, n), actuation


def check_actuation(actuation, nv: int) -> Array | None:
    """The (nv, nu) actuation matrix: given, checked to be of full column rank, or the columns
    of the identity at the actuated velocity coordinates (distinct indices, in the order of the
    control's outputs, or a boolean mask); None where all coordinates are actuated."""
    if actuation is None:
        return None
    if isinstance(actuation, jax.core.Tracer) or (np.ndim(actuation) == 2):
        return _actuation_matrix(actuation, nv)
    index = np.atleast_1d(np.asarray(actuation))
    if index.dtype == bool:
        if index.shape != (nv,):
            raise ValueError(f"actuation as a mask must have {nv} entries, got {index.shape}")
        index = np.flatnonzero(index)
    if not np.issubdtype(index.dtype, np.integer) or index.ndim != 1:
        raise TypeError(f"actuation must be velocity-coordinate indices (ints), a boolean mask or "
                        f"an (nv, nu) actuation matrix, got {actuation!r}")
    if len(set(index.tolist())) != len(index) or np.any(index < 0) or np.any(index >= nv):
        raise ValueError(f"actuation must be distinct indices in 0 ... {nv - 1}, got {index.tolist()}")
    return jnp.asarray(np.eye(nv)[:, index])


def _actuation_matrix(S, nv: int) -> Array:
    """An (nv, nu) actuation matrix, checked where concrete: real, finite, of rank nu."""
    S = jnp.asarray(S, dtype=float)
    if S.ndim != 2 or S.shape[0] != nv or S.shape[1] < 1:
        raise ValueError(f"actuation as a matrix must have shape (nv, nu) = ({nv}, nu) with "
                         f"nu >= 1, got {S.shape}")
    if not isinstance(S, jax.core.Tracer):
        values = np.asarray(S)
        if not np.isfinite(values).all():
            raise ValueError("actuation matrix must be finite")
        rank = np.linalg.matrix_rank(values)
        if rank < S.shape[1]:
            raise ValueError(f"actuation matrix has rank {rank} < nu = {S.shape[1]}: some "
                             "controls act alike (or not at all); give independent columns")
    return S


def check_points(point, n: int) -> Array | None:
    """Body-frame points, one per body, shape (n, 3) (a single (3,) point broadcast), or None."""
    if point is None:
        return None
    point = jnp.asarray(point, dtype=float)
    point = jnp.broadcast_to(point, (n, 3)) if point.shape == (3,) else point
    if point.shape != (n, 3):
        raise ValueError(f"external_point must be one body-frame point per body, shape ({n}, 3), "
                         f"got {point.shape}")
    return point


def about_origins(f: Array, R: Array, point: Array | None) -> Array:
    """Wrenches whose forces act at body-fixed points (n, 3), moved to the bodies' origins:
    torque + (R point) x force, with R (n, 3, 3) the bodies' rotations."""
    if point is None:
        return f
    arm = jnp.einsum("kij,kj->ki", R, point)
    return f.at[:, :3].add(jnp.cross(arm, f[:, 3:]))
