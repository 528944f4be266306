"""The Carpal Wrist as a parameter module (Canfield 1997; geometry in `docs/carpal-wrist-model.md`)."""

import equinox as eqx
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.wrist import dynamics, kinematics, newton_euler

ROTATION_MODELS = ("physical", "chapter")


def _concrete(x) -> bool:
    try:
        np.asarray(x)
        return True
    except Exception:          # a tracer: the constructor runs under jit or vmap
        return False


def _validate(given: dict) -> None:
    """The concrete parameters (NumPy arrays; a wrist built under jit or vmap is not checked)."""
    for name in ("base_radius", "link_length", "tool_mass"):
        if not np.all(given[name] > 0) or not np.all(np.isfinite(given[name])):  # NaN fails > 0
            raise ValueError(f"{name} must be positive and finite, got {given[name]}")
    for name in ("phi0", "gravity", "tool_com", "tool_inertia"):
        if not np.all(np.isfinite(given[name])):
            raise ValueError(f"{name} must be finite, got {given[name]}")
    inertia = given["tool_inertia"]
    if not np.allclose(inertia, np.swapaxes(inertia, -1, -2), rtol=1e-12, atol=1e-15):
        raise ValueError("tool_inertia must be symmetric")
    if np.any(np.linalg.eigvalsh(inertia) <= 0):
        raise ValueError("tool_inertia must be positive definite")


class CarpalWrist(eqx.Module):
    """A Carpal Wrist (Canfield 1997): three legs at azimuths phi0 + (0, 120, 240) deg on a base
    plate, their knees' plane mirroring the base into the distal plate that carries the tool.

    The generalized coordinates are the three input angles theta [rad], shape (3,). Every
    parameter is an array leaf, so wrists can be differentiated, vmapped and swept
    (`mbjax.wrist.grid`, `mbjax.trajopt.sweep`); the checks below run on concrete values only.
    The methods are the closed-form kinematics (§6.2) and the dynamics from the autodiff
    Lagrangian (§6.3); `WristSystem` makes the wrist a system for `mbjax.simulate`.

    Args:
        base_radius (float): radius rb of the base plate [m], positive.
        link_length (float): leg length l from the base axis to the knee [m], positive.
        phi0 (float): azimuth of the first leg [rad].
        tool_mass (float): mass of the rigid tool (distal plate and tool) [kg], positive.
        tool_inertia (Array): inertia of the tool about its centre of mass in the tool frame D
            [kg m^2], shape (3, 3), symmetric positive-definite.
        tool_com (Array): centre-of-mass offset from the distal-plate centre, in D [m], shape (3,).
        gravity (float): gravitational acceleration along -e3 [m/s^2], a scalar.
        rotation_model: "physical" (the mirror plate, R = Rz(alpha) Ry(beta) Rz(-alpha)) or
            "chapter" (Canfield 1997's printed R = Rz(alpha) Ry(beta), eq 6.2, for reproducing
            the chapter's equations only; see `kinematics.rotation_from_slope`); static.

    Raises:
        ValueError: an unknown rotation_model, wrong shapes, or (concrete values) a parameter
            that is not positive or finite, or an inertia that is not symmetric
            positive-definite.
    """

    base_radius: Array
    link_length: Array
    phi0: Array
    tool_mass: Array
    tool_inertia: Array
    tool_com: Array
    gravity: Array
    rotation_model: str = eqx.field(static=True)

    def __init__(self, base_radius, link_length, phi0=0.0, *, tool_mass, tool_inertia,
                 tool_com=(0.0, 0.0, 0.0), gravity=9.81, rotation_model: str = "physical"):
        if rotation_model not in ROTATION_MODELS:
            raise ValueError(f"rotation_model must be one of {ROTATION_MODELS}, got {rotation_model!r}")
        self.base_radius, self.link_length, self.phi0, self.tool_mass, self.gravity = (
            jnp.asarray(x, dtype=float) for x in (base_radius, link_length, phi0, tool_mass, gravity))
        self.tool_inertia = jnp.asarray(tool_inertia, dtype=float)
        self.tool_com = jnp.asarray(tool_com, dtype=float)
        self.rotation_model = rotation_model
        if self.tool_inertia.shape[-2:] != (3, 3) or self.tool_com.shape[-1:] != (3,):
            raise ValueError(f"tool_inertia must be 3x3 and tool_com a 3-vector, got shapes "
                             f"{self.tool_inertia.shape} and {self.tool_com.shape}")
        given = dict(base_radius=base_radius, link_length=link_length, tool_mass=tool_mass,
                     tool_inertia=tool_inertia, phi0=phi0, gravity=gravity, tool_com=tool_com)
        if all(_concrete(x) for x in given.values()):
            _validate({name: np.asarray(x, dtype=float) for name, x in given.items()})

    # -- kinematics (closed form) --------------------------------------------------------------
    def forward_kinematics(self, theta) -> kinematics.Pose:
        """The tool pose for input angles theta, in closed form.

        Args:
            theta: input angles [rad], shape (3,).

        Returns:
            The `Pose` (alpha, beta, plunge, slope, normal, rotation, centre, com).
        """
        return kinematics.forward_kinematics(self, theta)

    def leg_points(self, theta) -> Array:
        """The joints of the three legs, what a picture of the wrist draws.

        Args:
            theta: input angles [rad], shape (3,).

        Returns:
            Shape (3, 3, 3) [m]: [0] the base revolutes, [1] the knees, [2] the distal
                revolutes; then leg, then coordinate.
        """
        return kinematics.leg_points(self, theta)

    def inverse_kinematics(self, alpha, beta, plunge) -> Array:
        """The input angles (knees-out branch) for a tool pose.

        Args:
            alpha: azimuth of the tool axis [rad].
            beta: bend of the tool axis [rad], |beta| < pi.
            plunge: distance from the base centre along e3 to the midplane [m].

        Returns:
            theta [rad], shape (3,).

        Raises:
            equinox.EquinoxRuntimeError: an unreachable pose or one outside the chart (also
                under jit); `solve_inverse_kinematics` returns a flag instead.
        """
        return kinematics.inverse_kinematics(self, alpha, beta, plunge)

    def solve_inverse_kinematics(self, plunge, slope) -> tuple[Array, Array]:
        """The input angles for the midplane chart (plunge, slope); never raises, never NaN.

        Unreachable legs get their nearest boundary angle.

        Args:
            plunge: the midplane's plunge p [m].
            slope: the midplane's slope g, shape (2,) (tan(beta / 2) = |g|).

        Returns:
            (theta [rad], shape (3,); reachable, a boolean scalar).
        """
        return kinematics.solve_inverse_kinematics(self, jnp.asarray(plunge, dtype=float),
                                                   jnp.asarray(slope, dtype=float))

    def jacobian(self, theta) -> Array:
        """J of Canfield 1997 eq 6.34 by autodiff: (N_x, N_y, p)_dot = J theta_dot.

        Args:
            theta: input angles [rad], shape (3,).

        Returns:
            J, shape (3, 3): rows the midplane normal's N_x, N_y and the plunge p.
        """
        return kinematics.jacobian(self, theta)

    def jacobian_closed_form(self, theta) -> Array:
        """J of eq 6.34 in closed form (dN/dg K^-1 D), an independent check of `jacobian`.

        Args:
            theta: input angles [rad], shape (3,).

        Returns:
            J, shape (3, 3).
        """
        return kinematics.jacobian_closed_form(self, theta)

    def singularity_measures(self, theta) -> kinematics.SingularityMeasures:
        """Distances to the inverse and direct singularities (1 far, 0 on them).

        Args:
            theta: input angles [rad], shape (3,).

        Returns:
            `SingularityMeasures` (inverse, direct, condition), scalars.
        """
        return kinematics.singularity_measures(self, theta)

    def reachable(self, alpha, beta, plunge) -> Array:
        """Where a tool pose is in the chart and has a knees-out solution.

        Args:
            alpha: azimuth of the tool axis [rad]; broadcasts with beta and plunge.
            beta: bend of the tool axis [rad].
            plunge: the midplane's plunge [m].

        Returns:
            Booleans of the broadcast shape.
        """
        return kinematics.reachable(self, alpha, beta, plunge)

    # -- dynamics (autodiff Lagrangian) --------------------------------------------------------
    def mass_matrix(self, theta) -> Array:
        """A(theta) of eq 6.16, the Hessian of the kinetic energy in theta_dot.

        Args:
            theta: input angles [rad], shape (3,).

        Returns:
            A, symmetric, shape (3, 3); positive-definite inside the workspace, singular at the
                inverse singularity (the legs are massless).
        """
        return dynamics.mass_matrix(self, theta)

    def eom_terms(self, theta, theta_dot) -> tuple[Array, Array, Array]:
        """(A, B, C) of eq 6.16: tau = A theta_ddot + B + C.

        Args:
            theta: input angles [rad], shape (3,).
            theta_dot: their rates [rad/s], shape (3,).

        Returns:
            (A, shape (3, 3); B, the velocity terms [N m], shape (3,); C, the gravity torques
                [N m], shape (3,)).
        """
        return dynamics.eom_terms(self, theta, theta_dot)

    def forward_dynamics(self, theta, theta_dot, torque) -> Array:
        """theta_ddot = A^-1 (tau - B - C) of eq 6.21, by Cholesky.

        Args:
            theta: input angles [rad], shape (3,).
            theta_dot: their rates [rad/s], shape (3,).
            torque: motor torques [N m], shape (3,).

        Returns:
            theta_ddot [rad/s^2], shape (3,).
        """
        return dynamics.forward_dynamics(self, theta, theta_dot, torque)

    def inverse_dynamics(self, theta, theta_dot, theta_ddot) -> Array:
        """Motor torques of eq 6.16 from the Lagrangian (eq 6.5), no mass matrix formed.

        Args:
            theta: input angles [rad], shape (3,).
            theta_dot: their rates [rad/s], shape (3,).
            theta_ddot: their accelerations [rad/s^2], shape (3,).

        Returns:
            tau [N m], shape (3,).
        """
        return dynamics.inverse_dynamics(self, theta, theta_dot, theta_ddot)

    def newton_euler_torques(self, theta, theta_dot, theta_ddot) -> Array:
        """Motor torques by Newton-Euler on the tool and the Jacobian (an independent route to
        `inverse_dynamics`); arguments and result as there."""
        return newton_euler.newton_euler_torques(self, theta, theta_dot, theta_ddot)

    def energy(self, theta, theta_dot) -> Array:
        """T + V of the tool (eq 6.7) [J], a scalar, for theta [rad] and theta_dot [rad/s],
        shapes (3,); conserved with zero motor torque."""
        return dynamics.energy(self, theta, theta_dot)
