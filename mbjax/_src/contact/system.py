"""`ContactSystem`: a rigid tree whose geoms find their own contacts each step, and whose limited
joints stay in their ranges, under a contact model solved each step."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.contact.collision import COUNT, PAIRS
from mbjax._src.model.geoms import SOLIMP, SOLREF, Geoms, pair_parameters
from mbjax._src.contact.soft import AbstractContactModel, SoftConstraints
from mbjax._src.linalg import cho_solve, cholesky
from mbjax._src.model.joints import JOINT_TYPES
from mbjax._src.model.model import Model
from mbjax._src.rigid.dynamics import mass_matrix
from mbjax._src.rigid.frames import on_bodies, point_columns
from mbjax._src.rigid.kinematics import body_kinematics
from mbjax._src.system.tree_system import AbstractTreeSystem
from mbjax._src.system.status import Status
from mbjax._src.system.system import AbstractSystem


class Contacts(eqx.Module):
    """The candidate contacts at a state, a fixed number of them (one not touching has a
    positive distance past its margin: it is data, as a contact let go is).

    Attributes:
        distance: signed distance between the surfaces (negative: penetration) [m], (c,).
        position: the contact point, midway between the surfaces, world [m], (c, 3).
        frame: rows (normal from the first geom to the second, tangent, tangent), (c, 3, 3).
        geoms: each contact's pair of geom indices, c pairs.
        margin: distance below which the contact pushes (its pair's margin; MuJoCo 4 leaves
            the gap out of it), (c,).
    """

    distance: Array
    position: Array
    frame: Array
    margin: Array
    geoms: tuple = eqx.field(static=True)


def _groups(geoms: Geoms) -> list:
    """The detected pairs grouped by their kinds: [(kinds, (P, 2) pair indices)]."""
    groups = {}
    for i, j in geoms.pairs:
        kinds = (geoms.kinds[i], geoms.kinds[j])
        if kinds not in PAIRS:
            raise ValueError(f"geoms: contacts between a {kinds[0]} and a {kinds[1]} "
                             f"({geoms.names[i]!r}, {geoms.names[j]!r}) are not detected; "
                             f"detected kinds: {sorted(PAIRS)}")
        groups.setdefault(kinds, []).append((i, j))
    return [(kinds, np.asarray(p, dtype=int)) for kinds, p in groups.items()]


def detect(geoms: Geoms, R: Array, p: Array) -> Contacts:
    """The candidate contacts of every pair of `geoms` at the bodies' poses
    (`mbjax.rigid.forward_kinematics`): each pair kind's collision function `vmap`ped over its
    pairs.

    Args:
        geoms: the geometry, with its pairs.
        R, p: the bodies' world rotations (n, 3, 3) and origins (n, 3).

    Returns:
        `Contacts`, the pairs' candidates one after another.
    """
    out = []
    for kinds, pairs in _groups(geoms):
        poses = [(*on_bodies(R, p, np.asarray(geoms.bodies)[g], geoms.rotation[g],
                             geoms.position[g]), geoms.size[g]) for g in pairs.T]
        dist, pos, frame = jax.vmap(PAIRS[kinds])(*poses)
        margin = pair_parameters(geoms, *pairs.T)[3]
        k = COUNT[kinds]
        out.append((dist.reshape(-1), pos.reshape(-1, 3), frame.reshape(-1, 3, 3),
                    jnp.repeat(margin, k), np.repeat(pairs, k, axis=0)))
    if not out:
        z = jnp.zeros((0,), R.dtype)
        return Contacts(z, z.reshape(0, 3), z.reshape(0, 3, 3), z, ())
    dist, pos, frame, margin, index = (jnp.concatenate(x) if i < 4 else np.concatenate(x)
                                       for i, x in enumerate(zip(*out, strict=True)))
    return Contacts(dist, pos, frame, margin, tuple(map(tuple, index.tolist())))


@eqx.filter_jit                   # one program, not an eager operation each (a second at first)
def _invweights(model, q: Array) -> tuple[Array, Array]:
    """MuJoCo's `body_invweight0` (translational) and `dof_invweight0` at q: the mean diagonal
    of J M^-1 J^T for each body's centre of mass (its rotational mean where the translational
    one vanishes), and of each joint's block of M^-1."""
    kin = body_kinematics(model, q, jnp.zeros(model.nv, q.dtype))
    Minv = cho_solve(cholesky(mass_matrix(model, q)), jnp.eye(model.nv, dtype=q.dtype))
    path = jnp.asarray(model.topology.path_matrix()[:, model.dof_body()], float)   # (n, nv)
    com = kin.p + jnp.einsum("kij,kj->ki", kin.R, model.com)
    columns = point_columns(model, kin.S, com) * path[:, :, None]         # (n, nv, 6)
    w, v = columns[..., :3], columns[..., 3:]
    tran = jnp.einsum("kci,cd,kdi->k", v, Minv, v) / 3
    rot = jnp.einsum("kci,cd,kdi->k", w, Minv, w) / 3
    body = jnp.where(tran > 1e-15, tran, rot)
    diagonal = jnp.diagonal(Minv)
    dof = []
    for k, kind in enumerate(model.joint_types):
        start = int(np.searchsorted(model.dof_body(), k))
        width = int(np.sum(model.dof_body() == k))
        block = diagonal[start:start + width]
        if kind == "free":                     # (omega; v): the translational and rotational means
            block = jnp.concatenate([jnp.full(3, block[:3].mean()), jnp.full(3, block[3:].mean())])
        elif width > 1:
            block = jnp.full(width, block.mean())
        dof.append(block)
    return body, jnp.concatenate(dof)


def _world_rate(model, v: Array) -> Array:
    """What each free joint's velocity rate gains in world components: the rows' accelerations
    are MuJoCo's, J a_MuJoCo = J (a + this), with a free joint's linear velocity in world
    components, whose rate differs from that of mbjax's body components by omega x v."""
    pieces, done = [], 0
    for k, kind in enumerate(model.joint_types):
        if kind == "free":                          # (omega; v): omega x v on the v rows
            i = int(np.searchsorted(model.dof_body(), k))
            pieces += [jnp.zeros(i + 3 - done, v.dtype), jnp.cross(v[i:i + 3], v[i + 3:i + 6])]
            done = i + 6
    return jnp.concatenate([*pieces, jnp.zeros(model.nv - done, v.dtype)])


class ContactSystem(AbstractSystem):
    """A rigid tree on its geoms: contacts found each step between the pairs of geoms that may
    touch (`ContactSystem.contacts`), and limited joints held in their ranges, all solved by one
    contact model (`SoftConstraints`, MuJoCo's, by default). `mbjax.simulate` runs it like any
    other system (MuJoCo's own integrator is `mbjax.integrate.SemiImplicitEuler`).

    Args:
        tree: the `TreeSystem` (its model, control and external wrenches).
        geoms: the geometry, or None for the model's own (`tree.model.geoms`, from
            `load_mjcf`); join a ground with `geoms.join(mbjax.model.ground_plane())`.
        method: the contact model, a strategy object (`SoftConstraints()` by default).
        timestep: the simulation's step [s], for MuJoCo's safety bound on the time constants
            (at least two steps); 0.002 s (MuJoCo's default) by default.
        limits: hold the joints whose bounds are finite (`model.lower`, `model.upper`: MJCF's
            and URDF's limited joints) in their ranges, as MuJoCo does; True by default.
        limit_solref, limit_solimp: the limits' parameters (MuJoCo's defaults).
        q_reference: the configuration at which each body's and joint's inverse inertia scale
            is taken (MuJoCo's qpos0); the model's `neutral()` by default, which is MuJoCo's
            qpos0 for an MJCF file whose hinges and slides have no `ref`.
        penetration: the deepest a contact may sink past its margin before `check` fails the
            run (`Status.PENETRATING`) [m]; 0.05 by default.
        implicit_damping: take the joint damping implicitly over one step, as MuJoCo's Euler
            integrator does: the accelerations returned are (M + timestep B)^-1 M a, B the
            damping, so that `SemiImplicitEuler` at `timestep` steps as MuJoCo's Euler does
            (MuJoCo's default integrator, unless the file disables `eulerdamp`); False by
            default.

    Statuses:
        `simulate`'s saved states are checked: a contact deeper than `penetration` fails the
        run with `Status.PENETRATING`, a contact solve that missed its tolerance within its
        iterations with `Status.NOT_CONVERGED`, a pushing contact or limit whose time constant
        is shorter than two steps (which the steps cannot follow) with `Status.UNRESOLVED`;
        the tree's own notes follow (a joint past its position limit is not noted where the
        limits are held).

    Raises:
        TypeError: a tree that is not a `TreeSystem`, geoms that are not `Geoms`, or a method
            that is not a contact model.
        ValueError: a pair of geom kinds that is not detected, a geom on a body the model
            lacks, a nonpositive timestep or penetration.
    """

    tree: AbstractTreeSystem
    geoms: Geoms
    method: AbstractContactModel
    invweight: Array
    dof_invweight: Array
    limit_solref: Array
    limit_solimp: Array
    timestep: float = eqx.field(static=True)
    penetration: float = eqx.field(static=True)
    implicit_damping: bool = eqx.field(static=True)
    limited: tuple = eqx.field(static=True)      # the velocity coordinate of each limited joint

    def __init__(self, tree: AbstractTreeSystem, geoms: Geoms | None = None, *,
                 method: AbstractContactModel = SoftConstraints(), timestep: float = 0.002,
                 limits: bool = True, limit_solref=SOLREF, limit_solimp=SOLIMP,
                 q_reference=None, penetration: float = 0.05, implicit_damping: bool = False):
        if not (isinstance(tree, AbstractTreeSystem) and isinstance(tree.model, Model)):
            raise TypeError(f"tree must be a mbjax.rigid.TreeSystem, got {type(tree).__name__}")
        if not isinstance(method, AbstractContactModel):
            raise TypeError(f"method must be a contact model such as SoftConstraints(), got "
                            f"{method!r}")
        model = tree.model
        geoms = model.geoms if geoms is None else geoms
        if geoms is None:
            geoms = Geoms((), (), np.zeros((0, 3)))
        if not isinstance(geoms, Geoms):
            raise TypeError(f"geoms must be mbjax.model.Geoms, got {type(geoms).__name__}")
        _groups(geoms)                                  # a ValueError for an undetected pair
        if any(b >= model.n for b in geoms.bodies):
            raise ValueError(f"geoms: a body index beyond the model's {model.n} bodies")
        self.tree, self.geoms, self.method = tree, geoms, method
        if not (float(timestep) > 0):
            raise ValueError(f"timestep must be positive, got {timestep!r}")
        self.timestep = float(timestep)
        if not (float(penetration) > 0):
            raise ValueError(f"penetration must be positive, got {penetration!r}")
        self.penetration = float(penetration)
        self.implicit_damping = bool(implicit_damping)
        limited, iq = [], 0
        lower, upper = np.asarray(model.lower), np.asarray(model.upper)
        for k, kind in enumerate(model.joint_types):
            if limits and kind in ("revolute", "prismatic") and (np.isfinite(lower[iq])
                                                                  or np.isfinite(upper[iq])):
                limited.append((iq, int(np.searchsorted(model.dof_body(), k))))
            iq += JOINT_TYPES[kind][0]
        self.limited = tuple(limited)
        self.limit_solref = jnp.asarray(limit_solref, dtype=float)
        self.limit_solimp = jnp.asarray(limit_solimp, dtype=float)
        q_reference = (model.neutral() if q_reference is None
                       else jnp.asarray(q_reference, float))
        self.invweight, self.dof_invweight = _invweights(model, q_reference)

    @property
    def model(self):
        """The tree's model."""
        return self.tree.model

    def contacts(self, q: Array) -> Contacts:
        """The candidate contacts at configuration q (`detect`)."""
        kin = body_kinematics(self.model, q, jnp.zeros(self.model.nv, q.dtype))
        return detect(self.geoms, kin.R, kin.p)

    def _rows(self, q: Array, v: Array):
        """The constraint rows at (q, v): (J, position, invweight, solref, solimp, frictional)
        of every contact's pyramid edges (sliding, condim 3; and torsional, 4; and rolling, 6;
        MuJoCo's pyramids) or normal (condim 1) and every joint limit, and the
        contacts."""
        model, geoms = self.model, self.geoms
        kin = body_kinematics(model, q, v)
        found = detect(geoms, kin.R, kin.p)
        path = model.topology.path_matrix()[:, model.dof_body()].astype(float)   # (n, nv)
        parts = []
        if found.geoms:
            i, j = np.asarray(found.geoms).T
            body = np.asarray(geoms.bodies)
            def support(b: np.ndarray) -> np.ndarray:        # the columns on b's path, (c, nv)
                return np.where(b[:, None] >= 0, path[np.maximum(b, 0)], 0.0)

            columns = point_columns(model, kin.S, found.position)             # (c, nv, 6)
            relative = columns * (support(body[j]) - support(body[i]))[..., None]
            # the relative motion in the contact frame: (normal, tangents), then the turning
            # about them (spin, rolling), (c, 3, nv) each
            J = found.frame @ jnp.swapaxes(relative[..., 3:], -1, -2)
            turning = found.frame @ jnp.swapaxes(relative[..., :3], -1, -2)
            friction, solref, solimp, _ = pair_parameters(geoms, i, j)
            condim = np.maximum(np.asarray(geoms.condim)[i], np.asarray(geoms.condim)[j])
            weight = self.invweight[np.maximum(body[i], 0)] * (body[i] >= 0) + \
                self.invweight[np.maximum(body[j], 0)] * (body[j] >= 0)
            position = found.distance - found.margin
            for dim in (1, 3, 4, 6):
                on = np.flatnonzero(condim == dim)
                if not on.size:
                    continue
                if dim == 1:
                    rows, scale = J[on, :1], weight[on][:, None]
                else:           # a pair of pyramid edges per direction: J_n +- mu_k J_k
                    directions = jnp.concatenate([J[on, 1:], turning[on, :dim - 3]], 1)
                    f = friction[on]                   # sliding, torsional, rolling
                    mu = jnp.stack([f[:, 0], f[:, 0], f[:, 1], f[:, 2], f[:, 2]], 1)[:, :dim - 1]
                    signs = jnp.repeat(mu, 2, axis=1) * jnp.tile(jnp.array([1.0, -1.0]), dim - 1)
                    rows = J[on, :1] + jnp.repeat(directions, 2, axis=1) * signs[:, :, None]
                    # MuJoCo's common weight of a pyramid's edges, from its sliding friction
                    slide = f[:, 0]
                    scale = (weight[on] * (1 + slide**2) * 2 * slide**2)[:, None]
                edges = rows.shape[1]
                parts.append((rows.reshape(-1, model.nv), jnp.repeat(position[on], edges),
                              jnp.broadcast_to(scale, (on.size, edges)).reshape(-1),
                              jnp.repeat(solref[on], edges, axis=0),
                              jnp.repeat(solimp[on], edges, axis=0),
                              jnp.full(on.size * edges, dim > 1)))
        if self.limited:
            iq, iv = (np.asarray(x) for x in zip(*self.limited, strict=True))
            below, above = q[iq] - model.lower[iq], model.upper[iq] - q[iq]
            near = jnp.where(below < above, 1.0, -1.0)
            J = near[:, None] * np.eye(model.nv)[iv]                 # no scatter in a step
            parts.append((J, jnp.minimum(below, above), self.dof_invweight[iv],
                          jnp.broadcast_to(self.limit_solref, (iq.size, 2)),
                          jnp.broadcast_to(self.limit_solimp, (iq.size, 5)),
                          jnp.zeros(iq.size, bool)))
        if not parts:
            z = jnp.zeros((0,), q.dtype)
            return (z.reshape(0, model.nv), z, z, z.reshape(0, 2), z.reshape(0, 5),
                    z.astype(bool)), found
        return tuple(jnp.concatenate(x) for x in zip(*parts, strict=True)), found

    def _problem(self, t, q: Array, v: Array):
        """(M, a0, J, D, aref) of the contact model's problem at (t, q, v), the contacts, and
        the rows' (position, solref)."""
        M = self.tree.mass_matrix(q)
        free = cho_solve(cholesky(M), -self.tree.bias(t, q, v))
        (J, position, invweight, solref, solimp, frictional), found = self._rows(q, v)
        D, aref = self.method.rows(J, position, J @ v, invweight, solref, solimp, frictional,
                                   self.timestep)
        return (M, free, J, D, aref - J @ _world_rate(self.model, v)), found, (position, solref)

    def solve(self, t, q: Array, v: Array) -> tuple[Array, Array, Contacts]:
        """The contact model's solution at a state.

        Args:
            t: time [s], a scalar.
            q: configuration, shape (nq,).
            v: velocity, shape (nv,).

        Returns:
            (v_dot (with `implicit_damping`, the step's), each constraint row's force (the
            contacts' pyramid edges, then the joint limits), the candidate contacts).
        """
        problem, found, _ = self._problem(t, q, v)
        a, forces = self.method.solve(*problem)
        if self.implicit_damping:              # MuJoCo's mj_Euler: (M + h B) a_step = M a
            M = problem[0]
            a = cho_solve(cholesky(M + self.timestep * jnp.diag(self.model.damping)), M @ a)
        return a, forces, found

    def check(self, t, q, u):
        """`Status.PENETRATING` where a contact sinks deeper than `penetration`,
        `Status.NOT_CONVERGED` where the contact solve missed its tolerance,
        `Status.UNRESOLVED` where a pushing row's time constant is shorter than two steps, and
        the tree's flags (an int32 scalar)."""
        problem, found, (position, solref) = self._problem(t, q, u)
        flags = jnp.where(self.method.converged(*problem), 0, int(Status.NOT_CONVERGED))
        fast = (position < 0) & ~self.method.resolved(solref, self.timestep)
        flags = flags | jnp.where(jnp.any(fast), int(Status.UNRESOLVED), 0)
        if found.geoms:
            deep = jnp.any(found.distance - found.margin < -self.penetration)
            flags = flags | jnp.where(deep, int(Status.PENETRATING), 0)
        tree = self.tree.check(t, q, u)
        if self.limited:          # the limits are held (softly, as MuJoCo's), not just noted
            tree = tree & ~int(Status.LIMIT_EXCEEDED)
        return (flags | tree).astype(jnp.int32)

    # -- AbstractSystem ---------------------------------------------------------------------------

    def kinematics(self, q, u):
        return self.tree.kinematics(q, u)

    def acceleration(self, t, q, u):
        return self.solve(t, q, u)[0]

    def retract(self, q0, xi):
        return self.tree.retract(q0, xi)

    def local_rate(self, q0, xi, u):
        return self.tree.local_rate(q0, xi, u)

    def tangent(self, q, u):
        return self.tree.tangent(q, u)

    def difference(self, q0, q1):
        return self.tree.difference(q0, q1)

    def project(self, q):
        return self.tree.project(q)

    def hold(self, t, q, u):
        tree = self.tree.hold(t, q, u)
        return self if tree is self.tree else eqx.tree_at(lambda s: s.tree, self, tree)

    def quaternions(self):
        return self.tree.quaternions()

    def state_sizes(self):
        return self.tree.state_sizes()

    @property
    def n_controls(self) -> int:
        return self.tree.n_controls

    def with_control(self, control) -> "ContactSystem":
        return eqx.tree_at(lambda s: s.tree, self, self.tree.with_control(control))
