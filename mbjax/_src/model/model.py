"""`Model`: a tree of rigid bodies connected by joints.

Topology, joint types and names are static (hashable; changing them recompiles). Placements, axes,
masses, centres of mass, inertias and gravity are array leaves with a leading body axis, so they can
be differentiated, vmapped and swept without recompiling.

Body k hangs from body `parents[k]` (-1: the ground) through joint k. Generalized coordinates q
(length nq) and velocities v (length nv) are the joints' own, concatenated in body order; bodies are
numbered depth-first with children in document order, which is Pinocchio's ordering.
"""

from functools import lru_cache

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.model.geoms import Geoms
from mbjax._src.model.joints import (
    JOINT_TYPES,
    NEUTRAL,
    joint_calc,
    joint_local_rate,
    joint_rate,
    joint_difference,
    joint_integrate,
    wrap_angle,
)
from mbjax._src.model.checks import check_body
from mbjax._src.model.locked import lock_joints
from mbjax._src.tree.take import take
from mbjax._src.spatial import inertia_matrix
from mbjax._src.tree import Topology


@lru_cache(maxsize=None)
def _layout(joint_types: tuple[str, ...]):
    """Static index maps: each joint type's bodies and coordinates, the orders that put them back
    in body and coordinate order, the padded velocity columns' mask and the widths."""
    nqs = [JOINT_TYPES[k].nq for k in joint_types]
    nvs = [JOINT_TYPES[k].nv for k in joint_types]
    q0, v0 = np.cumsum([0, *nqs]), np.cumsum([0, *nvs])
    wq, wv = max(nqs), max(nvs)
    v_mask = np.array([[j < nvs[k] for j in range(wv)] for k in range(len(nvs))])
    groups = {kind: np.array([k for k, t in enumerate(joint_types) if t == kind])
              for kind in dict.fromkeys(joint_types)}
    # each joint type's own coordinates (bodies of the type, its nq or nv columns), and where the
    # bodies and coordinates of all types, concatenated type by type, go back to in body order
    q_own = {kind: q0[idx][:, None] + np.arange(JOINT_TYPES[kind].nq) for kind, idx in groups.items()}
    v_own = {kind: v0[idx][:, None] + np.arange(JOINT_TYPES[kind].nv) for kind, idx in groups.items()}

    def order(maps):
        return np.argsort(np.concatenate([m.ravel() for m in maps]), kind="stable")
    return dict(nq=int(q0[-1]), nv=int(v0[-1]), q_start=tuple(int(x) for x in q0[:-1]),
                v_start=tuple(int(x) for x in v0[:-1]), v_mask=v_mask, q_width=wq, width=wv,
                groups=groups, q_own=q_own, v_own=v_own,
                body_order=order(groups.values()), q_order=order(q_own.values()),
                v_order=order(v_own.values()))


class Model(eqx.Module):
    """A tree of rigid bodies connected by joints.

    Build it with `Model(parents, joint_types, ...)`, the builders `mbjax.model.chain` and
    `mbjax.model.random_tree`, or the loaders `mbjax.load_urdf` and `mbjax.load_mjcf`. Body k
    hangs from body parents[k] (-1: the ground) through joint k; q (nq,) and v (nv,) are the
    joints' own coordinates concatenated in body order (the loaders number bodies depth-first,
    children in document order, as Pinocchio does). Topology, joint types and names
    are static (hashable; changing them recompiles); every array is a leaf that can be
    differentiated, vmapped and swept without recompiling. Per-body arrays have a leading axis
    of n bodies; a per-body argument given for one body is broadcast to all of them.

    Limits are data (bounds for trajectory optimisation, checked by `TreeSystem.check` in
    `simulate`'s status, `Status.LIMIT_EXCEEDED`), not contact forces. Bodies with
    implausible but computable mass data (a triangle-inequality violation, negative moments, a
    massless leaf without armature) load with a `ModelWarning`; `strict=True` makes it an
    error.

    Args:
        parents (Sequence[int] | Topology): each body's parent, shape (n,), parents[k] < k or -1 for
            a base body; or a `Topology`.
        joint_types (str | Sequence[str]): each joint's type, one of "revolute", "prismatic",
            "universal", "spherical", "free" (a sequence of n, or one string for all).
        mass (ArrayLike): body masses, shape (n,) [kg].
        inertia (ArrayLike): inertias about each centre of mass in the body frame, shape (n, 3, 3)
            [kg m^2].
        com (ArrayLike): centres of mass in the body frames, shape (n, 3) [m]; zeros by default.
        axis (ArrayLike): joint axes in the joint frames, shape (n, 3), normalized here; z by
            default.
        axis2 (ArrayLike): the universal joints' second axes, shape (n, 3); y by default.
        placement_rotation (ArrayLike): joint k's frame in body parents[k]'s frame (the ground frame
            for a base body), shape (n, 3, 3); identities by default.
        placement_translation (ArrayLike): the joint frames' origins in the parents' frames, shape
            (n, 3) [m]; zeros by default.
        gravity (ArrayLike): the ground-frame acceleration of gravity, shape (3,) [m/s^2].
        names (Sequence[str] | None): body names, n strings; "body0", "body1", ... by default.
        joint_names (Sequence[str] | None): joint names, n strings; "joint0", ... by default.
        lower (ArrayLike): lower position limits, shape (nq,) [rad or m]; -inf (none) by default.
        upper (ArrayLike): upper position limits, shape (nq,); inf by default. A revolute joint
            without limits is a URDF "continuous" joint.
        velocity_limit (ArrayLike): bounds on |v|, shape (nv,); inf (none) by default.
        effort_limit (ArrayLike): bounds on |tau|, shape (nv,) [N m or N]; inf by default.
        damping (ArrayLike): viscous joint damping, a force -damping * v in the dynamics, shape
            (nv,).
        stiffness (ArrayLike): joint springs, a force -stiffness * (q - spring_reference) in the
            dynamics (MuJoCo's joint stiffness), shape (nv,); zero on spherical and free joints'
            coordinates (a spring there is not modelled).
        spring_reference (ArrayLike): the springs' rest positions (MuJoCo's springref), shape
            (nq,); zeros by default (read on the revolute, prismatic and universal joints only).
        armature (ArrayLike): rotor inertia reflected to the joint, added to the mass matrix
            diagonal (Featherstone's ABA adds it to D; MuJoCo's and Pinocchio's armature), shape
            (nv,).
        friction (ArrayLike): dry friction, shape (nv,), kept as data (not used by the dynamics).
        frame_names (Sequence[str]): names of extra frames fixed to bodies (URDF links merged
            through fixed joints, fixed joints, MJCF sites), m strings; see `mbjax.rigid.frame_pose`
            and `mbjax.rigid.frame_jacobian`.
        frame_parents (Sequence[int]): the body each frame is fixed to (-1: the ground), m ints.
        frame_rotation (ArrayLike): each frame's orientation in its body, shape (m, 3, 3).
        frame_translation (ArrayLike): each frame's origin in its body, shape (m, 3) [m].
        closures (tuple): the loop-closing constraints the model file declares (a URDF's mimic
            joints as `mbjax.loops.Coupling`s, an MJCF's connect and weld equalities as
            `mbjax.loops.CutJoint`s); `TreeSystem(model)` leaves them out and
            `ClosedSystem(TreeSystem(model), model.closures)` enforces them.
        geoms (mbjax.model.Geoms | None): the collision geometry (`load_mjcf` keeps an MJCF's
            geoms, `load_urdf` a URDF's `<collision>` shapes), which
            `mbjax.contact.ContactSystem` detects contacts between; None for
            none.
        strict (bool): turn the mass-data warnings into errors.

    Raises:
        ValueError: an invalid parents array, unknown joint type, wrong number of names, an
            array of the wrong shape, a non-finite value, a placement that is not a rotation,
            a zero or parallel joint axis, limits out of order, negative damping, stiffness,
            armature or friction, a spring on a spherical or free joint, an invalid mass or
            inertia (see `ModelWarning`; with strict=True also the implausible ones), or a
            frame whose parent is not a body.
        TypeError: an array argument that is not real numbers.
    """

    topology: Topology = eqx.field(static=True)
    joint_types: tuple[str, ...] = eqx.field(static=True)
    names: tuple[str, ...] = eqx.field(static=True)
    joint_names: tuple[str, ...] = eqx.field(static=True)
    placement_rotation: Array
    placement_translation: Array
    axis: Array
    axis2: Array
    mass: Array
    com: Array
    inertia: Array
    gravity: Array
    lower: Array
    upper: Array
    velocity_limit: Array
    effort_limit: Array
    damping: Array
    stiffness: Array
    spring_reference: Array
    armature: Array
    friction: Array
    frame_names: tuple[str, ...] = eqx.field(static=True)
    frame_parents: tuple[int, ...] = eqx.field(static=True)
    frame_rotation: Array
    frame_translation: Array
    closures: tuple
    geoms: object

    def __init__(self, parents, joint_types, *, mass, inertia, com=None, axis=None, axis2=None,
                 placement_rotation=None, placement_translation=None,
                 gravity=(0.0, 0.0, -9.81), names=None, joint_names=None, lower=None,
                 upper=None, velocity_limit=None, effort_limit=None, damping=None,
                 stiffness=None, spring_reference=None, armature=None, friction=None,
                 frame_names=(), frame_parents=(), frame_rotation=None, frame_translation=None,
                 closures=(), geoms=None, strict: bool = False):
        self.closures = tuple(closures)
        if geoms is not None and not isinstance(geoms, Geoms):
            raise TypeError(f"geoms must be mbjax.model.Geoms or None, got {type(geoms).__name__}")
        self.geoms = geoms
        self.topology = parents if isinstance(parents, Topology) else Topology(parents)
        n = self.topology.n
        joint_types = (joint_types,) * n if isinstance(joint_types, str) else tuple(joint_types)
        if len(joint_types) != n:
            raise ValueError(f"{len(joint_types)} joint types for {n} bodies")
        for k, kind in enumerate(joint_types):
            if kind not in JOINT_TYPES:
                raise ValueError(f"body {k}: unknown joint type {kind!r}; choose from "
                                 f"{sorted(JOINT_TYPES)}")
        self.joint_types = joint_types
        digits = len(str(n - 1))     # zero-padded defaults sort like the body indices (URDF order)
        self.names = (tuple(names) if names is not None
                      else tuple(f"body{k:0{digits}d}" for k in range(n)))
        self.joint_names = (tuple(joint_names) if joint_names is not None
                            else tuple(f"joint{k:0{digits}d}" for k in range(n)))
        if len(self.names) != n or len(self.joint_names) != n:
            raise ValueError(f"{len(self.names)} names and {len(self.joint_names)} joint names "
                             f"for {n} bodies")

        def field(value, default, shape, what, unit_rows=False):
            # concrete data is shaped in NumPy (array operations outside jit would each compile
            # a program); traced data (a model built inside jax.grad or vmap) in JAX
            value = default if value is None else value
            xp = jnp if _traced(value) else np
            try:
                arr = xp.asarray(value, dtype=float)
            except (TypeError, ValueError) as error:
                raise TypeError(f"{what} must be real numbers of shape {shape}, got "
                                f"{value!r:.80}") from error
            if arr.shape != shape:
                arr = xp.broadcast_to(arr, shape) if arr.ndim < len(shape) else arr
            if arr.shape != shape:
                raise ValueError(f"{what} must have shape {shape}, got {np.shape(value)}")
            if unit_rows:           # a zero row is reported below, by name
                with np.errstate(invalid="ignore", divide="ignore"):
                    # scaled by the largest component first: |a|^2 overflows from 1.3e154
                    arr = arr / xp.max(xp.abs(arr), axis=-1, keepdims=True)
                    arr = arr / xp.linalg.norm(arr, axis=-1, keepdims=True)
            return jnp.asarray(arr, dtype=float)

        self.mass = field(mass, None, (n,), "mass")
        self.inertia = field(inertia, None, (n, 3, 3), "inertia")
        self.com = field(com, np.zeros((n, 3)), (n, 3), "com")
        self.axis = field(axis, np.tile([0.0, 0.0, 1.0], (n, 1)), (n, 3), "axis", unit_rows=True)
        self.axis2 = field(axis2, np.tile([0.0, 1.0, 0.0], (n, 1)), (n, 3), "axis2",
                           unit_rows=True)
        self.placement_rotation = field(placement_rotation, np.tile(np.eye(3), (n, 1, 1)),
                                        (n, 3, 3), "placement_rotation")
        self.placement_translation = field(placement_translation, np.zeros((n, 3)), (n, 3),
                                           "placement_translation")
        self.gravity = field(gravity, None, (3,), "gravity")
        nq, nv = _layout(joint_types)["nq"], _layout(joint_types)["nv"]
        inf = np.inf
        self.lower = field(lower, np.full(nq, -inf), (nq,), "lower")
        self.upper = field(upper, np.full(nq, inf), (nq,), "upper")
        self.velocity_limit = field(velocity_limit, np.full(nv, inf), (nv,), "velocity_limit")
        self.effort_limit = field(effort_limit, np.full(nv, inf), (nv,), "effort_limit")
        self.damping = field(damping, np.zeros(nv), (nv,), "damping")
        self.stiffness = field(stiffness, np.zeros(nv), (nv,), "stiffness")
        self.spring_reference = field(spring_reference, np.zeros(nq), (nq,), "spring_reference")
        self.armature = field(armature, np.zeros(nv), (nv,), "armature")
        self.friction = field(friction, np.zeros(nv), (nv,), "friction")
        self.frame_names, self.frame_parents = tuple(frame_names), tuple(int(k) for k in frame_parents)
        m = len(self.frame_names)
        if len(self.frame_parents) != m:
            raise ValueError(f"{m} frame names and {len(self.frame_parents)} frame parents")
        for name, k in zip(self.frame_names, self.frame_parents):
            if not -1 <= k < n:
                raise ValueError(f"frame {name!r}: parent body {k} is not in 0 ... {n - 1} or -1")
        self.frame_rotation = field(frame_rotation, np.tile(np.eye(3), (m, 1, 1)), (m, 3, 3),
                                    "frame_rotation")
        self.frame_translation = field(frame_translation, np.zeros((m, 3)), (m, 3),
                                       "frame_translation")
        for what, raw, uses in (("axis", axis, ("revolute", "prismatic", "universal")),
                                ("axis2", axis2, ("universal",))):
            if raw is not None and not isinstance(raw, jax.core.Tracer):
                norms = np.max(np.abs(np.broadcast_to(np.asarray(raw, float), (n, 3))), axis=-1)
                for k, kind in enumerate(joint_types):
                    if kind in uses and not norms[k] > 0:
                        raise ValueError(f"body {self.names[k]!r}: the {kind} joint's {what} is "
                                         f"zero (or not finite); give a nonzero direction")
        if not isinstance(self.placement_rotation, jax.core.Tracer):
            self._check_geometry()
        if not isinstance(self.mass, jax.core.Tracer):
            mass, inertia = np.asarray(self.mass), np.asarray(self.inertia)
            rotor = np.asarray(self.armature) > 0
            dof_body = self.dof_body()
            for k in range(n):
                check_body(float(mass[k]), inertia[k], f"body {self.names[k]!r}",
                           carries=bool(self.topology.distal(k)) or bool(rotor[dof_body == k].all()),
                           strict=strict)
        if not isinstance(self.lower, jax.core.Tracer):
            self._check_joint_data()

    def _check_geometry(self) -> None:
        """Finite placements, centres of mass, axes, frames and gravity; rotations that are
        rotations (orthonormal, det +1, to ROTATION_TOLERANCE); a universal joint's two axes
        not parallel (its motion subspace would lose a column)."""
        per_body = (("placement_rotation", self.names), ("placement_translation", self.names),
                    ("com", self.names), ("axis", self.names), ("axis2", self.names),
                    ("frame_rotation", self.frame_names), ("frame_translation", self.frame_names))
        for what, owners in per_body:
            value = np.asarray(getattr(self, what))
            if not value.size:
                continue
            bad = np.flatnonzero(~np.isfinite(value.reshape(len(value), -1)).all(-1))
            if bad.size:
                raise ValueError(f"{what} of {owners[bad[0]]!r} must be finite, got "
                                 f"{value[bad[0]].tolist()}")
        if not np.isfinite(np.asarray(self.gravity)).all():
            raise ValueError(f"gravity must be finite, got {np.asarray(self.gravity).tolist()}")
        for what, owners in (("placement_rotation", self.names),
                             ("frame_rotation", self.frame_names)):
            R = np.asarray(getattr(self, what))
            if not len(R):
                continue
            orthogonality = np.abs(np.swapaxes(R, -1, -2) @ R - np.eye(3)).max(axis=(-1, -2))
            det = np.linalg.det(R)
            bad = np.flatnonzero((orthogonality > ROTATION_TOLERANCE)
                                 | (np.abs(det - 1.0) > ROTATION_TOLERANCE))
            if bad.size:
                k = bad[0]
                kind = "a reflection (det -1)" if det[k] < 0 else "not orthonormal"
                raise ValueError(
                    f"{what} of {owners[k]!r} is {kind}: R^T R - I up to {orthogonality[k]:.2g}, "
                    f"det {det[k]:.6g}, for R = {R[k].tolist()}; give a rotation matrix (the "
                    f"polar factor U V^T of an SVD R = U S V^T is the nearest one)")
        axis, axis2 = np.asarray(self.axis), np.asarray(self.axis2)
        for k, kind in enumerate(self.joint_types):
            if kind == "universal" and np.linalg.norm(np.cross(axis[k], axis2[k])) < 1e-6:
                raise ValueError(f"body {self.names[k]!r}: the universal joint's axis "
                                 f"{axis[k].tolist()} and axis2 {axis2[k].tolist()} are parallel, "
                                 "so it turns about one axis only; give two independent axes "
                                 "(or a revolute joint)")

    def _check_joint_data(self) -> None:
        """Limits in order; limits non-negative (infinite: none); damping, armature and
        friction non-negative and finite. Errors name the joint of the offending coordinate."""
        layout = _layout(self.joint_types)

        def joint(index: int, starts) -> str:
            return repr(self.joint_names[int(np.searchsorted(starts, index, side="right")) - 1])

        lower, upper = np.asarray(self.lower), np.asarray(self.upper)
        bad = np.flatnonzero(~(lower <= upper))
        if bad.size:
            raise ValueError(f"lower must not exceed upper; joint {joint(bad[0], layout['q_start'])}"
                             f" (coordinate {bad[0]}): lower {lower[bad[0]]}, upper "
                             f"{upper[bad[0]]}")
        for what in ("velocity_limit", "effort_limit", "damping", "stiffness", "armature",
                     "friction"):
            value = np.asarray(getattr(self, what))
            infinite_allowed = what.endswith("limit")           # an infinite limit: none
            bad = np.flatnonzero(np.isnan(value) | (value < 0)
                                 | (np.isinf(value) & (not infinite_allowed)))
            if bad.size:
                raise ValueError(f"{what} must be non-negative"
                                 f"{'' if infinite_allowed else ' and finite'}; joint "
                                 f"{joint(bad[0], layout['v_start'])} (coordinate {bad[0]}) has "
                                 f"{value[bad[0]]}")

        index, sprung = self.spring_index(), np.asarray(self.stiffness) != 0
        bad = np.flatnonzero(sprung & (index < 0))
        if bad.size:
            raise ValueError(f"stiffness must be zero on spherical and free joints (their springs "
                             f"are not modelled); joint {joint(bad[0], layout['v_start'])} "
                             f"(coordinate {bad[0]}) has {np.asarray(self.stiffness)[bad[0]]}")

    # -- sizes and layout -----------------------------------------------------------------------

    @property
    def n(self) -> int:
        """The number of bodies."""
        return self.topology.n

    @property
    def n_frames(self) -> int:
        """Frames of the tree: its bodies (a flexible model adds markers)."""
        return self.topology.n

    @property
    def nq(self) -> int:
        """The number of configuration coordinates (a quaternion counts 4)."""
        return _layout(self.joint_types)["nq"]

    @property
    def nv(self) -> int:
        """The number of velocity coordinates (degrees of freedom)."""
        return _layout(self.joint_types)["nv"]

    @property
    def width(self) -> int:
        """Columns of the widest joint's motion subspace (1 for revolute/prismatic trees)."""
        return _layout(self.joint_types)["width"]

    def neutral(self) -> Array:
        """The zero configuration: zero angles and displacements, identity quaternions.

        Returns:
            q, shape (nq,).
        """
        return jnp.asarray([x for kind in self.joint_types for x in NEUTRAL[kind]], dtype=float)

    def home(self) -> Array:
        """A configuration inside every joint's limits: `neutral()`, with each coordinate whose
        zero lies outside [lower, upper] moved to the middle of its range (or onto its one finite
        bound), so that a simulation started there succeeds without a limit note.

        A robot's neutral configuration need not be a reachable one (the Panda's elbow, joint 4,
        ranges over [-3.07, -0.07] rad); Pinocchio's `neutral` is likewise the zero.

        Returns:
            q, shape (nq,).
        """
        q, lower, upper = self.neutral(), jnp.asarray(self.lower), jnp.asarray(self.upper)
        middle = jnp.where(jnp.isfinite(lower) & jnp.isfinite(upper), (lower + upper) / 2,
                           jnp.where(jnp.isfinite(lower), lower, upper))
        return jnp.where((q >= lower) & (q <= upper), q, middle)

    @property
    def v_mask(self) -> np.ndarray:
        """(n, width) static mask: which padded joint columns are real velocity coordinates."""
        return _layout(self.joint_types)["v_mask"]

    def quaternions(self) -> tuple[tuple[int, int, str], ...]:
        """Where q holds unit quaternions: (start, stop, "the quaternion of joint 'NAME'") for
        each spherical and free joint, in joint order."""
        starts = _layout(self.joint_types)["q_start"]
        return tuple((starts[k] + (3 if kind == "free" else 0),
                      starts[k] + (7 if kind == "free" else 4),
                      f"the quaternion of joint {self.joint_names[k]!r}")
                     for k, kind in enumerate(self.joint_types) if kind in ("spherical", "free"))

    def body_v(self, v: Array) -> Array:
        """The velocity coordinates grouped per body, zero-padded to the widest joint.

        Args:
            v: velocity-like coordinates, shape (nv, ...).

        Returns:
            Per-body rows, shape (n, width, ...).
        """
        layout, width = _layout(self.joint_types), self.width
        return _by_body(layout, [
            jnp.pad(take(v, own), [(0, 0), (0, width - own.shape[1])] + [(0, 0)] * (v.ndim - 1))
            for own in layout["v_own"].values()])

    def flat_v(self, per_body: Array) -> Array:
        """The inverse of `body_v`: per-body padded rows back to flat coordinates.

        Args:
            per_body: shape (n, width, ...).

        Returns:
            The flat coordinates, shape (nv, ...).
        """
        layout = _layout(self.joint_types)
        return _flat(layout, "v", per_body)

    def dof_body(self) -> np.ndarray:
        """The body each velocity coordinate belongs to.

        Returns:
            Body indices, a NumPy int array of shape (nv,).
        """
        return np.repeat(np.arange(self.n), [JOINT_TYPES[k].nv for k in self.joint_types])

    def spring_index(self) -> np.ndarray:
        """Where each velocity coordinate's spring reads its position: the position coordinate
        of a revolute, prismatic or universal joint's (whose q and v coordinates are the same),
        -1 on spherical and free joints (no spring).

        Returns:
            Indices into q, a NumPy int array of shape (nv,).
        """
        layout, index = _layout(self.joint_types), []
        for kind, iq in zip(self.joint_types, layout["q_start"]):
            nq, nv = JOINT_TYPES[kind]
            index += list(range(iq, iq + nq)) if nq == nv else [-1] * nv
        return np.asarray(index, dtype=int)

    def passive_force(self, q: Array, v: Array) -> Array:
        """The joints' passive forces, -damping * v - stiffness * (q - spring_reference).

        Args:
            q: configuration, shape (nq,).
            v: velocity, shape (nv,).

        Returns:
            Generalized forces, shape (nv,).
        """
        return -self.damping * v - self.stiffness * self.spring_stretch(q)

    def spring_stretch(self, q: Array) -> Array:
        """q - spring_reference at each velocity coordinate's position coordinate
        (`spring_index`; a spherical or free joint's entries, which have no stiffness, read
        its own first coordinates).

        Args:
            q: configuration, shape (nq,).

        Returns:
            The springs' stretches, shape (nv,).
        """
        return take(q - self.spring_reference, self._spring_gather())

    def _spring_gather(self) -> np.ndarray:
        """`spring_index` with a spherical or free joint's entries read from its own first
        coordinates (a run of consecutive indices, where stiffness is zero), so that `take`
        reads it as slices: no gather, and no scatter in its gradient."""
        layout, index = _layout(self.joint_types), self.spring_index()
        for kind, iq, iv in zip(self.joint_types, layout["q_start"], layout["v_start"]):
            nq, nv = JOINT_TYPES[kind]
            if nq != nv:
                index[iv:iv + nv] = np.arange(iq, iq + nv)
        return index

    # -- joints ---------------------------------------------------------------------------------

    def _per_type(self, fn, q: Array, *vs: Array):
        """Apply fn(kind, q_k, *v_k, axis_k, axis2_k) to every body, grouped by joint type so each
        type is one vmapped call (no Python loop over bodies). Each v in vs has length nv."""
        layout = _layout(self.joint_types)
        outs = [jax.vmap(lambda qk, a, a2, *vk, kind=kind: fn(kind, qk, *vk, a, a2))(
                    take(q, layout["q_own"][kind]), take(self.axis, idx), take(self.axis2, idx),
                    *[take(v, layout["v_own"][kind]) for v in vs])
                for kind, idx in layout["groups"].items()]
        return jax.tree.map(lambda *pieces: _by_body(layout, pieces), *outs)

    def joints(self, q: Array, v: Array):
        """Every joint's transform and motion subspace at (q, v).

        Args:
            q: configuration, shape (nq,).
            v: velocity, shape (nv,).

        Returns:
            R: body k's orientation in its proximal body's frame, shape (n, 3, 3).
            p: body k's origin in its proximal body's frame, shape (n, 3) [m].
            S: the motion subspaces in body coordinates, shape (n, 6, width).
            S_dot: their rates, shape (n, 6, width).
        """
        width = self.width
        R_J, p_J, S, S_dot = self._per_type(
            lambda kind, qk, vk, a, a2: joint_calc(kind, qk, vk, a, a2, width), q, v)
        R = self.placement_rotation @ R_J
        p = self.placement_translation + jnp.einsum("kij,kj->ki", self.placement_rotation, p_J)
        return R, p, S, S_dot

    def q_dot(self, q: Array, v: Array) -> Array:
        """The configuration's rate dq/dt for velocity v.

        Equal to v for revolute, prismatic and universal joints; the quaternion kinematics for
        spherical and free joints.

        Args:
            q: configuration, shape (nq,).
            v: velocity, shape (nv,).

        Returns:
            dq/dt, shape (nq,).
        """
        if self.euclidean:
            return v
        return self._flat_q(self._per_type(
            lambda kind, qk, vk, a, a2: self._pad_q(kind, joint_rate(kind, qk, vk)), q, v))

    @property
    def euclidean(self) -> bool:
        """Whether every joint's coordinates are Euclidean (revolute, prismatic, universal): then
        q_dot = v and retract(q0, xi) = q0 + xi, with no per-joint-type gathers and scatters."""
        return all(JOINT_TYPES[kind].nq == JOINT_TYPES[kind].nv for kind in self.joint_types)

    def integrate(self, q: Array, v: Array) -> Array:
        """q (+) v: the configuration reached from q by the velocity v in one unit of time.

        q + v for revolute, prismatic and universal joints; on the rotation group for spherical
        joints and on SE(3) for free joints (the body twist's exponential), equal to
        Pinocchio's `integrate` after `mbjax.model.state_to_pinocchio`. Differentiable, with
        finite derivatives at zero and half turns.

        Args:
            q: configuration, shape (nq,).
            v: tangent vector (a velocity times a time), shape (nv,).

        Returns:
            The configuration, shape (nq,).

        Raises:
            ValueError: q or v of another shape.
        """
        q, v = coordinates(self, q, "q"), coordinates(self, v, "v")
        if self.euclidean:
            return q + v
        return self._flat_q(self._per_type(
            lambda kind, qk, vk, a, a2: self._pad_q(kind, joint_integrate(kind, qk, vk)), q, v))

    def difference(self, q0: Array, q1: Array, *, wrap: bool = True) -> Array:
        """The tangent vector v with q0 (+) v = q1: `integrate`'s inverse.

        q1 - q0 for revolute, prismatic and universal joints; the body-frame rotation vector
        (|omega| <= pi) for quaternions and the SE(3) logarithm for free joints. With `wrap`,
        a revolute joint without limits (URDF continuous) has its difference wrapped to
        [-pi, pi), as Pinocchio's `difference` (its (cos, sin) coordinates do not count turns):
        then equal to Pinocchio's after the state converters. Without, it is the exact inverse
        of `integrate` in mbjax's coordinates, whose angles do count turns, and continuous
        along any path: what the systems' `difference` and so the trajectory optimisers'
        feedback and defects use.

        Args:
            q0: configuration, shape (nq,).
            q1: configuration, shape (nq,).
            wrap: wrap continuous joints' angle differences (static).

        Returns:
            v, shape (nv,).

        Raises:
            ValueError: q0 or q1 of another shape.
        """
        q0, q1 = coordinates(self, q0, "q0"), coordinates(self, q1, "q1")
        layout, width = _layout(self.joint_types), self.width
        continuous = (jnp.isinf(self.lower) & jnp.isinf(self.upper)) if wrap else \
            jnp.zeros(self.nq, bool)
        if self.euclidean:                       # q1 - q0, continuous angles wrapped
            d = q1 - q0
            if not wrap:
                return d
            revolute = np.zeros(self.nq, bool)
            for k in layout["groups"].get("revolute", ()):
                revolute[layout["q_start"][k]] = True
            return jnp.where(revolute & continuous, wrap_angle(d), d)
        pieces = []
        for kind, idx in layout["groups"].items():
            own = layout["q_own"][kind]
            d = jax.vmap(lambda a, b, c, kind=kind: joint_difference(kind, a, b, c))(
                take(q0, own), take(q1, own), take(continuous, own[:, 0]))
            pieces.append(jnp.pad(d, ((0, 0), (0, width - d.shape[1]))))
        return self.flat_v(_by_body(layout, pieces))

    def retract(self, q0: Array, xi: Array) -> Array:
        """The configuration at chart point xi about q0: `integrate(q0, xi)`, the chart that
        `local_rate` differentiates (what RKMK4 and the closed loops' projections step in).

        Args:
            q0: the chart's base configuration, shape (nq,).
            xi: the chart point, shape (nv,).

        Returns:
            The configuration, shape (nq,).
        """
        return self.integrate(q0, xi)

    def local_rate(self, q0: Array, xi: Array, v: Array) -> Array:
        """The chart coordinates' rate xi_dot at chart point xi about q0 for velocity v.

        Args:
            q0: the chart's base configuration, shape (nq,).
            xi: the chart point, shape (nv,).
            v: velocity, shape (nv,).

        Returns:
            xi_dot, shape (nv,).
        """
        if self.euclidean:
            return v
        width = self.width
        rates = self._per_type(
            lambda kind, qk, xk, vk, a, a2: jnp.pad(joint_local_rate(kind, qk, xk, vk),
                                                    (0, width - JOINT_TYPES[kind].nv)), q0, xi, v)
        return self.flat_v(rates)

    def _pad_q(self, kind: str, qk: Array) -> Array:
        return jnp.pad(qk, (0, _layout(self.joint_types)["q_width"] - qk.shape[0]))

    def _flat_q(self, per_body: Array) -> Array:
        return _flat(_layout(self.joint_types), "q", per_body)

    def normalize(self, q: Array) -> Array:
        """q with every quaternion scaled to unit length.

        Args:
            q: configuration, shape (nq,).

        Returns:
            The normalized configuration, shape (nq,).
        """
        layout = _layout(self.joint_types)
        starts = [layout["q_start"][k] + offset for kind, offset in (("spherical", 0), ("free", 3))
                  for k in layout["groups"].get(kind, ())]
        if not starts:
            return q
        idx = np.asarray(starts)[:, None] + np.arange(4)
        quats = take(q, idx)
        units = quats / jnp.linalg.norm(quats, axis=-1, keepdims=True)
        # q with the quaternions' entries read from the unit ones appended after it: a static
        # map (slices where it is a few runs), no scatter to keep a loop from one kernel
        source = np.arange(q.shape[0])
        source[idx.ravel()] = q.shape[0] + np.arange(idx.size)
        return take(jnp.concatenate([q, units.ravel()]), source)

    def locked(self, joint_names, q: Array) -> "Model":
        """The model with some joints fixed at q's values (Pinocchio's `buildReducedModel`).

        Each locked joint's body is merged into its parent (mass, centre of mass and inertia
        combined at the locked configuration, as a URDF's fixed joints are merged); the body
        and its frames stay as frames, its children hang from the parent, and the remaining
        joints keep their order, limits, damping and armature.

        Args:
            joint_names: names of the joints to lock, a sequence of strings.
            q: a configuration of this model, shape (nq,); the locked joints' values are read
                from it.

        Returns:
            The reduced `Model`.

        Raises:
            ValueError: an unknown joint name, a joint named twice, every joint locked, or q of
                the wrong shape.
        """
        return lock_joints(self, joint_names, q)

    def with_payload(self, mass, *, body: int | str, point=(0.0, 0.0, 0.0)) -> "Model":
        """The model with a point mass fixed to a body: a payload in a gripper.

        The body's mass, centre of mass and inertia about it are combined with the point mass's
        (parallel axes), differentiably in `mass` and `point`.

        Args:
            mass (ArrayLike): the payload's mass [kg], a scalar, zero or more.
            body: the body carrying it, an index or a name (`Model.names`).
            point (ArrayLike): where it sits in the body's frame, shape (3,) [m].

        Returns:
            The `Model` with the body's inertial data changed.

        Raises:
            ValueError: an unknown body, a point of the wrong shape, or a mass that is not a
                scalar or is negative.
        """
        if isinstance(body, str):
            if body not in self.names:
                raise ValueError(f"body must be one of the model's bodies {self.names}, got "
                                 f"{body!r}")
            body = self.names.index(body)
        if not (isinstance(body, int | np.integer) and -self.n <= body < self.n):
            raise ValueError(f"body must be a body index below {self.n} or a name, got {body!r}")
        mass, point = jnp.asarray(mass, dtype=float), jnp.asarray(point, dtype=float)
        if mass.shape != () or point.shape != (3,):
            raise ValueError(f"mass must be a scalar and point of shape (3,), got shapes "
                             f"{mass.shape} and {point.shape}")
        if not _traced(mass) and float(mass) < 0:
            raise ValueError(f"mass must not be negative, got {float(mass)}")
        m, c, J = self.mass[body], self.com[body], self.inertia[body]
        total = m + mass
        com = (m * c + mass * point) / total

        def shifted(mass, d):
            return mass * (d @ d * jnp.eye(3) - jnp.outer(d, d))

        inertia = J + shifted(m, c - com) + shifted(mass, point - com)
        return eqx.tree_at(lambda s: (s.mass, s.com, s.inertia), self,
                           (self.mass.at[body].set(total), self.com.at[body].set(com),
                            self.inertia.at[body].set(inertia)))

    def spatial_inertia(self) -> Array:
        """The spatial inertias about each body's origin, in body coordinates.

        Returns:
            Shape (n, 6, 6), angular rows first.
        """
        return inertia_matrix(self.mass, self.com, self.inertia)


def _by_body(layout: dict, pieces) -> Array:
    """Per-type arrays (one per joint type, leading axis that type's bodies) in body order."""
    if len(pieces) == 1:
        return pieces[0]
    return take(jnp.concatenate(pieces), layout["body_order"])


def _flat(layout: dict, which: str, per_body: Array) -> Array:
    """Per-body padded rows (n, width, ...) -> the flat coordinates (nq or nv, ...) they hold."""
    blocks = [take(per_body, idx)[:, :own.shape[1]].reshape(-1, *per_body.shape[2:])
              for idx, own in zip(layout["groups"].values(), layout[f"{which}_own"].values(),
                                  strict=True)]
    return take(jnp.concatenate(blocks), layout[f"{which}_order"])


# how far a given rotation matrix may be from orthonormal with det +1 (rounded source data)
ROTATION_TOLERANCE = 1e-6


def _traced(value) -> bool:
    """Whether value (an array, or nested lists of numbers and arrays) holds a tracer of jit,
    grad or vmap."""
    return any(isinstance(leaf, jax.core.Tracer) for leaf in jax.tree.leaves(value))


def coordinates(model: Model, x, name: str) -> Array:
    """x as a float array of shape (nq,) (a name starting with q) or (nv,) (any other: v, u, a
    tangent), or a ValueError naming the argument."""
    x = jnp.asarray(x, dtype=float)
    which = "nq" if name.startswith("q") else "nv"
    size = model.nq if which == "nq" else model.nv
    if x.shape != (size,):
        raise ValueError(f"{name} must have shape ({size},) ({which}) for this model (n = "
                         f"{model.n} bodies, nq = {model.nq}, nv = {model.nv}), got shape "
                         f"{x.shape}; use jax.vmap for batches")
    return x
