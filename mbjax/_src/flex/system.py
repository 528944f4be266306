"""Flexible trees as systems for `mbjax.simulate` and `mbjax.loops.ClosedSystem`.

`FlexibleSystem` integrates (q, v) = (joint and modal coordinates, their rates) with Anderson 1993's
O(n) recursion (`method=Recursive()`, `mbjax._src.flex.aba`) or the dense Lagrangian route
(`method=Dense()`, `mbjax._src.flex.lagrange`). Closed loops and prescribed motions wrap it in
`mbjax.loops.ClosedSystem(..., method=Stabilized())`, with cut joints at the model's markers.
"""

from typing import ClassVar

import equinox as eqx
import jax
import jax.numpy as jnp
from jax import Array

from mbjax._src.control import AbstractControl
from mbjax._src.system.driven import about_origins, drive
from mbjax._src.system.dynamics import AbstractForwardDynamics, Auto, Recursive, as_dynamics
from mbjax._src.flex.aba import flexible_aba_responses
from mbjax._src.flex.body import kinetic_energy as body_kinetic_energy
from mbjax._src.flex.kinematics import body_velocities, body_and_marker_poses, marker_forces
from mbjax._src.flex.lagrange import lagrangian_forward_dynamics, potential_energy
from mbjax._src.flex.model import FlexibleModel
from mbjax._src.system.tree_system import AbstractTreeSystem


class FlexibleSystem(AbstractTreeSystem):
    """A flexible tree as a system for `mbjax.simulate`: u = v; v_dot from the tree's forward
    dynamics under gravity, elasticity, the control and the external wrenches.

    The state is (q, v) = (joint and modal coordinates, their rates), shapes (nq,) and (nv,).
    The control drives joint and modal coordinates alike (`actuation` picks some).

    Args:
        model: the flexible tree, a `FlexibleModel`.
        control (Callable | Array | None): a callable (t, q, v) -> generalized forces on the
            actuated coordinates (joint forces, then modal forces), an `mbjax.control` module, a
            constant array, or None.
        external (Callable | None): a callable (t, q, v) -> world-frame wrenches (torque [N m];
            force [N]): one per body, shape (n, 6), acting on the body's reference frame (the joint
            grid where its modes are clamped, or `external_point`, a point fixed in that frame), as
            in `mbjax.rigid.TreeSystem`; or one per frame, shape (n + markers, 6), the rows past n
            acting at the model's markers (torque about the marker's origin, the force applied
            there); or None.
        external_point (Array | None): body-frame points where the bodies' external forces act [m],
            shape (n, 3) or (3,); None: the bodies' frame origins.
        actuation (Array | None): the indices of the velocity coordinates the control drives (or a
            boolean mask of length nv), or an (nv, nu) actuation matrix S of rank nu (generalized
            force S u: thrusters, tendons); None: all of them. Stored as the matrix.
        method: `mbjax.Recursive()` (Anderson 1993's O(n) recursion), `mbjax.Dense()` (the
            Lagrangian, O(n^3); joints whose q is their own rate only) or `mbjax.Auto()` (the
            default); static.

    Raises:
        TypeError: `model` is not a `FlexibleModel`, or `method` is not a strategy instance.
        ValueError: malformed control, external, external_point or actuation.

    Loads and stiffening:
        A load at a marker on a grid point bends the body and stiffens it (Anderson 1993 eq 33,
        `grid_point` in `mbjax/_src/flex/kinematics.py`), as a cut joint's constraint load there does.

        Geometric stiffening adds acceleration-dependent loads, so the equations are not
        M v_dot + bias = 0 with a symmetric M (`symmetric_dynamics` is False): closed loops go
        through `mbjax.loops.Stabilized`, on either route.
    """

    model: FlexibleModel
    control: AbstractControl | None
    external: AbstractControl | None
    external_point: Array | None
    actuation: Array | None
    method: AbstractForwardDynamics = eqx.field(static=True)
    symmetric_dynamics: ClassVar[bool] = False

    def __init__(self, model: FlexibleModel, control=None, *, external=None, external_point=None,
                 actuation=None, method: AbstractForwardDynamics = Auto()):
        if not isinstance(model, FlexibleModel):
            raise TypeError(f"model must be a FlexibleModel, got {type(model).__name__}")
        self.model = model
        self.control, self.external, self.external_point, self.actuation = drive(
            control, external, external_point, actuation, nv=model.nv, n=model.n)
        self.method = as_dynamics(method)

    def frames(self, q):
        """World poses of the body frames (joint grids), then of the markers at grid points,
        deformation included.

        Args:
            q: configuration, shape (nq,).

        Returns:
            (R, p): rotations, shape (n + markers, 3, 3), and origins [m], shape
                (n + markers, 3).
        """
        R, p, R_markers, p_markers = body_and_marker_poses(self.model, q)
        return jnp.concatenate([R, R_markers]), jnp.concatenate([p, p_markers])

    def kinetic_energy(self, q, v):
        """T = sum_k w_k^T M_k(q_k) w_k / 2 (Anderson 1993 eq 34), w from the recursion's
        velocities; a scalar [J]."""
        w = body_velocities(self.model, q, v)
        qf = self.model.split(q)[1]
        return jnp.sum(jax.vmap(body_kinetic_energy)(self.model.bodies, qf, w))

    def dissipative(self):
        """Joint damping or modal damping."""
        return jnp.any(self.model.model.damping != 0) | jnp.any(self.model.bodies.damping != 0)

    def energy(self, q, v):
        """Kinetic, gravitational and modal strain energy [J], a scalar; the work of the applied
        forces is not included."""
        return self.kinetic_energy(q, v) + potential_energy(self.model, q)

    def mass_matrix(self, q):
        """d^2 T / dv^2, symmetric, shape (nv, nv); the equations of motion add stiffening to it."""
        zero = jnp.zeros(self.nv, q.dtype)
        return jax.jacfwd(jax.grad(self.kinetic_energy, argnums=1), argnums=1)(q, zero)

    def wrenches(self, t, q, v):
        """The bodies' external wrenches (n, 6), world frame, torque about each body's origin;
        or None (marker rows, if any, are in `applied`'s generalized forces)."""
        return self._loads(t, q, v)[1]

    def applied(self, t, q, v):
        """The control's generalized forces, plus those of the wrenches at markers, shape (nv,)."""
        return self._loads(t, q, v)[0]

    def _loads(self, t, q, v):
        """(generalized forces, body wrenches or None), `external` called once."""
        tau = super().applied(t, q, v)
        if self.external is None:
            return tau, None
        f = jnp.asarray(self.external(t, q, v), v.dtype)
        if f.shape not in ((self.n, 6), (self.n_frames, 6)):
            raise ValueError(f"external returned shape {f.shape}; it must return one world-frame "
                             f"wrench (torque; force) per body, shape ({self.n}, 6), or per body "
                             f"and marker, shape ({self.n_frames}, 6)")
        if f.shape[0] > self.n:
            tau = tau + marker_forces(self.model, q, f[self.n:])
        return tau, about_origins(f[:self.n], self.frames(q)[0][:self.n], self.external_point)

    def responses(self, t, q, v, loads):
        """As `AbstractTreeSystem.responses`, by the route `method` resolves to."""
        tau, f = self._loads(t, q, v)
        if isinstance(self.method.resolve(self.nv), Recursive):
            return flexible_aba_responses(self.model, q, v, tau, loads, f)
        return lagrangian_forward_dynamics(self.model, q, v, tau, f, loads)
