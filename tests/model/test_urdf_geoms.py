"""A URDF's collision geometry (`load_urdf` -> `Model.geoms`) against Pinocchio's collision model
of the same files (example-robot-data: ANYmal's primitives, Solo12's STL and the Kinova arm's
COLLADA meshes as their bounding boxes): every geom where Pinocchio puts it, the same size; and
a robot loaded from URDF dropped on a floor lands on its feet."""

import warnings

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import mbjax
from mbjax.contact import ContactSystem
from mbjax.integrate import SemiImplicitEuler
from mbjax.model import ModelWarning, state_to_pinocchio
from mbjax.rigid import TreeSystem
from tests.conftest import example_robots

ROBOTS = ("anymal/anymal", "solo/solo12", "kinova/kinova")


def _load(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return mbjax.load_urdf(path, floating_base=True)


def _world(model, q):
    """Each geom's world rotation and centre at q."""
    R, p = (np.asarray(x) for x in mbjax.rigid.forward_kinematics(model, q))
    g, body = model.geoms, np.asarray(model.geoms.bodies)
    on = body >= 0
    Rw = np.where(on[:, None, None], R[np.maximum(body, 0)] @ np.asarray(g.rotation),
                  np.asarray(g.rotation))
    pw = np.where(on[:, None], p[np.maximum(body, 0)]
                  + np.einsum("gij,gj->gi", R[np.maximum(body, 0)], np.asarray(g.position)),
                  np.asarray(g.position))
    return Rw, pw


def test_collision_geometry_is_pinocchios():
    pin = pytest.importorskip("pinocchio")
    for path in example_robots(ROBOTS):
        model = _load(path)
        package = str(path).split("/example-robot-data/")[0]
        pm, cm, _ = pin.buildModelsFromUrdf(str(path), package_dirs=[package],
                                            root_joint=pin.JointModelFreeFlyer())
        q = model.normalize(jnp.asarray(np.random.default_rng(0).normal(size=model.nq)))
        pd, cd = pm.createData(), cm.createData()
        pin.updateGeometryPlacements(pm, pd, cm, cd,
                                     np.asarray(state_to_pinocchio(model, q, jnp.zeros(model.nv))[0]))
        Rw, pw = _world(model, q)
        size = np.asarray(model.geoms.size)
        assert model.geoms.n == len(cm.geometryObjects), path
        for k, obj in enumerate(cm.geometryObjects):
            M, shape = cd.oMg[k], obj.geometry
            kind = type(shape).__name__
            if kind.startswith("BVH"):               # a mesh: its bounding box
                shape.computeLocalAABB()
                box = shape.aabb_local
                centre, half = M.translation + M.rotation @ box.center(), (box.max_ - box.min_) / 2
            else:
                centre = M.translation
                half = {"Sphere": lambda s: [s.radius], "Box": lambda s: s.halfSide,
                        "Cylinder": lambda s: [s.radius, s.halfLength]}[kind](shape)
            j = int(np.argmin(np.linalg.norm(pw - centre, axis=1)))
            assert np.linalg.norm(pw[j] - centre) < 1e-8, (path.name, obj.name)
            np.testing.assert_allclose(size[j, :len(half)], half, atol=1e-8)
            if kind in ("Box", "Cylinder") or kind.startswith("BVH"):
                np.testing.assert_allclose(Rw[j], M.rotation, atol=1e-8)


def test_missing_and_unread_meshes_are_named():
    urdf = """<robot name="r"><link name="a"><inertial><mass value="1"/>
      <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>
      <collision><geometry><mesh filename="package://nowhere/a.stl"/></geometry></collision>
      <collision><geometry><sphere radius="0.1"/></geometry></collision></link></robot>"""
    with pytest.warns(ModelWarning, match="collision meshes not found"):
        model = mbjax.load_urdf(urdf, floating_base=True)
    assert model.geoms.kinds == ("sphere",) and model.geoms.pairs == ()


def test_solo12_from_its_urdf_lands_on_its_feet():
    """Solo12's collision meshes as boxes, a floor joined in code: dropped from 0.4 m, it lands
    on its feet, the base resting where its straight legs hold it."""
    (path,) = example_robots(("solo/solo12",))
    model = _load(path)
    geoms = model.geoms.join(mbjax.model.ground_plane())
    assert len(geoms.pairs) == model.geoms.n            # each geom against the floor, no more
    system = ContactSystem(TreeSystem(model), geoms, timestep=0.002)
    sol = mbjax.simulate(system, SemiImplicitEuler(), model.neutral().at[2].set(0.4),
                         jnp.zeros(model.nv), dt=0.002, t1=0.6)
    assert int(sol.status) == 0
    lowest = jax.vmap(lambda q: _lowest(model, q))(sol.qs[-1:])
    assert 0.25 < float(sol.qs[-1, 2]) < 0.4 and abs(float(sol.vs[-1, 2])) < 0.05
    assert float(lowest[0]) > -2e-3                    # nothing sunk into the floor


def _lowest(model, q):
    R, p = mbjax.rigid.forward_kinematics(model, q)
    g, body = model.geoms, np.asarray(model.geoms.bodies)
    corners = jnp.asarray([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    points = (p[body][:, None] + jnp.einsum("gij,gcj->gci", R[body] @ g.rotation,
                                            corners * g.size[:, None])
              + jnp.einsum("gij,gj->gi", R[body], g.position)[:, None])
    return points[..., 2].min()
