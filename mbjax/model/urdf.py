"""`load_urdf`: a `Model` from a URDF file or string.

Links with <inertial> become bodies; revolute and continuous joints become revolute joints,
prismatic joints prismatic ones and floating joints free joints; a fixed joint merges its child
link (mass, centre of mass and inertia, and the placements of the joints beyond it) into the
parent body. The root link is welded to the ground unless `floating_base=True` adds a free joint.
Bodies are numbered depth-first from the root, as Pinocchio numbers its joints, so q and v line
up with Pinocchio's. Pinocchio (through urdfdom, which keeps joints in a name-sorted map) visits
the children of a link in order of joint name; that is the default here. `sibling_order=
"document"` visits them in document order instead (the two agree when sibling joint names sort
in document order, as `to_urdf`'s zero-padded defaults do).
"""

import os
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from mbjax.model.model import Model
from mbjax.spatial import check_inertia

_KINDS = {"revolute": "revolute", "continuous": "revolute", "prismatic": "prismatic",
          "floating": "free", "fixed": None}


def _floats(text: str | None, count: int, what: str, default) -> np.ndarray:
    if text is None:
        return np.asarray(default, dtype=float)
    try:
        values = np.array([float(x) for x in text.split()])
    except ValueError:
        raise ValueError(f"URDF: {what} must be {count} numbers, got {text!r}") from None
    if values.shape != (count,):
        raise ValueError(f"URDF: {what} must be {count} numbers, got {text!r}")
    return values


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
    massless."""
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
    try:
        i = {k: float(inertia_el.get(k, "0")) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
    except ValueError:
        raise ValueError(f"URDF: link {name!r} has a non-numeric inertia entry") from None
    J = np.array([[i["ixx"], i["ixy"], i["ixz"]],
                  [i["ixy"], i["iyy"], i["iyz"]],
                  [i["ixz"], i["iyz"], i["izz"]]])
    R, xyz = _origin(inertial, f"link {name!r} inertial")
    if mass < 0 or (mass == 0 and J.any()):
        raise ValueError(f"URDF: link {name!r} has mass {mass}: it must be positive")
    if mass > 0:
        check_inertia(J, f"URDF link {name!r}")
    return float(mass), xyz, R @ J @ R.T


def _merge(a, b):
    """Two (mass, com, inertia about com) in one frame combined (parallel-axis theorem)."""
    (ma, ca, Ja), (mb, cb, Jb) = a, b
    m = ma + mb
    if m == 0:
        return a
    c = (ma * ca + mb * cb) / m

    def shifted(mass, com, J):
        d = com - c
        return J + mass * (d @ d * np.eye(3) - np.outer(d, d))
    return m, c, shifted(ma, ca, Ja) + shifted(mb, cb, Jb)


def load_urdf(source: str | os.PathLike, *, floating_base: bool = False,
              gravity=(0.0, 0.0, -9.81), sibling_order: str = "name") -> Model:
    """A Model from a URDF path or XML string (a string starting with '<' is read as XML).

    sibling_order: "name" (Pinocchio's numbering) or "document" (see the module docstring).
    """
    if sibling_order not in ("name", "document"):
        raise ValueError(f"sibling_order must be 'name' or 'document', got {sibling_order!r}")
    text = str(source)
    if isinstance(source, os.PathLike) or not text.lstrip().startswith("<"):
        path = Path(source)
        if not path.is_file():
            raise FileNotFoundError(f"URDF file not found: {path}")
        text = path.read_text()
    try:
        robot = ET.fromstring(text)
    except ET.ParseError as err:
        raise ValueError(f"URDF: malformed XML ({err})") from None
    if robot.tag != "robot":
        raise ValueError(f"URDF: the root element must be <robot>, got <{robot.tag}>")

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
    if sibling_order == "name":
        children = {link: sorted(joints, key=lambda j: j.get("name"))
                    for link, joints in children.items()}
    roots = [name for name in links if name not in has_parent]
    if len(roots) != 1:
        raise ValueError(f"URDF: expected exactly one root link, found {roots or 'none (a cycle)'}")

    bodies = []    # dicts: parent index, kind, joint/link names, placement, axis, inertial

    def visit(link: str, body: int, R_acc: np.ndarray, p_acc: np.ndarray) -> None:
        """Walk the joints below `link`, which sits at (R_acc, p_acc) in body `body`'s frame."""
        for joint in children[link]:
            R, p = _origin(joint, f"joint {joint.get('name')!r}")
            R_place, p_place = R_acc @ R, p_acc + R_acc @ p
            child = joint.find("child").get("link")
            kind = _KINDS[joint.get("type")]
            if kind is None:                             # fixed: merge into `body`
                m, c, J = links[child]
                if body >= 0 and m > 0:
                    target = bodies[body]
                    target["inertial"] = _merge(target["inertial"],
                                                (m, R_place @ c + p_place, R_place @ J @ R_place.T))
                visit(child, body, R_place, p_place)
                continue
            axis = _floats(joint.find("axis").get("xyz") if joint.find("axis") is not None
                           else None, 3, f"joint {joint.get('name')!r} axis", [1.0, 0.0, 0.0])
            if kind != "free" and not np.linalg.norm(axis) > 0:
                raise ValueError(f"URDF: joint {joint.get('name')!r} has a zero axis")
            bodies.append(dict(parent=body, kind=kind, joint=joint.get("name"), link=child,
                               R=R_place, p=p_place, axis=axis, inertial=links[child]))
            visit(child, len(bodies) - 1, np.eye(3), np.zeros(3))

    root = roots[0]
    if floating_base:
        bodies.append(dict(parent=-1, kind="free", joint="root_joint", link=root, R=np.eye(3),
                           p=np.zeros(3), axis=np.array([1.0, 0.0, 0.0]), inertial=links[root]))
        visit(root, 0, np.eye(3), np.zeros(3))
    else:
        visit(root, -1, np.eye(3), np.zeros(3))
    if not bodies:
        raise ValueError("URDF: no movable joint; the model would have no degrees of freedom")
    return Model(
        [b["parent"] for b in bodies], [b["kind"] for b in bodies],
        mass=[b["inertial"][0] for b in bodies], com=[b["inertial"][1] for b in bodies],
        inertia=[b["inertial"][2] for b in bodies], axis=[b["axis"] for b in bodies],
        placement_rotation=[b["R"] for b in bodies],
        placement_translation=[b["p"] for b in bodies], gravity=gravity,
        names=[b["link"] for b in bodies], joint_names=[b["joint"] for b in bodies])


def matrix_rpy(R: np.ndarray) -> np.ndarray:
    """Inverse of `rpy_matrix` (away from pitch = +-pi/2)."""
    return np.array([np.arctan2(R[2, 1], R[2, 2]), -np.arcsin(np.clip(R[2, 0], -1, 1)),
                     np.arctan2(R[1, 0], R[0, 0])])


def to_urdf(model: Model, name: str = "mbjax") -> str:
    """The URDF of a revolute/prismatic/free tree (for loading the same model into Pinocchio or
    MuJoCo). Link k is `model.names[k]`; the ground link is `base`."""
    kinds = {"revolute": "revolute", "prismatic": "prismatic", "free": "floating"}
    for kind in model.joint_types:
        if kind not in kinds:
            raise ValueError(f"to_urdf: a {kind!r} joint has no URDF counterpart")

    def fmt(values) -> str:
        return " ".join(repr(float(x)) for x in values)

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
            lines.append('    <limit lower="-1e3" upper="1e3" effort="1e6" velocity="1e6"/>')
        lines.append("  </joint>")
    lines.append("</robot>")
    return "\n".join(lines) + "\n"
