"""`lock_joints`: a `Model` with some joints fixed at given values (Pinocchio's
`buildReducedModel`), behind `Model.locked`.

A locked joint welds its body to its parent at the joint's value in q: the body's pose in the
parent is its joint transform there (`Model.joints`). Its mass, centre of mass and inertia are
merged into the parent (parallel axes, `mbjax._src.model.checks.combine`, as `load_urdf` merges
links through fixed joints; into the ground, they vanish), its name and its joint's name become
frames of the parent at that pose, its own frames move to the parent with composed placements,
and its children hang from the parent with composed placements. Chains of locked joints collapse
into the nearest kept ancestor (or the ground). The kept bodies keep their relative order, which
is parent-before-child and Pinocchio's numbering of the reduced model, and their joints keep their
types, axes, names, limits, damping, springs, armature and friction (the kept coordinates' entries).

Geoms move with their bodies into the kept ones (a pair that ends up on one body is dropped).
Closures follow the bodies and coordinates: a `CutJoint`'s frames move with their bodies into the
kept ones; a `Coupling` or `Prescribed` motion is renumbered to the kept coordinates, and a
`Coupling` of two locked coordinates (a URDF mimic pair locked together) is dropped. One that
ties a kept coordinate to a locked one, drives a locked coordinate, or whose two frames end up
in one body (or frame A in the ground) is an error naming the joint.

This runs once, on concrete data, in NumPy (not inside jit).
"""

import jax.numpy as jnp
import numpy as np

from mbjax._src.model.checks import combine
from mbjax._src.model.closures import GROUND, Coupling, CutJoint, Prescribed
from mbjax._src.model.geoms import Geoms
from mbjax._src.model.joints import JOINT_TYPES


def _starts(model, size: str) -> np.ndarray:
    """Each joint's first coordinate in q ("nq") or v ("nv"), and the total, shape (n + 1,)."""
    return np.cumsum([0] + [getattr(JOINT_TYPES[k], size) for k in model.joint_types])


def lock_joints(model, joint_names, q):
    """The model with the named joints fixed at q's values (see the module).

    Args:
        model: the tree, with concrete (not traced) arrays.
        joint_names: names of the joints to lock, a sequence of strings (any joint type,
            free and spherical joints included).
        q: a configuration of `model`, shape (nq,); the locked joints' values are read from
            it (quaternions are normalized), the others are ignored.

    Returns:
        The reduced `Model`: the kept bodies in their original order, each locked body's name
        and joint name as frames of the body it is welded to, gravity unchanged.

    Raises:
        ValueError: a joint name that is not the model's, a joint named twice, every joint
            locked, q of the wrong shape or not finite, or a closure that the locking cannot
            keep (see the module).
    """
    if isinstance(joint_names, str):
        joint_names = (joint_names,)
    joint_names = list(joint_names)
    for name in joint_names:
        if name not in model.joint_names:
            raise ValueError(f"lock_joints: no joint named {name!r}; the model's joints are "
                             f"{', '.join(map(repr, model.joint_names))}")
    repeated = sorted({name for name in joint_names if joint_names.count(name) > 1})
    if repeated:
        raise ValueError(f"lock_joints: joint(s) {', '.join(map(repr, repeated))} named more "
                         "than once")
    n = model.n
    locked = np.zeros(n, bool)
    locked[[model.joint_names.index(name) for name in joint_names]] = True
    if locked.all():
        raise ValueError("lock_joints: every joint would be locked, leaving no body; keep at "
                         "least one joint")
    q = np.asarray(q, dtype=float)
    if q.shape != (model.nq,):
        raise ValueError(f"lock_joints: q must have shape ({model.nq},), got {q.shape}")
    if not np.isfinite(q).all():
        raise ValueError("lock_joints: q must be finite")

    # each body's frame in the frame of its host: itself if kept, else the nearest kept ancestor
    # (-1: the ground), as (host, R, p) with x_host = R x_body + p
    R_joint, p_joint, _, _ = model.joints(jnp.asarray(q), jnp.zeros(model.nv))
    R_joint, p_joint = np.asarray(R_joint), np.asarray(p_joint)
    R_place = np.asarray(model.placement_rotation)
    p_place = np.asarray(model.placement_translation)
    mass, com, inertia = (np.asarray(x) for x in (model.mass, model.com, model.inertia))
    kept = np.flatnonzero(~locked)
    new_index = np.full(n, -1)
    new_index[kept] = np.arange(len(kept))
    parents = model.topology.parents
    eye, zero = np.eye(3), np.zeros(3)
    host: list[tuple[int, np.ndarray, np.ndarray]] = []

    def in_host(body: int, R: np.ndarray, p: np.ndarray):
        """(host, R, p): the pose (R, p) given in `body`'s frame (-1: the ground), in its host's."""
        if body < 0:
            return -1, R, p
        h, R_h, p_h = host[body]
        return h, R_h @ R, p_h + R_h @ p

    new_parents, placement_R, placement_p = [], [], []
    parts = {int(k): [(float(mass[k]), com[k], inertia[k])] for k in kept}
    frames = []                                           # (name, new body, R, p)
    for k in range(n):
        if locked[k]:
            h, R, p = in_host(parents[k], R_joint[k], p_joint[k])
            host.append((h, R, p))
            if h >= 0:
                parts[int(kept[h])].append((float(mass[k]), R @ com[k] + p, R @ inertia[k] @ R.T))
            frames += [(name, h, R, p) for name in dict.fromkeys(
                (model.names[k], model.joint_names[k]))]
        else:
            host.append((int(new_index[k]), eye, zero))
            h, R, p = in_host(parents[k], R_place[k], p_place[k])
            new_parents.append(h)
            placement_R.append(R)
            placement_p.append(p)
    frame_R, frame_p = np.asarray(model.frame_rotation), np.asarray(model.frame_translation)
    old_frames = [(name, *in_host(f, frame_R[i], frame_p[i]))
                  for i, (name, f) in enumerate(zip(model.frame_names, model.frame_parents))]
    frames = old_frames + frames
    # a body that takes in no other keeps its data as it is (combine would reset the centre of
    # mass of a massless one)
    merged = [combine(parts[int(k)]) if len(parts[int(k)]) > 1 else parts[int(k)][0]
              for k in kept]

    q0, v0 = _starts(model, "nq"), _starts(model, "nv")
    q_kept = np.concatenate([np.arange(q0[k], q0[k + 1]) for k in kept])
    v_kept = np.concatenate([np.arange(v0[k], v0[k + 1]) for k in kept])

    def per(field: str, index: np.ndarray) -> np.ndarray:
        return np.asarray(getattr(model, field))[index]

    closures = tuple(c for c in (_remap(c, model, locked, host, new_index, q0, q_kept)
                                 for c in model.closures) if c is not None)
    geoms = model.geoms
    if geoms is not None:                   # each geom moves with its body into the host
        placed = [in_host(b, R, p) for b, R, p in zip(geoms.bodies, np.asarray(geoms.rotation),
                                                      np.asarray(geoms.position))]
        bodies = [h for h, _, _ in placed]
        geoms = Geoms(geoms.kinds, bodies, geoms.size, position=[p for _, _, p in placed],
                      rotation=[R for _, R, _ in placed], friction=geoms.friction,
                      solref=geoms.solref, solimp=geoms.solimp, solmix=geoms.solmix,
                      margin=geoms.margin, gap=geoms.gap, condim=geoms.condim, names=geoms.names,
                      pairs=[(i, j) for i, j in geoms.pairs if bodies[i] != bodies[j]
                             and not (bodies[i] < 0 and bodies[j] < 0)])
    return type(model)(               # the model's own class: this module imports no Model
        new_parents, [model.joint_types[k] for k in kept],
        mass=[m for m, _, _ in merged], com=[c for _, c, _ in merged],
        inertia=[J for _, _, J in merged], axis=per("axis", kept), axis2=per("axis2", kept),
        placement_rotation=np.reshape(placement_R, (-1, 3, 3)),
        placement_translation=np.reshape(placement_p, (-1, 3)), gravity=np.asarray(model.gravity),
        names=[model.names[k] for k in kept], joint_names=[model.joint_names[k] for k in kept],
        lower=per("lower", q_kept), upper=per("upper", q_kept),
        velocity_limit=per("velocity_limit", v_kept), effort_limit=per("effort_limit", v_kept),
        damping=per("damping", v_kept), stiffness=per("stiffness", v_kept),
        spring_reference=per("spring_reference", q_kept), armature=per("armature", v_kept),
        friction=per("friction", v_kept),
        frame_names=[f[0] for f in frames], frame_parents=[f[1] for f in frames],
        frame_rotation=np.reshape([f[2] for f in frames], (-1, 3, 3)),
        frame_translation=np.reshape([f[3] for f in frames], (-1, 3)), closures=closures,
        geoms=geoms)


def _remap(closure, model, locked: np.ndarray, host: list, new_index: np.ndarray,
           q0: np.ndarray, q_kept: np.ndarray):
    """The closure in the reduced model's bodies and coordinates (see the module)."""
    new_q = np.full(model.nq, -1)
    new_q[q_kept] = np.arange(len(q_kept))

    def coordinate(i: int) -> int:
        if not 0 <= i < model.nq:
            raise ValueError(f"lock_joints: the closure {type(closure).__name__} refers to "
                             f"coordinate {i}, but the model has {model.nq}")
        if new_q[i] < 0:
            joint = model.joint_names[int(np.searchsorted(q0, i, side="right")) - 1]
            raise ValueError(f"lock_joints: joint {joint!r} is locked, but the closure "
                             f"{type(closure).__name__} refers to its coordinate {i}; leave "
                             "the joint free or drop the closure")
        return int(new_q[i])

    if isinstance(closure, Coupling):
        if all(0 <= i < model.nq and new_q[i] < 0 for i in (closure.coordinate, closure.reference)):
            return None                   # both ends locked: it constrains nothing that moves
        return Coupling(coordinate(closure.coordinate), coordinate(closure.reference),
                        closure.multiplier, closure.offset)
    if isinstance(closure, Prescribed):
        return Prescribed(coordinate(closure.dof), closure.q0, closure.rate, closure.motion)
    if isinstance(closure, CutJoint):
        ends = []
        for body, R, p in ((closure.body_a, closure.rotation_a, closure.origin_a),
                           (closure.body_b, closure.rotation_b, closure.origin_b)):
            R, p = np.asarray(R), np.asarray(p)
            if body == GROUND:
                ends.append((GROUND, R, p))
            else:
                h, R_h, p_h = host[body]
                ends.append((h, R_h @ R, p_h + R_h @ p))
        (a, R_a, p_a), (b, R_b, p_b) = ends
        if a == b or a == GROUND:
            joints = [model.joint_names[k] for k in (closure.body_a, closure.body_b)
                      if k >= 0 and locked[k]]
            where = ("the ground" if a == GROUND
                     else f"body {model.names[int(np.flatnonzero(new_index == a)[0])]!r}")
            raise ValueError(f"lock_joints: locking joint(s) {', '.join(map(repr, joints))} "
                             f"puts both frames of a {closure.kind} cut joint in {where}; "
                             "leave the joint free or drop the closure")
        return CutJoint(closure.kind, a, b, origin_a=p_a, origin_b=p_b, rotation_a=R_a,
                        rotation_b=R_b)
    raise ValueError(f"lock_joints: cannot renumber a closure of type {type(closure).__name__} "
                     "for the reduced model; drop it before locking joints")
