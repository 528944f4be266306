"""`load_mjcf` and `from_mujoco`: a `Model` from MJCF, read through MuJoCo's own compiler
(`load_mjcf`'s docstring gives the mapping)."""

import os
import warnings

import numpy as np

from mbjax._src.model.checks import ModelWarning, combine
from mbjax._src.model.closures import CutJoint, Spherical, Weld
from mbjax._src.model.geoms import DETECTED, Geoms
from mbjax._src.model.geoms import KINDS as GEOM_KINDS
from mbjax._src.model.joints import JOINT_TYPES
from mbjax._src.model.model import Model

# mjtJoint: FREE, BALL, SLIDE, HINGE
KINDS = ("free", "spherical", "prismatic", "revolute")
# mbjax's free-joint velocity (omega; v) in MuJoCo's dof order (v; omega)
_FREE_DOFS = (3, 4, 5, 0, 1, 2)


def _mujoco():
    try:
        import mujoco
    except ImportError as err:
        raise ImportError("load_mjcf compiles MJCF with MuJoCo, which is not installed: "
                          "pip install mujoco") from err
    return mujoco


def quat_matrix(quat) -> np.ndarray:
    """Rotation matrices of (..., 4) quaternions (w, x, y, z), normalized first."""
    q = np.asarray(quat, dtype=float)
    w, x, y, z = np.moveaxis(q / np.linalg.norm(q, axis=-1, keepdims=True), -1, 0)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1)], -2)


def _axis_rotation(axis, angle) -> np.ndarray:
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def object_name(mjmodel, kind: str, i: int) -> str:
    """The name of MuJoCo object i of `kind` ("body", "joint", "site"), or kind + index."""
    mujoco = _mujoco()
    obj = {"body": mujoco.mjtObj.mjOBJ_BODY, "joint": mujoco.mjtObj.mjOBJ_JOINT,
           "site": mujoco.mjtObj.mjOBJ_SITE, "geom": mujoco.mjtObj.mjOBJ_GEOM}[kind]
    return mujoco.mj_id2name(mjmodel, obj, i) or f"{kind}{i}"


def site_frame_name(model: Model, site: str) -> str:
    """The frame name `from_mujoco` gives a MuJoCo site."""
    return f"site/{site}" if f"site/{site}" in model.frame_names else site


def _actuator_joint_terms(m) -> tuple[np.ndarray, np.ndarray]:
    """Per joint: the armature and damping that actuators with a joint transmission add (MuJoCo
    >= 4, actuator_armature / actuator_damping, scaled by gear^2); zeros for older MuJoCo."""
    armature, damping = np.zeros(m.njnt), np.zeros(m.njnt)
    if not hasattr(m, "actuator_armature"):
        return armature, damping
    mujoco = _mujoco()
    joint_trn = (int(mujoco.mjtTrn.mjTRN_JOINT), int(mujoco.mjtTrn.mjTRN_JOINTINPARENT))
    gear = np.ravel(m.actuator_gear)
    for k in range(m.nu):
        if int(m.actuator_trntype[k]) in joint_trn:
            g = gear[6 * (m.actuator_outadr[k] if hasattr(m, "actuator_outadr") else k)]
            armature[m.actuator_trnid[k, 0]] += m.actuator_armature[k] * g**2
            damping[m.actuator_trnid[k, 0]] += m.actuator_damping[k] * g**2
    return armature, damping


def _nonzero(m, field: str) -> int:
    """Rows of mjModel array `field` with a nonzero entry (0 where this MuJoCo lacks it)."""
    value = getattr(m, field, None)
    if value is None or np.size(value) == 0:
        return 0
    return int(np.any(np.reshape(value, (np.shape(value)[0], -1)) != 0, axis=1).sum())


def _contact_pairs(m, filter_parent: bool) -> int:
    """Geom pairs that MuJoCo's broadphase may pass on (contype/conaffinity match, different
    rigid bodies, not both static, not parent and child), plus explicit <pair>s."""
    return len(_pair_list(m, filter_parent)) + int(m.npair)


def _pair_list(m, filter_parent: bool) -> list[tuple[int, int]]:
    """The geom pairs of `_contact_pairs` without the explicit <pair>s, less the <exclude>d
    body pairs."""
    if m.ngeom < 2:
        return []
    ct, ca = m.geom_contype, m.geom_conaffinity
    weld = m.body_weldid[m.geom_bodyid]
    parent = m.body_weldid[m.body_parentid[weld]]
    moving = m.body_dofnum[weld] > 0
    can = ((ct[:, None] & ca[None, :]) | (ca[:, None] & ct[None, :])) != 0
    can &= (weld[:, None] != weld[None, :]) & (moving[:, None] | moving[None, :])
    if filter_parent:
        related = (weld[:, None] == parent[None, :]) | (parent[:, None] == weld[None, :])
        can &= ~(related & (weld[:, None] != 0) & (weld[None, :] != 0))
    for signature in np.asarray(getattr(m, "exclude_signature", np.zeros(0)), dtype=np.int64):
        b1, b2 = int(signature) >> 16, int(signature) & 0xFFFF
        body = m.geom_bodyid
        can &= ~(((body[:, None] == b1) & (body[None, :] == b2))
                 | ((body[:, None] == b2) & (body[None, :] == b1)))
    return [(int(i), int(j)) for i, j in zip(*np.nonzero(np.triu(can, 1)), strict=True)]


# mjtGeom: the kinds mbjax detects
_GEOM_KINDS = {0: "plane", 2: "sphere", 3: "capsule", 4: "ellipsoid", 5: "cylinder", 6: "box"}


def _geoms(m, mujoco, where) -> tuple[Geoms | None, list[str]]:
    """The model's geoms that mbjax detects contacts of (planes, spheres, capsules,
    ellipsoids, cylinders, boxes), on the mbjax bodies that carry them, with the pairs MuJoCo's
    broadphase would pass on whose kinds are detected; and what is left out."""
    if not m.ngeom:
        return None, []
    filter_parent = not int(m.opt.disableflags) & int(mujoco.mjtDisableBit.mjDSBL_FILTERPARENT)
    kept = [g for g in range(m.ngeom) if int(m.geom_type[g]) in _GEOM_KINDS]
    index = {g: k for k, g in enumerate(kept)}
    rotation, position, bodies = [], [], []
    geom_quat = quat_matrix(m.geom_quat)
    for g in kept:
        k, R, p = where[int(m.geom_bodyid[g])]
        bodies.append(k)
        rotation.append(R @ geom_quat[g])
        position.append(p + R @ m.geom_pos[g])
    kind = {g: _GEOM_KINDS[int(m.geom_type[g])] for g in kept}
    pairs, undetected = [], {}
    for i, j in _pair_list(m, filter_parent):
        if i in index and j in index:
            kinds = tuple(sorted((kind[i], kind[j]), key=GEOM_KINDS.index))
            if kinds in DETECTED:
                pairs.append((index[i], index[j]))
            else:
                undetected[kinds] = undetected.get(kinds, 0) + 1
    left = [f"contacts between {a} and {b} geoms ({count} pairs; not detected)"
            for (a, b), count in sorted(undetected.items())]
    skipped = sorted({mujoco.mjtGeom(int(m.geom_type[g])).name[6:].lower()
                      for g in range(m.ngeom) if g not in index
                      and (m.geom_contype[g] or m.geom_conaffinity[g])})
    if skipped:
        left.append(f"contacts of {', '.join(skipped)} geoms (mbjax detects planes, spheres, "
                    f"capsules, ellipsoids, cylinders and boxes)")
    if m.npair:
        left.append(f"explicit contact pairs ({m.npair})")
    if not kept:
        return None, left
    names = [object_name(m, "geom", g) for g in kept]
    geoms = Geoms([_GEOM_KINDS[int(m.geom_type[g])] for g in kept], bodies,
                  np.asarray(m.geom_size)[kept], position=np.stack(position),
                  rotation=np.stack(rotation), friction=np.asarray(m.geom_friction)[kept],
                  solref=np.asarray(m.geom_solref)[kept], solimp=np.asarray(m.geom_solimp)[kept],
                  solmix=np.asarray(m.geom_solmix)[kept], margin=np.asarray(m.geom_margin)[kept],
                  gap=np.asarray(m.geom_gap)[kept],
                  condim=[int(m.geom_condim[g]) for g in kept],
                  names=names, pairs=pairs)
    return geoms, left


def _ignored(m, mujoco) -> list[str]:
    """What the compiled model uses that the mbjax Model does not represent."""
    disabled = int(m.opt.disableflags)
    off = lambda flag: bool(disabled & int(flag))  # noqa: E731
    bits = mujoco.mjtDisableBit
    out = []
    constraints = not off(bits.mjDSBL_CONSTRAINT)
    pairs = (_contact_pairs(m, not off(bits.mjDSBL_FILTERPARENT))
             if constraints and not off(bits.mjDSBL_CONTACT) else 0)
    if pairs:
        out.append(f"contacts in TreeSystem(model) ({pairs} geom pairs can collide; "
                   "mbjax.contact.ContactSystem(TreeSystem(model)) detects them)")
    if m.nu:
        out.append(f"actuator forces ({m.nu} actuators; apply them as tau)")
    if m.ntendon:
        out.append(f"tendons ({m.ntendon})")
    if not off(bits.mjDSBL_SPRING):
        scalar = np.isin(m.jnt_type, (int(mujoco.mjtJoint.mjJNT_HINGE),
                                      int(mujoco.mjtJoint.mjJNT_SLIDE)))
        if springs := int(np.sum((np.asarray(m.jnt_stiffness) != 0) & ~scalar)):
            out.append(f"springs on ball and free joints ({springs})")
        if poly := _nonzero(m, "jnt_stiffnesspoly"):
            out.append(f"polynomial joint springs ({poly})")
    if not off(bits.mjDSBL_DAMPER) and (poly := _nonzero(m, "dof_dampingpoly")
                                        + _nonzero(m, "actuator_dampingpoly")):
        out.append(f"polynomial damping ({poly})")
    if gravcomp := _nonzero(m, "body_gravcomp"):
        out.append(f"gravity compensation ({gravcomp} bodies)")
    if m.opt.density or m.opt.viscosity:
        out.append("fluid forces (density, viscosity)")
    if m.nflex:
        out.append(f"flexes ({m.nflex})")
    if m.nplugin:
        out.append(f"plugins ({m.nplugin})")
    ball_limits = int(np.sum(m.jnt_limited.astype(bool)
                             & (m.jnt_type == int(mujoco.mjtJoint.mjJNT_BALL))))
    if ball_limits:
        out.append(f"ball joint limits ({ball_limits})")
    other = int(np.sum(m.eq_active0.astype(bool)
                       & ~np.isin(m.eq_type, (int(mujoco.mjtEq.mjEQ_CONNECT),
                                              int(mujoco.mjtEq.mjEQ_WELD)))))
    if other and _equality_on(m, mujoco):
        out.append(f"joint, tendon, flex and distance equality constraints ({other})")
    return out


def from_mujoco(mjmodel, *, strict: bool = False) -> Model:
    """A `Model` from a compiled `mujoco.MjModel` (`load_mjcf` gives the mapping).

    The active connect and weld equality constraints are the model's `closures`
    (`mbjax.loops.CutJoint`s), for `mbjax.loops.ClosedSystem(TreeSystem(model), model.closures)`.
    What mbjax does not model is named in one `ModelWarning`.

    Args:
        mjmodel (mujoco.MjModel): the compiled `mujoco.MjModel`.
        strict: make implausible inertias errors (`mbjax.model.ModelWarning`), not the features
            mbjax leaves out.

    Returns:
        The `Model`; q and v follow MuJoCo's qpos and qvel (free joints' velocities convert
            with `mbjax.model.state_from_mujoco`).

    Raises:
        ImportError: MuJoCo is not installed.
        ValueError: a model without joints, or (strict=True) implausible inertial data.
    """
    mujoco = _mujoco()
    m = mjmodel
    if m.nv == 0:
        raise ValueError("the MuJoCo model has no joints: nothing moves, and an mbjax Model needs "
                         "at least one body")
    # where[b] = (mbjax body, R, p): MuJoCo body b's frame in that mbjax body's frame (-1: ground)
    where = {0: (-1, np.eye(3), np.zeros(3))}
    bodies, parts = [], []          # per mbjax body: its joint; its (mass, com, inertia) parts
    frames = []                     # (name, mbjax body, R, p)
    body_quat, iquat = quat_matrix(m.body_quat), quat_matrix(m.body_iquat)
    act_armature, act_damping = _actuator_joint_terms(m)
    for b in range(1, m.nbody):
        k, R, p = where[int(m.body_parentid[b])]
        R, p = R @ body_quat[b], p + R @ m.body_pos[b]
        name = object_name(m, "body", b)
        joints = range(m.body_jntadr[b], m.body_jntadr[b] + m.body_jntnum[b])
        for j in joints:
            kind = KINDS[m.jnt_type[j]]
            anchor = np.zeros(3) if kind == "free" else np.array(m.jnt_pos[j], dtype=float)
            axis = np.array(m.jnt_axis[j], dtype=float)
            R_place, p_place = (np.eye(3), np.zeros(3)) if kind == "free" else (R, p + R @ anchor)
            ref = m.qpos0[m.jnt_qposadr[j]]
            if kind == "revolute":                     # MuJoCo rotates by qpos - ref
                R_place = R_place @ _axis_rotation(axis / np.linalg.norm(axis), -ref)
            elif kind == "prismatic":
                p_place = p_place - ref * (R_place @ axis)
            joint_name = object_name(m, "joint", j)
            bodies.append(dict(parent=k, kind=kind, axis=axis, R=R_place, p=p_place, joint=j,
                               name=name if j == joints[-1] else f"{name}/{joint_name}",
                               joint_name=joint_name))
            parts.append([])
            k, R, p = len(bodies) - 1, np.eye(3), -anchor
        where[b] = (k, R, p)
        if k >= 0:
            J = iquat[b] @ np.diag(m.body_inertia[b]) @ iquat[b].T
            parts[k].append((float(m.body_mass[b]), p + R @ m.body_ipos[b], R @ J @ R.T))
        if not len(joints) or p.any():      # welded, or the last joint is off the body origin
            frames.append((name, k, R, p))
    taken = {*(body["name"] for body in bodies), *(body["joint_name"] for body in bodies),
             *(f[0] for f in frames)}
    site_quat = quat_matrix(m.site_quat) if m.nsite else np.zeros((0, 3, 3))
    for s in range(m.nsite):
        k, R, p = where[int(m.site_bodyid[s])]
        name = object_name(m, "site", s)
        frames.append((f"site/{name}" if name in taken else name, k, R @ site_quat[s],
                       p + R @ m.site_pos[s]))

    nq = m.nq
    lower, upper = np.full(nq, -np.inf), np.full(nq, np.inf)
    per_dof = {key: np.zeros(m.nv) for key in ("damping", "stiffness", "armature", "friction")}
    spring_reference = np.zeros(nq)
    effort = np.full(m.nv, np.inf)
    damper = not (int(m.opt.disableflags) & int(mujoco.mjtDisableBit.mjDSBL_DAMPER))
    spring = not (int(m.opt.disableflags) & int(mujoco.mjtDisableBit.mjDSBL_SPRING))
    iq = iv = free_armature = 0
    for body in bodies:
        j, kind = body["joint"], body["kind"]
        assert (m.jnt_qposadr[j], m.jnt_dofadr[j]) == (iq, iv), "bodies out of MuJoCo's order"
        nq_j, nv_j = JOINT_TYPES[kind]
        if kind in ("revolute", "prismatic") and m.jnt_limited[j]:
            lower[iq], upper[iq] = m.jnt_range[j]
        if kind in ("revolute", "prismatic") and spring:     # qfrc_spring, MuJoCo's passive.c
            per_dof["stiffness"][iv] = m.jnt_stiffness[j]
            spring_reference[iq] = m.qpos_spring[iq]
        dofs = iv + np.asarray(_FREE_DOFS if kind == "free" else range(nv_j))
        per_dof["damping"][iv:iv + nv_j] = (m.dof_damping[dofs] + act_damping[j]) * damper
        per_dof["armature"][iv:iv + nv_j] = m.dof_armature[dofs] + act_armature[j]
        if kind == "free" and per_dof["armature"][iv + 3:iv + 6].any():
            per_dof["armature"][iv + 3:iv + 6] = 0.0       # see load_mjcf's docstring
            free_armature += 1
        per_dof["friction"][iv:iv + nv_j] = m.dof_frictionloss[dofs]
        if m.jnt_actfrclimited[j]:
            effort[iv:iv + nv_j] = np.abs(m.jnt_actfrcrange[j]).max()
        iq, iv = iq + nq_j, iv + nv_j

    inertial = [combine(p) for p in parts]
    gravity = np.array(m.opt.gravity, dtype=float)
    if int(m.opt.disableflags) & int(mujoco.mjtDisableBit.mjDSBL_GRAVITY):
        gravity = np.zeros(3)
    cuts, connect_weld = _cut_joints(m, mujoco, where)
    geoms, left_out = _geoms(m, mujoco, where)
    ignored = _ignored(m, mujoco) + left_out
    if connect_weld:
        ignored.append(f"connect and weld equality constraints in TreeSystem(model) "
                       f"({connect_weld}; they are model.closures, which "
                       "mbjax.loops.ClosedSystem(TreeSystem(model), model.closures) enforces)")
    if free_armature:
        ignored.append(f"armature on free joints' translation ({free_armature})")
    if ignored:
        warnings.warn("from_mujoco: mbjax does not model, and ignored: " + "; ".join(ignored),
                      ModelWarning, stacklevel=2)
    model = Model(
        [body["parent"] for body in bodies], [body["kind"] for body in bodies],
        mass=[x[0] for x in inertial], com=np.stack([x[1] for x in inertial]),
        inertia=np.stack([x[2] for x in inertial]),
        axis=np.stack([body["axis"] if body["axis"].any() else np.array([0.0, 0.0, 1.0])
                       for body in bodies]),
        placement_rotation=np.stack([body["R"] for body in bodies]),
        placement_translation=np.stack([body["p"] for body in bodies]), gravity=gravity,
        names=[body["name"] for body in bodies],
        joint_names=[body["joint_name"] for body in bodies], lower=lower, upper=upper,
        effort_limit=effort, **per_dof, spring_reference=spring_reference,
        frame_names=[f[0] for f in frames],
        frame_parents=[f[1] for f in frames],
        frame_rotation=np.reshape([f[2] for f in frames], (-1, 3, 3)),
        frame_translation=np.reshape([f[3] for f in frames], (-1, 3)), closures=cuts,
        geoms=geoms, strict=strict)
    return model


def _equality_on(m, mujoco) -> bool:
    """Whether the model's options leave its equality constraints acting."""
    bits = mujoco.mjtDisableBit
    return not int(m.opt.disableflags) & int(bits.mjDSBL_CONSTRAINT | bits.mjDSBL_EQUALITY)


def _cut_joints(m, mujoco, where) -> tuple[list, int]:
    """The active connect and weld constraints as CutJoints, and how many there are (constraints
    within one rigid body, always satisfied or never, are left out)."""
    cuts, count = [], 0
    if not _equality_on(m, mujoco):
        return cuts, count
    site_quat = quat_matrix(m.site_quat) if m.nsite else None
    for i in range(m.neq):
        kind = {int(mujoco.mjtEq.mjEQ_CONNECT): "spherical",
                int(mujoco.mjtEq.mjEQ_WELD): "weld"}.get(int(m.eq_type[i]))
        if kind is None or not m.eq_active0[i]:
            continue
        count += 1
        data, ids = np.asarray(m.eq_data[i], dtype=float), (m.eq_obj1id[i], m.eq_obj2id[i])
        if int(m.eq_objtype[i]) == int(mujoco.mjtObj.mjOBJ_SITE):      # the two sites' frames
            ends = [(int(m.site_bodyid[s]), site_quat[s], m.site_pos[s]) for s in ids]
        elif kind == "spherical":          # body 1's point data[0:3] on body 2's data[3:6]
            ends = [(int(ids[0]), np.eye(3), data[0:3]), (int(ids[1]), np.eye(3), data[3:6])]
        else:    # body 1's frame at data[3:6] turned by the relpose quaternion data[6:10] on body
            #      2's frame at its anchor data[0:3] (MuJoCo's weld residual)
            ends = [(int(ids[0]), quat_matrix(data[6:10]), data[3:6]),
                    (int(ids[1]), np.eye(3), data[0:3])]
            if data[10] == 0:                                # torquescale 0: position only
                kind = "spherical"
        mapped = []
        for body, R_f, p_f in ends:
            k, R, p = where[body]
            mapped.append((k, R @ R_f, p + R @ p_f))
        (ka, Ra, pa), (kb, Rb, pb) = sorted(mapped, key=lambda e: e[0] < 0)   # ground second
        if ka == kb:
            continue
        cuts.append(CutJoint(Spherical() if kind == "spherical" else Weld(), ka, kb,
                             rotation_a=Ra, origin_a=pa, rotation_b=Rb, origin_b=pb))
    return cuts, count


def load_mjcf(source: str | os.PathLike, *, strict: bool = False) -> Model:
    """A `Model` from an MJCF file, compiled by MuJoCo (`pip install mujoco`).

    MuJoCo's compiler reads the file, and `from_mujoco` the compiled model, so q and v follow
    MuJoCo's qpos and qvel; the connect and weld equality constraints are the model's
    `closures`, and what mbjax does not model is named in one `ModelWarning`.

    Args:
        source (str | os.PathLike): a file path, or an XML string (one starting with '<').
        strict: make implausible inertias errors (not the features mbjax leaves out).

    Returns:
        The `Model` (`from_mujoco` of the compiled model).

    Raises:
        ImportError: MuJoCo is not installed.
        ValueError: MuJoCo's compiler rejects the file, a model without joints, or
            (strict=True) implausible inertial data.

    More on the compiler, the mapping, not modelled: the documentation site's Details page
    (docs/details.md).
    """
    mujoco = _mujoco()
    text = str(source)
    if not isinstance(source, os.PathLike) and text.lstrip().startswith("<"):
        mjmodel = mujoco.MjModel.from_xml_string(text)
    else:
        mjmodel = mujoco.MjModel.from_xml_path(text)
    return from_mujoco(mjmodel, strict=strict)
