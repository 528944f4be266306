"""The Carpal Wrist as a system for `simulate` (Canfield 1997 §6.4)."""

import jax.numpy as jnp
from jax import Array

from mbjax._src.control import AbstractControl
from mbjax._src.system.driven import AbstractDrivenSystem, drive
from mbjax._src.system.invariants import energy_invariant
from mbjax._src.system.status import Status
from mbjax._src.wrist import dynamics, kinematics
from mbjax._src.wrist.model import CarpalWrist


# how close (in `kinematics.singularity_measures`' inverse and direct measures, 1 far away) a
# saved state may come to a singularity before `simulate` reports SINGULAR
SINGULAR_TOLERANCE = 1e-3


class WristSystem(AbstractDrivenSystem):
    """The Carpal Wrist as a system for `mbjax.simulate` (Canfield 1997 §6.4): q = theta,
    u = theta_dot, each shape (3,); theta_ddot from eq 6.21 under the motor torques and an
    external wrench on the tool. With `ExplicitEuler` this is the chapter's eq 6.45.

    Args:
        model: the wrist, a `CarpalWrist`.
        control (Callable | Array | None): the motor torques [N m], a callable (t, theta, theta_dot)
            -> shape (3,) (or (n_controls,) with `actuation`): a `mbjax.control` module such as a
            torque spline or a servo (`mbjax.wrist.servo`), a controller from `mbjax.trajopt`, any
            callable, or a constant array; None: unpowered motors.
        external (Callable | None): a callable (t, theta, theta_dot) -> a world-frame wrench (torque
            [N m]; force [N]) on the tool, shape (1, 6), its force acting at the distal-plate centre
            or at `external_point`; or None.
        external_point (Array | None): where the external force acts, in the tool frame D [m], shape
            (1, 3) or (3,); None: the distal-plate centre.
        actuation (Array | None): the indices of the driven motors (or a boolean mask of length 3,
            or a (3, nu) actuation matrix); None: all three. Stored as the matrix.

    Raises:
        TypeError: `model` is not a `CarpalWrist`.
        ValueError: malformed control, external, external_point or actuation.
    """

    model: CarpalWrist
    control: AbstractControl | None
    external: AbstractControl | None
    external_point: Array | None
    actuation: Array | None

    def __init__(self, model: CarpalWrist, control=None, *, external=None, external_point=None,
                 actuation=None):
        if not isinstance(model, CarpalWrist):
            raise TypeError(f"model must be a CarpalWrist, got {type(model).__name__}")
        self.model = model
        self.control, self.external, self.external_point, self.actuation = drive(
            control, external, external_point, actuation, nv=3, n=1)

    @property
    def n(self) -> int:
        """One body, the tool (distal plate)."""
        return 1

    @property
    def nv(self) -> int:
        """The three motor angles' rates."""
        return 3

    def state_sizes(self):
        return 3, 3

    def torques(self, t: Array, q: Array, u: Array) -> Array:
        """The motor torques of the control plus the torques equivalent to the external wrench.

        Args:
            t: time [s], a scalar.
            q: input angles theta [rad], shape (3,).
            u: their rates [rad/s], shape (3,).

        Returns:
            tau [N m], shape (3,).
        """
        tau = self.applied(t, q, u)
        f = self.external_wrenches(t, q, u)
        if f is None:
            return tau
        point = None if self.external_point is None else self.external_point[0]
        return tau + dynamics.external_torques(self.model, q, f[0], point)

    def kinematics(self, q: Array, u: Array) -> Array:
        return u

    def acceleration(self, t: Array, q: Array, u: Array) -> Array:
        return dynamics.forward_dynamics(self.model, q, u, self.torques(t, q, u))

    def check(self, t: Array, q: Array, u: Array) -> Array:
        """`Status.SINGULAR` where the wrist is within SINGULAR_TOLERANCE of an inverse or a
        direct singularity (`kinematics.singularity_measures`): there the accelerations of
        eq 6.21 are not defined (A of eq 6.16 is singular, and they grow without bound on the
        way; see benchmarks/README.md).

        Returns:
            An int32 scalar of `Status` flags.
        """
        m = kinematics.singularity_measures(self.model, q)
        near = jnp.minimum(jnp.abs(m.inverse), jnp.abs(m.direct)) < SINGULAR_TOLERANCE
        return jnp.where(near, int(Status.SINGULAR), 0).astype(jnp.int32)

    def culprit(self, t: Array, q: Array, u: Array) -> Array:
        """0 where the inverse singularity is the nearer, 1 the direct."""
        m = kinematics.singularity_measures(self.model, q)
        return jnp.where(jnp.abs(m.inverse) <= jnp.abs(m.direct), 0, 1).astype(jnp.int32)

    def culprit_names(self) -> tuple[str, ...]:
        """The two singularities."""
        return ("an inverse singularity", "a direct singularity")

    def energy(self, q: Array, u: Array) -> Array:
        """T + V of the tool [J], a scalar; the work of the motors and the external wrench is not
        included."""
        return dynamics.energy(self.model, q, u)

    def invariants(self, t, q, u):
        """The tool's energy with unpowered motors and no external wrench; None otherwise."""
        if not self.passive:
            return None
        return energy_invariant(dynamics.energy(self.model, q, u),
                                dynamics.kinetic_energy(self.model, q, u), False)

