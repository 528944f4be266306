"""Closed mechanisms as systems for `mbjax.simulate`: any tree closed by cut joints, couplings and
prescribed motions, solved by a loop method passed in (diffrax-style strategies).

    ClosedSystem(tree, closures, method=Coupled(baumgarte=...) | Momentum() | Stabilized(...),
                 projection=False)

The tree (`mbjax.rigid.TreeSystem`, `mbjax.flex.FlexibleSystem`) carries the applied forces:
its control and external wrenches (also settable here with `control=` and `external=`). After
each step `simulate` calls `constrain` (projection onto Phi = 0 and A v + B = 0 when
`projection=True`, differentiable: `mbjax._src.loops.projection`), and at every saved state `check`,
which flags `Status.CONSTRAINT_VIOLATED` once |Phi| exceeds `tolerance` and `Status.REDUNDANT`
when the constraint Jacobian has lost rank (redundant closures, a singular configuration; the
least-squares loads of `mbjax._src.loops.multipliers` keep the run finite).
"""

from collections.abc import Callable

import equinox as eqx
import jax.numpy as jnp
from jax import Array

from mbjax._src.control import as_control
from mbjax._src.system.driven import check_points
from mbjax._src.system.invariants import energy_invariant
from mbjax._src.system.status import Status
from mbjax._src.system.system import AbstractSystem
from mbjax._src.system.tree_system import AbstractTreeSystem
from mbjax._src.model.closures import Prescribed
from mbjax._src.loops.constraints import Loops
from mbjax._src.loops.coupled import Coupled
from mbjax._src.loops.method import AbstractLoopMethod
from mbjax._src.loops.multipliers import numerical_rank
from mbjax._src.loops.projection import ITERATIONS, project_configuration, project_velocity
from mbjax._src.loops.stabilized import Stabilized

TOLERANCE = 1e-6


def _with_forces(tree: AbstractTreeSystem, control, external, external_point) -> AbstractTreeSystem:
    """The tree with the closed system's control and external loads put on it."""
    new = {"control": as_control(control), "external": as_control(external),
           "external_point": check_points(external_point, tree.n)}
    new = {name: value for name, value in new.items() if value is not None}
    for name in new:
        if getattr(tree, name) is not None:
            raise ValueError(f"the tree already has its {name}: give it to the tree or to "
                             "ClosedSystem, not both")
    if not new:
        return tree
    return eqx.tree_at(lambda s: tuple(getattr(s, name) for name in new), tree,
                       tuple(new.values()), is_leaf=lambda x: x is None)


class ClosedSystem(AbstractSystem):
    """A tree closed by `closures`, solved by a loop method, as a system for `mbjax.simulate`.

    Its state is the tree's configuration q and the method's velocity state u (see The state in
    docs/details.md): make u with `initial_state(q, v)` after putting the initial conditions on the
    constraints with `consistent_state`.

    Args:
        tree: the open tree (`mbjax.rigid.TreeSystem`, `mbjax.flex.FlexibleSystem`); it
            carries the applied forces.
        closures (Sequence): `CutJoint`s, `Coupling`s and `Prescribed` motions (at least one), e.g.
            a loaded model's `model.closures`.
        method: an `AbstractLoopMethod` instance; None: `Coupled()` for trees with a symmetric
            mass matrix, `Stabilized()` otherwise.
        projection: after every step, project (q, v) onto Phi = 0 and A v + B = 0
            (differentiably; `mbjax/_src/loops/projection.py`); static.
        tolerance: the residual |Phi| past which `check` reports
            `Status.CONSTRAINT_VIOLATED`; static.
        control (Callable | Array | None): the tree's control, if not given to the tree (as in
            `TreeSystem`).
        external (Callable | None): the tree's external wrenches, if not given to the tree.
        external_point (Array | None): where the external forces act, if not given to the tree.
        iterations: chord iterations of each projection; static.
        watch (Callable | None): a check of the loads: watch(loops, q, multipliers) ->
            `Status` flags (int32), with `loops` the tree and its closures (`Loops`), OR-ed
            into `check` (`mbjax.contact.stance` watches its contacts for a pulling or
            slipping foot).

    Raises:
        TypeError: `tree` is not a tree system, `method` is a class or not a loop method, the
            method cannot close loops on this tree (`Coupled`, `Momentum` on a flexible tree),
            or a closure of another type.
        ValueError: no closures, a closure that names a body or coordinate the tree lacks,
            a control or external load given both here and to the tree, tolerance <= 0 or
            iterations < 1.

    More on the state: the documentation site's Details page (docs/details.md).
    """

    loops: Loops
    method: AbstractLoopMethod
    projection: bool = eqx.field(static=True)
    tolerance: float = eqx.field(static=True)
    iterations: int = eqx.field(static=True)
    watch: Callable | None

    def __init__(self, tree: AbstractTreeSystem, closures, method: AbstractLoopMethod | None = None,
                 projection: bool = False, tolerance: float = TOLERANCE, *, control=None,
                 external=None, external_point=None, iterations: int = ITERATIONS,
                 watch: Callable | None = None):
        if isinstance(method, type):
            raise TypeError(f"method must be an instance, e.g. {method.__name__}(), "
                            "not the class")
        if not isinstance(tree, AbstractTreeSystem):
            Loops(tree, closures)                    # raises with the right message
        if method is None:
            method = Coupled() if tree.symmetric_dynamics else Stabilized()
        if not isinstance(method, AbstractLoopMethod):
            raise TypeError(f"method must be Coupled(...), Momentum() or Stabilized(...), got "
                            f"{type(method).__name__}")
        method.validate(tree)
        if not tolerance > 0:
            raise ValueError(f"tolerance must be positive, got {tolerance}")
        if int(iterations) < 1:
            raise ValueError(f"iterations must be >= 1, got {iterations}")
        self.loops = Loops(_with_forces(tree, control, external, external_point), closures)
        self.method = method
        self.projection = bool(projection)
        self.tolerance = float(tolerance)
        self.iterations = int(iterations)
        if watch is not None and not callable(watch):
            raise TypeError(f"watch must be a callable of (loops, q, multipliers), got {watch!r}")
        self.watch = watch

    @property
    def tree(self) -> AbstractTreeSystem:
        """The open tree, with the applied forces."""
        return self.loops.tree

    @property
    def closures(self) -> tuple:
        """The closures, a tuple."""
        return self.loops.closures

    # -- the method's state -----------------------------------------------------------------------

    def velocity(self, q: Array, u: Array) -> Array:
        """The joint velocities v in the state u.

        Args:
            q: configuration, shape (nq,).
            u: the method's velocity state.

        Returns:
            v, shape (nv,).
        """
        return self.method.velocity(self.loops, q, u)

    def initial_state(self, q: Array, v: Array, t=0.0, *, consistent: bool = True) -> Array:
        """The method's velocity state u for joint velocities v.

        Args:
            q: configuration, shape (nq,).
            v: joint velocities, shape (nv,).
            t: time [s], a scalar.
            consistent: for `Stabilized(epsilon > 0)`, start the load state from the algebraic
                loads (True) or from Anderson 1993 eq 89 (False).

        Returns:
            u: v (`Coupled`, `Stabilized()`), M(q) v (`Momentum`), or (v, f_c), shape
                (nv + m,) (`Stabilized(epsilon > 0)`).
        """
        q, v = jnp.asarray(q, float), jnp.asarray(v, float)
        self.loops.checked(q, v)
        return self.method.initial_state(self.loops, q, v, jnp.asarray(t, q.dtype), consistent)

    def loads(self, t, q: Array, u: Array) -> Array:
        """The constraint loads on the rows of A at a state.

        Args:
            t: time [s], a scalar.
            q: configuration, shape (nq,).
            u: the method's velocity state.

        Returns:
            The loads, shape (m,). `Coupled`, `Momentum`: the multipliers K_c, A^t K_c the
                generalized constraint force; `Stabilized`: f_c = -K_c.
        """
        return self.method.loads(self.loops, t, q, u)

    def multipliers(self, t, q: Array, u: Array) -> Array:
        """The Lagrange multipliers K_c of the rows of A at a state, for every method alike.

        Args:
            t: time [s], a scalar.
            q: configuration, shape (nq,).
            u: the method's velocity state.

        Returns:
            K_c, shape (m,): A^t K_c is the generalized constraint force (Jerkovsky 1978 eq 93);
                for a closure on the ground whose residual is a point's position in world
                components, its three multipliers are the force on that point.
        """
        return self.method.multipliers(self.loops, t, q, u)

    def solve(self, t, q: Array, u: Array) -> tuple[Array, Array]:
        """The acceleration and the multipliers at a state from one solve where the method
        finds both at once (`Coupled`).

        Args:
            t: time [s], a scalar.
            q: configuration, shape (nq,).
            u: the method's velocity state.

        Returns:
            (`acceleration`, `multipliers`) at (t, q, u).
        """
        return self.method.solve(self.loops, t, q, u)

    # -- AbstractSystem ---------------------------------------------------------------------------

    def kinematics(self, q, u):
        return self.tree.q_dot(q, self.velocity(q, u))

    def acceleration(self, t, q, u):
        return self.method.acceleration(self.loops, t, q, u)

    def retract(self, q0, xi):
        return self.tree.retract(q0, xi)

    def local_rate(self, q0, xi, u):
        return self.tree.local_rate(q0, xi, self.velocity(self.retract(q0, xi), u))

    def tangent(self, q, u):
        return self.tree.tangent(q, self.velocity(q, u))

    def difference(self, q0, q1):
        return self.tree.difference(q0, q1)

    def project(self, q):
        return self.tree.normalize(q)

    def state_sizes(self):
        """The tree's nq and the length of the method's u (`Stabilized(epsilon > 0)` adds the
        loads to v)."""
        return self.tree.nq, self.method.state_size(self.loops)

    @property
    def n_controls(self) -> int:
        """The number of forces the tree's control returns."""
        return self.tree.n_controls

    def with_control(self, control) -> "ClosedSystem":
        """The closed system with its tree driven by `control`."""
        return eqx.tree_at(lambda s: s.loops.tree, self, self.tree.with_control(control))

    def holding_control(self, q, nu):
        """The tree's holding control with the closures' forces helping
        (`AbstractTreeSystem.holding_control`)."""
        return self.tree.holding_control(q, nu, self.loops.jacobian(q))

    def hold(self, t, q, u):
        tree = self.tree.hold(t, q, self.velocity(q, u))
        return self if tree is self.tree else eqx.tree_at(lambda s: s.loops.tree, self, tree)

    def constrain(self, t, q, u):
        if not self.projection:
            return q, u
        q = project_configuration(self.loops, q, t, iterations=self.iterations)[0]
        v = project_velocity(self.loops, q, self.velocity(q, u), t)
        return q, self.method.with_velocity(self.loops, q, u, v)

    def quaternions(self):
        """The tree's quaternions in q."""
        return self.tree.quaternions()

    def culprit(self, t, q, u):
        """The tree's (a joint beyond its limit)."""
        return self.tree.culprit(t, q, self.velocity(q, u))

    def culprit_names(self):
        """The tree's."""
        return self.tree.culprit_names()

    def check(self, t, q, u):
        """`Status.CONSTRAINT_VIOLATED` where |Phi| > tolerance, `Status.REDUNDANT` where the
        constraint Jacobian has lost rank, the `watch`'s flags and the tree's own; an int32
        scalar."""
        violated = jnp.linalg.norm(self.loops.phi(q, t)) > self.tolerance
        A = self.loops.jacobian(q, t)
        redundant = numerical_rank(A @ A.T) < self.loops.held()
        watched = (0 if self.watch is None
                   else self.watch(self.loops, q, self.multipliers(t, q, u)).astype(jnp.int32))
        return (jnp.where(violated, int(Status.CONSTRAINT_VIOLATED), 0)
                | jnp.where(redundant, int(Status.REDUNDANT), 0) | watched
                | self.tree.check(t, q, self.velocity(q, u))).astype(jnp.int32)

    # -- invariants -------------------------------------------------------------------------------

    def energy(self, q, u):
        """The tree's energy (kinetic, gravitational, strain) at the state's velocities [J], a
        scalar; the work of the applied forces and prescribed motions is not included."""
        return self.tree.energy(q, self.velocity(q, u))

    def invariants(self, t, q, u):
        """The tree's energy where the tree is passive and no closure is a prescribed motion
        (the closures' loads do no work then); None otherwise. The constraint residual is the
        other invariant, held to `tolerance` by `check`."""
        if not self.tree.passive or any(isinstance(c, Prescribed) for c in self.closures):
            return None
        v = self.velocity(q, u)
        return energy_invariant(self.tree.energy(q, v), self.tree.kinetic_energy(q, v),
                                self.tree.dissipative())

