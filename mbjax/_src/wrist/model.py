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
    """A Carpal Wrist: three legs at azimuths phi0 + (0, 120, 240) deg on a base of radius
    `base_radius`, legs of `link_length` from base axis to knee, a rigid tool of `tool_mass`,
    inertia `tool_inertia` about its centre of mass (3x3 in D) and centre-of-mass offset `tool_com`
    from the distal-plate centre (in D), gravity `gravity` along -e3.

    Every parameter is an array leaf, so wrists can be differentiated, vmapped and swept
    (`mbjax._src.synthesis.sweeps`). `rotation_model="chapter"` switches to Canfield 1997's printed
    R = Rz(alpha) Ry(beta) (eq 6.2) instead of the physical mirror plate Rz(alpha) Ry(beta)
    Rz(-alpha): for reproducing the chapter's equations only, see `kinematics.rotation_from_slope`.
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
        """The tool pose (alpha, beta, plunge, rotation, centre, com) for input angles theta."""
        return kinematics.forward_kinematics(self, theta)

    def leg_points(self, theta) -> Array:
        """Base revolutes, knees and distal revolutes of the three legs, (3, 3, 3)."""
        return kinematics.leg_points(self, theta)

    def inverse_kinematics(self, alpha, beta, plunge) -> Array:
        """theta (knees-out) for the pose; an unreachable pose raises."""
        return kinematics.inverse_kinematics(self, alpha, beta, plunge)

    def solve_inverse_kinematics(self, plunge, slope) -> tuple[Array, Array]:
        """(theta, reachable) for the midplane chart (plunge, slope); never raises, never NaN."""
        return kinematics.solve_inverse_kinematics(self, jnp.asarray(plunge, dtype=float),
                                                   jnp.asarray(slope, dtype=float))

    def jacobian(self, theta) -> Array:
        """J of eq 6.34 by autodiff: (N_x, N_y, p)_dot = J theta_dot."""
        return kinematics.jacobian(self, theta)

    def jacobian_closed_form(self, theta) -> Array:
        """J of eq 6.34 in closed form (K^-1 D)."""
        return kinematics.jacobian_closed_form(self, theta)

    def singularity_measures(self, theta) -> kinematics.SingularityMeasures:
        """Distances to the inverse and direct singularities (1 far, 0 on them)."""
        return kinematics.singularity_measures(self, theta)

    def reachable(self, alpha, beta, plunge) -> Array:
        """True where (alpha, beta, plunge) is in the workspace."""
        return kinematics.reachable(self, alpha, beta, plunge)

    # -- dynamics (autodiff Lagrangian) --------------------------------------------------------
    def mass_matrix(self, theta) -> Array:
        """A(theta) of eq 6.16."""
        return dynamics.mass_matrix(self, theta)

    def eom_terms(self, theta, theta_dot) -> tuple[Array, Array, Array]:
        """(A, B, C) of eq 6.16."""
        return dynamics.eom_terms(self, theta, theta_dot)

    def forward_dynamics(self, theta, theta_dot, torque) -> Array:
        """theta_ddot of eq 6.21 (Cholesky)."""
        return dynamics.forward_dynamics(self, theta, theta_dot, torque)

    def inverse_dynamics(self, theta, theta_dot, theta_ddot) -> Array:
        """Motor torques of eq 6.16 from the Lagrangian."""
        return dynamics.inverse_dynamics(self, theta, theta_dot, theta_ddot)

    def newton_euler_torques(self, theta, theta_dot, theta_ddot) -> Array:
        """Motor torques by Newton-Euler on the tool and the Jacobian (independent route)."""
        return newton_euler.newton_euler_torques(self, theta, theta_dot, theta_ddot)

    def energy(self, theta, theta_dot) -> Array:
        """T + V."""
        return dynamics.energy(self, theta, theta_dot)
