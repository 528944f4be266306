"""A URDF's `<collision>` elements as `Geoms`: spheres, boxes and cylinders as they are, a mesh as
the box bounding its vertices (STL, OBJ and COLLADA files), each on the body its link is merged
into."""

import struct
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from mbjax._src.model.geoms import Geoms


def _collada_vertices(data: bytes) -> np.ndarray:
    """The vertices of a COLLADA (.dae) file's meshes, in metres (its `<unit meter=...>`),
    placed by the `<matrix>` of the nodes that instance them."""
    root = ET.fromstring(data)
    namespace = root.tag[:root.tag.index("}") + 1] if root.tag.startswith("{") else ""

    def tag(name: str) -> str:
        return namespace + name

    unit = root.find(f"{tag('asset')}/{tag('unit')}")
    scale = float(unit.get("meter", 1.0)) if unit is not None else 1.0
    arrays = {a.get("id"): a for a in root.iter(tag("float_array"))}
    sources = {s.get("id"): s for s in root.iter(tag("source"))}
    per_geometry = {}
    for geometry in root.iter(tag("geometry")):
        points = []
        for vertices in geometry.iter(tag("vertices")):
            for put in vertices.findall(tag("input")):
                if put.get("semantic") != "POSITION":
                    continue
                source = sources.get(put.get("source", "").lstrip("#"))
                array = None if source is None else source.find(tag("float_array"))
                array = array if array is not None else arrays.get(put.get("source", "")[1:])
                if array is not None and array.text:
                    points.append(np.asarray(array.text.split(), float).reshape(-1, 3))
        if points:
            per_geometry[geometry.get("id")] = np.concatenate(points)
    placed = []

    def walk(node, transform):
        matrix = node.find(tag("matrix"))
        if matrix is not None and matrix.text:
            transform = transform @ np.asarray(matrix.text.split(), float).reshape(4, 4)
        for instance in node.findall(tag("instance_geometry")):
            points = per_geometry.get(instance.get("url", "").lstrip("#"))
            if points is not None:
                placed.append(points @ transform[:3, :3].T + transform[:3, 3])
        for child in node.findall(tag("node")):
            walk(child, transform)

    for scene in root.iter(tag("visual_scene")):
        for node in scene.findall(tag("node")):
            walk(node, np.eye(4))
    if not placed:                           # no scene: the meshes as they are
        placed = list(per_geometry.values())
    return scale * (np.concatenate(placed) if placed else np.zeros((0, 3)))


def _mesh_vertices(path: Path) -> np.ndarray:
    """The vertices of an STL (binary or ASCII) or OBJ mesh file, (k, 3); a ValueError for
    another format."""
    suffix = path.suffix.lower()
    data = path.read_bytes()
    if suffix == ".stl":
        if data[:5].lower() == b"solid" and b"facet" in data[:1000]:
            words = data.decode(errors="replace").split()
            return np.asarray([[float(w) for w in words[i + 1:i + 4]]
                               for i, w in enumerate(words) if w == "vertex"], float)
        count = struct.unpack("<I", data[80:84])[0]
        records = np.frombuffer(data[84:84 + 50 * count], dtype=np.dtype(
            [("normal", "<f4", 3), ("corners", "<f4", (3, 3)), ("attribute", "<u2")]))
        return records["corners"].reshape(-1, 3).astype(float)
    if suffix == ".obj":
        return np.asarray([[float(x) for x in line.split()[1:4]]
                           for line in data.decode(errors="replace").splitlines()
                           if line.startswith("v ")], float)
    if suffix == ".dae":
        return _collada_vertices(data)
    raise ValueError(f"a {suffix or 'suffixless'} mesh (STL, OBJ and COLLADA meshes are read)")


def _resolve(filename: str, base: Path | None, package_dirs) -> Path | None:
    """A mesh's file: `package://NAME/rest` in a package directory given, or in the folder
    named NAME above the URDF file; a relative path from the URDF's folder; None if absent."""
    if filename.startswith("package://"):
        package, _, rest = filename[len("package://"):].lstrip("/").partition("/")
        roots = [Path(d) for d in package_dirs]
        if base is not None:
            roots += [p.parent for p in (base, *base.parents) if p.name == package]
        for root in roots:
            for candidate in (root / package / rest, root / rest):
                if candidate.is_file():
                    return candidate
        return None
    path = Path(filename[len("file://"):] if filename.startswith("file://") else filename)
    if not path.is_absolute() and base is not None:
        path = base / path
    return path if path.is_file() else None


def collision_geoms(robot, where: dict, base: Path | None, package_dirs, floats,
                    origin) -> tuple[Geoms | None, list[str]]:
    """The robot's collision geometry and what was approximated or left out.

    Args:
        robot: the parsed `<robot>` element.
        where: each link's (body, R, p): its frame in the frame of the body it is part of
            (-1: the ground).
        base: the URDF file's folder (None for a string), where relative mesh paths start.
        package_dirs: folders to look for `package://` meshes in.
        floats, origin: the URDF reader's parsers of number lists and `<origin>` elements.

    Returns:
        (`Geoms` or None, notes for the loader's warning). No two of the robot's geoms form a
        pair (a URDF says nothing of which may touch, and meshes' bounding boxes of
        neighbouring links overlap); `Geoms.join` pairs them with what is joined.
    """
    kinds, bodies, sizes, rotations, positions, names = [], [], [], [], [], []
    bounded, missing, unread = [], [], []
    for link in robot.findall("link"):
        body, R_link, p_link = where.get(link.get("name"), (None, None, None))
        if body is None:
            continue
        for k, collision in enumerate(link.findall("collision")):
            what = f"link {link.get('name')!r} collision {k}"
            R, p = origin(collision, what)
            geometry = collision.find("geometry")
            shape = None if geometry is None else next(iter(geometry), None)
            if shape is None:
                continue
            tag, size, offset = shape.tag, None, np.zeros(3)
            if tag == "sphere":
                kind, size = "sphere", [floats(shape.get("radius"), 1, f"{what} radius", None)[0],
                                        0.0, 0.0]
            elif tag == "box":
                kind, size = "box", floats(shape.get("size"), 3, f"{what} size", None) / 2
            elif tag == "cylinder":
                radius = floats(shape.get("radius"), 1, f"{what} radius", None)[0]
                length = floats(shape.get("length"), 1, f"{what} length", None)[0]
                kind, size = "cylinder", [radius, length / 2, 0.0]
            elif tag == "mesh":
                filename = shape.get("filename", "")
                path = _resolve(filename, base, package_dirs)
                if path is None:
                    missing.append(filename)
                    continue
                try:
                    vertices = _mesh_vertices(path)
                except ValueError as error:
                    unread.append(f"{path.name}: {error}")
                    continue
                if not len(vertices):
                    unread.append(f"{path.name}: no vertices")
                    continue
                vertices = vertices * floats(shape.get("scale"), 3, f"{what} scale", [1.0] * 3)
                low, high = vertices.min(0), vertices.max(0)
                kind, size, offset = "box", np.maximum((high - low) / 2, 1e-6), (low + high) / 2
                bounded.append(path.name)
            else:
                unread.append(f"{what}: <{tag}>")
                continue
            kinds.append(kind)
            bodies.append(body)
            sizes.append(size)
            rotations.append(R_link @ R)
            positions.append(p_link + R_link @ (p + R @ offset))
            names.append(collision.get("name") or f"{link.get('name')}/collision{k}")
    notes = []
    if bounded:
        notes.append(f"{len(bounded)} collision meshes as the boxes bounding them")
    if missing:
        notes.append(f"collision meshes not found ({len(missing)}: {missing[0]}, ...; give "
                     f"package_dirs=)")
    if unread:
        notes.append(f"collision geometry not read ({'; '.join(unread[:3])})")
    if not kinds:
        return None, notes
    geoms = Geoms(kinds, bodies, np.asarray(sizes, float), position=np.asarray(positions),
                  rotation=np.asarray(rotations), names=names, pairs=())
    return geoms, notes
