"""`load_urdf`: a `Model` from a URDF file or string (its docstring gives the mapping)."""

import os
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import equinox as eqx
import numpy as np

from mbjax._src.model.checks import ModelWarning, combine, warn
from mbjax._src.model.closures import Coupling
from mbjax._src.model.joints import JOINT_TYPES
from mbjax._src.model.model import Model
from mbjax._src.model.siblings import AbstractSiblingOrder, ByName, check_sibling_order
from mbjax._src.model.urdf_geoms import collision_geoms

_KINDS = {"revolute": "revolute", "continuous": "revolute", "prismatic": "prismatic",
          "floating": "free", "fixed": None}


def _floats(text: str | None, count: int, what: str, default) -> np.ndarray:
    if text is None:
        return np.asarray(default, dtype=float)
    expected = "a number" if count == 1 else f"{count} numbers"
    try:
        values = np.array([float(x) for x in text.split()])
    except ValueError:
        raise ValueError(f"URDF: {what} must be {expected}, got {text!r}") from None
    if values.shape != (count,):
        raise ValueError(f"URDF: {what} must be {expected}, got {text!r}")
    if not np.all(np.isfinite(values)):
        raise ValueError(f"URDF: {what} must be finite, got {text!r}")
    return values


def _attribute(element, key: str, what: str, default: float) -> float:
    """A numeric attribute (infinite values allowed: they mean "no limit")."""
    text = element.get(key) if element is not None else None
    if text is None:
        return default
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"URDF: {what} {key} must be a number, got {text!r}") from None
    if np.isnan(value):
        raise ValueError(f"URDF: {what} {key} is NaN")
    return value


def rpy_matrix(rpy) -> np.ndarray:
    """URDF's fixed-axis roll-pitch-yaw: R = Rz(yaw) Ry(pitch) Rx(roll)."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def _origin(element, what: str) -> tuple[np.ndarray, np.ndarray]:
    origin = element.find("origin") if element is not None else None
    if origin is None:
        return np.eye(3), np.zeros(3)
    xyz = _floats(origin.get("xyz"), 3, f"{what} origin xyz", np.zeros(3))
    rpy = _floats(origin.get("rpy"), 3, f"{what} origin rpy", np.zeros(3))
    return rpy_matrix(rpy), xyz


def _inertial(link) -> tuple[float, np.ndarray, np.ndarray]:
    """(mass, centre of mass, inertia about it) in the link frame; a link without <inertial> is
    massless. Plausibility is checked later, on the merged bodies."""
    name = link.get("name")
    inertial = link.find("inertial")
    if inertial is None:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    mass_el, inertia_el = inertial.find("mass"), inertial.find("inertia")
    if mass_el is None or mass_el.get("value") is None:
        raise ValueError(f"URDF: link {name!r} has <inertial> without <mass value=...>")
    mass = _floats(mass_el.get("value"), 1, f"link {name!r} mass", None)[0]
    if inertia_el is None:
        raise ValueError(f"URDF: link {name!r} has <inertial> without <inertia>")
    i = {k: _floats(inertia_el.get(k, "0"), 1, f"link {name!r} inertia {k}", None)[0]
         for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
    J = np.array([[i["ixx"], i["ixy"], i["ixz"]],
                  [i["ixy"], i["iyy"], i["iyz"]],
                  [i["ixz"], i["iyz"], i["izz"]]])
    R, xyz = _origin(inertial, f"link {name!r} inertial")
    return float(mass), xyz, R @ J @ R.T


def _bounded(inertial, min_mass: float, min_inertia: float):
    """MuJoCo's boundmass and boundinertia: mass and principal moments raised to the bounds."""
    m, c, J = inertial
    if min_inertia > 0:
        moments, axes = np.linalg.eigh(J)
        J = axes @ np.diag(np.maximum(moments, min_inertia)) @ axes.T
    return (max(m, min_mass) if min_mass > 0 else m), c, J


def _read(text: str):
    try:
        robot = ET.fromstring(text)
    except ET.ParseError as err:
        raise ValueError(f"URDF: malformed XML ({err})") from None
    if robot.tag != "robot":
        raise ValueError(f"URDF: the root element must be <robot>, got <{robot.tag}>")
    return robot


def _armature(armature, nv: int) -> np.ndarray:
    """armature as one value per velocity coordinate, or an error naming it."""
    value = np.asarray(armature, float)
    if value.shape not in ((), (nv,)):
        raise ValueError(f"armature must be a number or one per velocity coordinate, shape "
                         f"({nv},), got shape {value.shape}")
    return np.broadcast_to(value, (nv,))


def load_urdf(source: str | bytes | os.PathLike, *, floating_base: bool = False,
              gravity=(0.0, 0.0, -9.81), sibling_order: AbstractSiblingOrder = ByName(), armature=0.0,
              min_mass: float = 0.0, min_inertia: float = 0.0, package_dirs=(),
              strict: bool = False) -> Model:
    """A `Model` from a URDF file or XML string.

    Links with an `<inertial>` become bodies, numbered depth-first from the root as Pinocchio
    numbers its joints, so q and v line up with Pinocchio's; fixed joints merge their child links
    into their parents. The mimic joints' couplings are the model's `closures` (`mbjax.loops.Coupling`s),
    empty without mimic joints.

    Args:
        source: a path, or an XML string (a string starting with '<' is read as XML).
        floating_base: add a free joint above the root link (else it is welded to the ground).
        gravity (Array): gravitational acceleration in the world frame [m/s^2], shape (3,).
        sibling_order: the order the children of a link are numbered in: `ByName()`
            (Pinocchio's numbering, the default) or `InDocument()` (MuJoCo's; see The mapping in
            docs/details.md).
        armature (float | Array): rotor inertia on every joint coordinate [kg m^2 or kg], a
            number or an (nv,) array.
        min_mass: lower bound on every body's mass [kg] (MuJoCo's boundmass), a remedy for
            massless leaves on moving joints.
        min_inertia: lower bound on every body's principal moments [kg m^2] (MuJoCo's
            boundinertia).
        package_dirs (Sequence[str | os.PathLike]): folders where `package://NAME/...` collision
            meshes are looked for (`NAME/...` or `...` under each); the folder named NAME above
            the URDF file is looked in too.
        strict: turn the warnings on implausible data into errors (not the note on mimic
            joints).

    Returns:
        The `Model`, bodies numbered depth-first from the root.

    Raises:
        FileNotFoundError: a path that is not a file.
        ValueError: malformed XML or numbers, an unsupported joint type, a graph that is not a
            tree, no movable joint, or (strict=True) implausible inertial data.
        TypeError: sibling_order is not `ByName()` or `InDocument()` (a string, say).

    More on the mapping, inertial data, joint data, collision geometry: the documentation site's
    Details page (docs/details.md).
    """
    sibling_order = check_sibling_order(sibling_order)
    text, path = source.decode() if isinstance(source, bytes) else str(source), None
    if isinstance(source, os.PathLike) or not text.lstrip().startswith("<"):
        path = Path(source)
        if not path.is_file():
            raise FileNotFoundError(f"URDF file not found: {path}")
        text = path.read_text()
    robot = _read(text)

    links = {}
    for link in robot.findall("link"):
        name = link.get("name")
        if not name:
            raise ValueError("URDF: a <link> has no name")
        if name in links:
            raise ValueError(f"URDF: link {name!r} is defined twice")
        links[name] = _inertial(link)
    children: dict[str, list] = {name: [] for name in links}
    has_parent: dict[str, str] = {}
    joint_names = set()
    for joint in robot.findall("joint"):
        name, kind = joint.get("name"), joint.get("type")
        if not name:
            raise ValueError("URDF: a <joint> has no name")
        if name in joint_names:
            raise ValueError(f"URDF: joint {name!r} is defined twice")
        joint_names.add(name)
        if kind not in _KINDS:
            raise ValueError(f"URDF: joint {name!r} has unknown or unsupported type {kind!r}; "
                             f"supported: {sorted(_KINDS)}")
        parent, child = joint.find("parent"), joint.find("child")
        if parent is None or child is None:
            raise ValueError(f"URDF: joint {name!r} needs <parent link=...> and <child link=...>")
        parent, child = parent.get("link"), child.get("link")
        for link in (parent, child):
            if link not in links:
                raise ValueError(f"URDF: joint {name!r} refers to undefined link {link!r}")
        if child in has_parent:
            raise ValueError(f"URDF: link {child!r} is the child of two joints "
                             f"({has_parent[child]!r} and {name!r}): a URDF must be a tree")
        has_parent[child] = name
        children[parent].append(joint)
    children = {link: sibling_order.order(joints) for link, joints in children.items()}
    if not links:
        raise ValueError("URDF: the robot has no links")
    roots = [name for name in links if name not in has_parent]
    if len(roots) != 1:
        raise ValueError(f"URDF: expected exactly one root link, found {roots or 'none (a cycle)'}")

    bodies = []    # dicts: parent index, kind, joint/link names, placement, axis, inertial, data
    frames = []    # (name, body, R, p): links merged through fixed joints, and those joints
    where = {}     # each link's (body, R, p) in the frame of the body it is part of

    def visit(link: str, body: int, R_acc: np.ndarray, p_acc: np.ndarray) -> None:
        """Walk the joints below `link`, which sits at (R_acc, p_acc) in body `body`'s frame."""
        for joint in children[link]:
            name = joint.get("name")
            R, p = _origin(joint, f"joint {name!r}")
            R_place, p_place = R_acc @ R, p_acc + R_acc @ p
            child = joint.find("child").get("link")
            kind = _KINDS[joint.get("type")]
            if kind is None:                             # fixed: merge into `body`
                m, c, J = links[child]
                if body >= 0 and (m > 0 or J.any()):
                    target = bodies[body]
                    target["inertial"] = combine([target["inertial"],
                                                  (m, R_place @ c + p_place, R_place @ J @ R_place.T)])
                frames.extend([(child, body, R_place, p_place), (name, body, R_place, p_place)])
                where[child] = (body, R_place, p_place)
                visit(child, body, R_place, p_place)
                continue
            what = f"joint {name!r}"
            axis = _floats(joint.find("axis").get("xyz") if joint.find("axis") is not None
                           else None, 3, f"{what} axis", [1.0, 0.0, 0.0])
            if kind != "free" and not np.max(np.abs(axis)) > 0:
                raise ValueError(f"URDF: joint {name!r} has a zero axis")
            limit, dynamics = joint.find("limit"), joint.find("dynamics")
            bounded = joint.get("type") in ("revolute", "prismatic")
            if bounded and limit is None:
                # the specification requires <limit> here (its lower and upper default to 0);
                # without it, no position limits, as MuJoCo's URDF import reads the joint
                warn(f"URDF: {what} ({joint.get('type')}) has no <limit>, which the URDF "
                     "specification requires; it loads without position limits", strict)
                bounded = False
            bodies.append(dict(
                parent=body, kind=kind, joint=name, link=child, R=R_place, p=p_place, axis=axis,
                inertial=links[child], mimic=joint.find("mimic"),
                lower=_attribute(limit, "lower", what, 0.0) if bounded else -np.inf,
                upper=_attribute(limit, "upper", what, 0.0) if bounded else np.inf,
                effort=abs(_attribute(limit, "effort", what, np.inf)) or np.inf,
                velocity=abs(_attribute(limit, "velocity", what, np.inf)) or np.inf,
                damping=_attribute(dynamics, "damping", what, 0.0),
                friction=_attribute(dynamics, "friction", what, 0.0)))
            where[child] = (len(bodies) - 1, np.eye(3), np.zeros(3))
            visit(child, len(bodies) - 1, np.eye(3), np.zeros(3))

    root = roots[0]
    if floating_base:
        bodies.append(dict(parent=-1, kind="free", joint="root_joint", link=root, R=np.eye(3),
                           p=np.zeros(3), axis=np.array([1.0, 0.0, 0.0]), inertial=links[root],
                           mimic=None, lower=-np.inf, upper=np.inf, effort=np.inf,
                           velocity=np.inf, damping=0.0, friction=0.0))
        where[root] = (0, np.eye(3), np.zeros(3))
        visit(root, 0, np.eye(3), np.zeros(3))
    else:
        frames.append((root, -1, np.eye(3), np.zeros(3)))
        where[root] = (-1, np.eye(3), np.zeros(3))
        visit(root, -1, np.eye(3), np.zeros(3))
    if not bodies:
        raise ValueError("URDF: no movable joint; the model would have no degrees of freedom "
                         "(load a single free-flying body with floating_base=True)")

    def per_coordinate(key: str, size: str) -> np.ndarray:
        return np.concatenate([np.full(getattr(JOINT_TYPES[b["kind"]], size), b[key])
                               for b in bodies])

    inertials = [_bounded(b["inertial"], min_mass, min_inertia) for b in bodies]
    model = Model(
        [b["parent"] for b in bodies], [b["kind"] for b in bodies],
        mass=[m for m, _, _ in inertials], com=[c for _, c, _ in inertials],
        inertia=[J for _, _, J in inertials], axis=[b["axis"] for b in bodies],
        placement_rotation=[b["R"] for b in bodies],
        placement_translation=[b["p"] for b in bodies], gravity=gravity,
        names=[b["link"] for b in bodies], joint_names=[b["joint"] for b in bodies],
        lower=per_coordinate("lower", "nq"), upper=per_coordinate("upper", "nq"),
        effort_limit=per_coordinate("effort", "nv"),
        velocity_limit=per_coordinate("velocity", "nv"),
        damping=per_coordinate("damping", "nv"), friction=per_coordinate("friction", "nv"),
        armature=_armature(armature, sum(JOINT_TYPES[b["kind"]].nv for b in bodies)),
        frame_names=[f[0] for f in frames], frame_parents=[f[1] for f in frames],
        frame_rotation=np.reshape([f[2] for f in frames], (-1, 3, 3)),
        frame_translation=np.reshape([f[3] for f in frames], (-1, 3)), strict=strict)
    base = None if path is None else path.resolve().parent
    geoms, notes = collision_geoms(robot, where, base, tuple(package_dirs), _floats, _origin)
    if notes:
        warnings.warn("load_urdf: " + "; ".join(notes), ModelWarning, stacklevel=2)
    return eqx.tree_at(lambda m: (m.closures, m.geoms), model,
                       (tuple(_mimics(model, bodies)), geoms), is_leaf=lambda x: x is None)


def _mimics(model: Model, bodies: list) -> list:
    """The mimic joints' couplings q = multiplier q_reference + offset."""
    q_start = dict(zip(model.joint_names, _q_starts(model), strict=True))
    out, names = [], []
    for b in bodies:
        mimic = b["mimic"]
        if mimic is None:
            continue
        reference = mimic.get("joint")
        if reference not in q_start:
            names.append(f"{b['joint']} mimics {reference!r}, which is not a moving joint of "
                         "the model: no coupling")
            continue
        what = f"joint {b['joint']!r} mimic"
        out.append(Coupling(q_start[b["joint"]], q_start[reference],
                            _attribute(mimic, "multiplier", what, 1.0),
                            _attribute(mimic, "offset", what, 0.0)))
        names.append(f"{b['joint']} = {out[-1].multiplier} {reference} + {out[-1].offset}")
    if names:
        warn(f"URDF: mimic joints ({'; '.join(names)}): TreeSystem(model) moves them as "
             "independent joints, as Pinocchio and MuJoCo load them; the couplings are "
             "model.closures, for mbjax.loops.ClosedSystem(TreeSystem(model), model.closures)",
             strict=False)
    return out


def _q_starts(model: Model) -> list[int]:
    return list(np.cumsum([0] + [JOINT_TYPES[k].nq for k in model.joint_types])[:-1])


def matrix_rpy(R: np.ndarray) -> np.ndarray:
    """Inverse of `rpy_matrix` (away from pitch = +-pi/2)."""
    return np.array([np.arctan2(R[2, 1], R[2, 2]), -np.arcsin(np.clip(R[2, 0], -1, 1)),
                     np.arctan2(R[1, 0], R[0, 0])])


def to_urdf(model: Model, name: str = "mbjax") -> str:
    """The URDF of a revolute/prismatic/free tree (for loading the same model into Pinocchio or
    MuJoCo).

    Link k is `model.names[k]`; the ground link is `base`. Limits, damping and friction are
    written; a joint without limits gets wide ones (+-1e3), so that the peers keep one angle
    per revolute joint (a URDF continuous joint is (cos, sin) in Pinocchio). Armature, named
    frames and closures have no URDF field and are not written.

    Args:
        model: the tree.
        name: the robot's name.

    Returns:
        The URDF document, a string.

    Raises:
        ValueError: a joint other than revolute, prismatic or free.
    """
    kinds = {"revolute": "revolute", "prismatic": "prismatic", "free": "floating"}
    for kind in model.joint_types:
        if kind not in kinds:
            raise ValueError(f"to_urdf: a {kind!r} joint has no URDF counterpart")

    def fmt(values) -> str:
        return " ".join(repr(float(x)) for x in values)

    lower, upper, effort, velocity, damping, friction = (np.asarray(x) for x in (
        model.lower, model.upper, model.effort_limit, model.velocity_limit, model.damping,
        model.friction))
    starts = list(zip(_q_starts(model), np.cumsum([0] + [JOINT_TYPES[t].nv
                                                         for t in model.joint_types])[:-1],
                      strict=True))
    lines = [f'<robot name="{name}">', '  <link name="base"/>']
    for k in range(model.n):
        J = np.asarray(model.inertia[k]).astype(float).tolist()
        lines += [f'  <link name="{model.names[k]}">', "    <inertial>",
                  f'      <origin xyz="{fmt(model.com[k])}" rpy="0 0 0"/>',
                  f'      <mass value="{float(model.mass[k])!r}"/>',
                  f'      <inertia ixx="{J[0][0]!r}" ixy="{J[0][1]!r}" ixz="{J[0][2]!r}" '
                  f'iyy="{J[1][1]!r}" iyz="{J[1][2]!r}" izz="{J[2][2]!r}"/>',
                  "    </inertial>", "  </link>"]
        parent = "base" if model.topology.parents[k] < 0 else model.names[model.topology.parents[k]]
        R = np.asarray(model.placement_rotation[k])
        lines += [f'  <joint name="{model.joint_names[k]}" type="{kinds[model.joint_types[k]]}">',
                  f'    <parent link="{parent}"/>', f'    <child link="{model.names[k]}"/>',
                  f'    <origin xyz="{fmt(model.placement_translation[k])}" '
                  f'rpy="{fmt(matrix_rpy(R))}"/>',
                  f'    <axis xyz="{fmt(model.axis[k])}"/>']
        if model.joint_types[k] in ("revolute", "prismatic"):
            iq, iv = starts[k]
            bound = lambda x, wide: repr(float(x)) if np.isfinite(x) else wide  # noqa: E731
            lines.append(f'    <limit lower="{bound(lower[iq], "-1e3")}" '
                         f'upper="{bound(upper[iq], "1e3")}" '
                         f'effort="{bound(effort[iv], "1e6")}" '
                         f'velocity="{bound(velocity[iv], "1e6")}"/>')
            if damping[iv] or friction[iv]:
                lines.append(f'    <dynamics damping="{float(damping[iv])!r}" '
                             f'friction="{float(friction[iv])!r}"/>')
        lines.append("  </joint>")
    lines.append("</robot>")
    return "\n".join(lines) + "\n"
