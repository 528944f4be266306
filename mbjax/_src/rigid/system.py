"""Trees as systems for `mbjax.simulate`, every integrator and `mbjax.loops.ClosedSystem`.

`TreeSystem` integrates (q, v) with the velocity form (Anderson 1993's recursion or Jerkovsky 1978 eq 74);
`MomentumSystem` integrates (q, p) with Jerkovsky 1978's momentum form (eqs 72-73); `BatchTreeSystem`
B copies at once in the throughput layout.

Systems are equinox modules (their model and controls are array leaves), so compile their bound
methods with `eqx.filter_jit(system.energy)`, or pass the system as an argument:
`jax.jit(TreeSystem.energy)(system, q, u)`. (`jax.jit(system.energy)` fails: a bound method
holding arrays is not hashable.)
"""

from typing import ClassVar

import equinox as eqx
import jax.numpy as jnp
from jax import Array

from mbjax._src.control import AbstractControl
from mbjax._src.system.driven import AbstractDrivenSystem, about_origins, drive, held
from mbjax._src.system.dynamics import AbstractForwardDynamics, Auto, Recursive, as_dynamics
from mbjax._src.system.invariants import energy_invariant, join
from mbjax._src.system.system import AbstractSystem
from mbjax._src.system.tree_system import AbstractTreeSystem
from mbjax._src.system.status import Status
from mbjax._src.model import Model
from mbjax._src.model.limits import exceeded, excess_names, first_exceeded
from mbjax._src.rigid.aba import aba_responses
from mbjax._src.rigid.motion import body_forces, body_motion
from mbjax._src.rigid.batched import batch_aba
from mbjax._src.rigid.dense import dense_responses
from mbjax._src.rigid.dynamics import forward_dynamics, mass_matrix
from mbjax._src.rigid.energy import energies, energy, floating, free_momenta, kinetic_energy
from mbjax._src.rigid.kinematics import forward_kinematics
from mbjax._src.rigid.momentum import momentum_rate, velocity_from_momentum
from mbjax._src.rigid import rnea_derivatives
from mbjax._src.rigid.rnea import inverse_dynamics


def _model(model) -> Model:
    if not isinstance(model, Model):
        raise TypeError(f"model must be a mbjax.Model, got {type(model).__name__}"
                        + ("; a flexible tree goes in mbjax.flex.FlexibleSystem"
                           if type(model).__name__ == "FlexibleModel" else ""))
    return model


class TreeSystem(AbstractTreeSystem):
    """A rigid tree as a system for `mbjax.simulate`: u = v, v_dot the forward dynamics under
    gravity, the control and the external wrenches, by Anderson 1993's O(n) recursion or
    Jerkovsky 1978 eq 74 (`method`, as in `mbjax.forward_dynamics`).

    The state is (q, v), shapes (nq,) and (nv,). Its derivatives, of any order, come from the
    adjoint rule of `mbjax/_src/rigid/adjoint.py`.

    Args:
        model: the tree, a `mbjax.Model`.
        control (Callable | Array | None): a callable (t, q, v) -> forces on the actuated
            coordinates, shape (n_controls,) (an `mbjax.control` module or any function), a constant
            array (a constant tau [N m or N]), or None.
        external (Callable | None): a callable (t, q, v) -> world-frame wrenches (torque [N m];
            force [N]) on the bodies, shape (n, 6), acting at their origins or at `external_point`;
            or None.
        external_point (Array | None): body-frame points where the external forces act [m], shape
            (n, 3) or (3,) (the same for every body); None: the bodies' origins.
        actuation (Array | None): the indices of the velocity coordinates the control drives (or a
            boolean mask of length nv), or an (nv, nu) actuation matrix S of rank nu (generalized
            force S u: thrusters, tendons); None: all of them. Stored as the matrix.
        method: `mbjax.Recursive()`, `mbjax.Dense()` or `mbjax.Auto()` (the default); static.

    Raises:
        TypeError: `model` is not a `mbjax.Model` (a flexible tree goes in
            `mbjax.flex.FlexibleSystem`), or `method` is not a strategy instance.
        ValueError: malformed control, external, external_point or actuation.
    """

    model: Model
    control: AbstractControl | None
    external: AbstractControl | None
    external_point: Array | None
    actuation: Array | None
    method: AbstractForwardDynamics = eqx.field(static=True)
    symmetric_dynamics: ClassVar[bool] = True

    def __init__(self, model: Model, control=None, *, external=None, external_point=None,
                 actuation=None, method: AbstractForwardDynamics = Auto()):
        self.model = _model(model)
        self.control, self.external, self.external_point, self.actuation = drive(
            control, external, external_point, actuation, nv=model.nv, n=model.n)
        self.method = as_dynamics(method)

    def frames(self, q):
        """The bodies' world poses: `mbjax.rigid.forward_kinematics` (the model's named frames
        are in `mbjax.rigid.frame_pose`)."""
        return forward_kinematics(self.model, q)

    def body_motion(self, q, v, v_dot=None):
        """The bodies' poses, spatial velocities and (without gravity) accelerations at the world
        origin (`mbjax/_src/rigid/motion.py`: derivatives written out)."""
        if v_dot is None:
            R, p, V, _ = body_motion(self.model, q, v, jnp.zeros_like(v))
            return R, p, V, None
        return body_motion(self.model, q, v, v_dot)

    def body_forces(self, q, wrenches):
        """S^T of the wrenches summed over each joint's outward set (`mbjax/_src/rigid/motion.py`)."""
        return body_forces(self.model, q, wrenches)

    def quaternions(self):
        """The spherical and free joints' quaternions in q (`Model.quaternions`)."""
        return self.model.quaternions()

    def check(self, t, q, u):
        """`Status.LIMIT_EXCEEDED` where the state or the control is beyond the model's joint
        limits (`Model.lower`, `upper`, `velocity_limit`, `effort_limit`); limits are data here, not
        contact forces.

        Args:
            t: time [s], a scalar.
            q: configuration, shape (nq,).
            u: generalized velocity, shape (nv,).

        Returns:
            An int32 scalar of `Status` flags.
        """
        over = exceeded(self.model, q, u, self.applied(t, q, u))
        return jnp.where(over, int(Status.LIMIT_EXCEEDED), 0).astype(jnp.int32)

    def culprit(self, t, q, u):
        """The first coordinate beyond its limit (`first_exceeded` in `mbjax/_src/model/limits.py`)."""
        return first_exceeded(self.model, q, u, self.applied(t, q, u))

    def culprit_names(self):
        """Each joint coordinate's position, velocity and effort limit."""
        return excess_names(self.model)

    def energy(self, q, v):
        """Kinetic plus gravitational energy [J], a scalar (`mbjax.rigid.kinetic_energy` plus
        `potential_energy`); the work of the control and external load is not included."""
        return energy(self.model, q, v)

    def kinetic_energy(self, q, v):
        """The kinetic energy [J], a scalar (`mbjax.rigid.kinetic_energy`)."""
        return kinetic_energy(self.model, q, v)

    def dissipative(self):
        """Whether any joint is damped."""
        return jnp.any(self.model.damping != 0)

    def invariants(self, t, q, u):
        """The energy of a passive tree (from one outward sweep: `energies`, what
        `simulate`'s default check evaluates along a run), and, where every base body hangs from
        a free joint, the momenta of `free_momenta`; None under a control or an external load."""
        if not self.passive:
            return None
        T, E = energies(self.model, q, u)
        energy_part = energy_invariant(E, T, self.dissipative())
        if not floating(self.model):
            return energy_part
        return join(energy_part, free_momenta(self.model, t, q, u))

    def mass_matrix(self, q):
        """M(q), shape (nv, nv) (`mbjax.mass_matrix`)."""
        return mass_matrix(self.model, q)

    def responses(self, t, q, v, loads):
        """As `AbstractTreeSystem.responses`, by the route `method` resolves to."""
        tau, f = self.applied(t, q, v), self.wrenches(t, q, v)
        recursive = isinstance(self.method.resolve(self.model.nv), Recursive)
        route = aba_responses if recursive else dense_responses
        return route(self.model, q, v, tau, loads, f)

    def acceleration(self, t, q, u):
        """`mbjax.forward_dynamics` under the control and the external wrenches (its derivatives
        by the adjoint rule of `mbjax/_src/rigid/adjoint.py`).

        Args:
            t: time [s], a scalar.
            q: configuration, shape (nq,).
            u: generalized velocity v, shape (nv,).

        Returns:
            v_dot, shape (nv,).
        """
        return forward_dynamics(self.model, q, u, self.applied(t, q, u), self.method,
                                self.wrenches(t, q, u))

    def inverse(self, t, q, v, v_dot):
        """The RNEA at v_dot less the control (one O(n) pass): M v_dot + bias; shape (nv,).
        Its derivative in (q, v) is written out where the joints allow it (`rnea_derivatives`)."""
        f = self.wrenches(t, q, v)
        if f is None and rnea_derivatives.applies(self.model):
            tau = rnea_derivatives.inverse_dynamics(self.model, q, v, v_dot)
        else:
            tau = inverse_dynamics(self.model, q, v, v_dot, f)
        return tau - self.applied(t, q, v)

    def bias(self, t, q, v):
        """The RNEA at zero acceleration (velocity terms, gravity, external wrenches) less the
        control: M v_dot + bias = 0; shape (nv,)."""
        return (inverse_dynamics(self.model, q, v, jnp.zeros_like(v), self.wrenches(t, q, v))
                - self.applied(t, q, v))


class BatchTreeSystem(AbstractSystem):
    """B copies of a tree of revolute and prismatic joints in one system, batch last.

    q and u are (nv, B) and u_dot = `batch_aba(model, q, u, tau)`; `simulate` integrates all of
    them in one scan and reports a status for each copy (`Solution.status` of shape (B,)).
    Gravity comes from the model; no control or external load; no invariants.

    Args:
        model: a tree of revolute and prismatic joints only.
        tau (Array | None): constant joint forces [N m or N], shape (nv,) (the same for every copy)
            or (nv, B); None: zero.

    Raises:
        ValueError: (when simulated) a joint that is not revolute or prismatic, or q not of
            shape (nv, B).

    Throughput:
        The one scan runs with the throughput layout of `mbjax.rigid.batched_forward_dynamics`: the same
        trajectories as `jax.vmap` of a `TreeSystem` simulation.
    """

    model: Model
    tau: Array

    def __init__(self, model: Model, tau=None):
        self.model = model
        self.tau = jnp.zeros(model.nv) if tau is None else jnp.asarray(tau)

    # the copies lie along the state's last axis: `simulate` reports a status for each
    batched = True

    def kinematics(self, q, u):
        return u

    def acceleration(self, t, q, u):
        """The joint accelerations of every copy, shape (nv, B), from q and u of shape (nv, B)."""
        return batch_aba(self.model, q, u, self.tau)


class MomentumSystem(AbstractDrivenSystem):
    """A rigid tree integrated in Jerkovsky 1978's momentum form: u = p = M(q) v, the free
    momenta (eq 73), and u_dot from eq 72, which needs no mass-matrix solve (only v = M^-1 p
    does).

    The state is (q, p), shapes (nq,) and (nv,); make p from joint velocities as
    `mbjax.mass_matrix(model, q) @ v` and read v back with `velocity(q, p)`.

    Args:
        model: the tree, a `mbjax.Model`.
        control (Callable | Array | None): as for `TreeSystem`: a callable (t, q, v) -> forces on
            the actuated coordinates (called with the velocities v, not the momenta), a constant
            array, or None.
        external (Callable | None): a callable (t, q, v) -> world-frame wrenches, shape (n, 6), or
            None.
        external_point (Array | None): body-frame points where the external forces act [m], shape
            (n, 3) or (3,); None: the bodies' origins.
        actuation (Array | None): the indices of the velocity coordinates the control drives, or an
            (nv, nu) actuation matrix; None: all. Stored as the matrix.

    Raises:
        TypeError: `model` is not a `mbjax.Model`.
        ValueError: malformed control, external, external_point or actuation.
    """

    model: Model
    control: AbstractControl | None
    external: AbstractControl | None
    external_point: Array | None
    actuation: Array | None

    def __init__(self, model: Model, control=None, *, external=None, external_point=None,
                 actuation=None):
        self.model = _model(model)
        self.control, self.external, self.external_point, self.actuation = drive(
            control, external, external_point, actuation, nv=model.nv, n=model.n)

    @property
    def n(self) -> int:
        """Number of bodies."""
        return self.model.n

    @property
    def nv(self) -> int:
        """Number of velocity coordinates (and of momenta)."""
        return self.model.nv

    def quaternions(self):
        """The spherical and free joints' quaternions in q (`Model.quaternions`)."""
        return self.model.quaternions()

    def velocity(self, q, p):
        """The joint velocities of the momenta, v = M(q)^-1 p, by Cholesky.

        Args:
            q: configuration, shape (nq,).
            p: free momenta, shape (nv,).

        Returns:
            v, shape (nv,).
        """
        return velocity_from_momentum(self.model, q, p)

    def kinematics(self, q, u):
        return self.model.q_dot(q, self.velocity(q, u))

    def acceleration(self, t, q, u):
        v = self.velocity(q, u)
        f = self.external_wrenches(t, q, v)
        if f is not None and self.external_point is not None:
            f = about_origins(f, forward_kinematics(self.model, q)[0], self.external_point)
        return momentum_rate(self.model, q, v, self.applied(t, q, v), f)

    def retract(self, q0, xi):
        return self.model.retract(q0, xi)

    def local_rate(self, q0, xi, u):
        return self.model.local_rate(q0, xi, self.velocity(self.model.retract(q0, xi), u))

    def tangent(self, q, u):
        return self.velocity(q, u)

    def difference(self, q0, q1):
        return self.model.difference(q0, q1, wrap=False)

    def project(self, q):
        return self.model.normalize(q)

    def hold(self, t, q, u):
        return held(self, t, q, self.velocity(q, u))

    def energy(self, q, u):
        """Kinetic plus gravitational energy [J] at the momenta u, a scalar."""
        return energy(self.model, q, self.velocity(q, u))

    def invariants(self, t, q, u):
        """As `TreeSystem`'s, at the velocities of the momenta (none under a control or an
        external load)."""
        if not self.passive:
            return None
        return TreeSystem(self.model).invariants(t, q, self.velocity(q, u))
