"""Contact detection against MuJoCo's narrow phase: every pair kind mbjax detects, at random
poses of six free bodies over a floor, gives MuJoCo's deepest distance and normal per touching
pair, and a point at every point of MuJoCo's contact set; box stacks and capsules on boxes come
to rest where MuJoCo's do."""

import warnings

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import mbjax
from mbjax.contact import ContactSystem
from mbjax.integrate import SemiImplicitEuler
from mbjax.rigid import TreeSystem

mujoco = pytest.importorskip("mujoco")

SHAPES = {"sphere": 'type="sphere" size="0.12"', "capsule": 'type="capsule" size="0.08 0.2"',
          "ellipsoid": 'type="ellipsoid" size="0.1 0.15 0.2"',
          "cylinder": 'type="cylinder" size="0.1 0.15"', "box": 'type="box" size="0.2 0.15 0.1"',
          "box2": 'type="box" size="0.12 0.1 0.25"', "sphere2": 'type="sphere" size="0.08"',
          "capsule2": 'type="capsule" size="0.05 0.15"'}
SCENE = ('<mujoco><option><flag gravity="disable"/></option><worldbody>'
         '<geom name="floor" type="plane" size="3 3 .1"/>'
         + "".join(f'<body pos="0 0 {0.5 * k}"><freejoint/><geom name="{name}" {shape}/></body>'
                   for k, (name, shape) in enumerate(SHAPES.items()))
         + '</worldbody></mujoco>')
# MuJoCo's capsule-box may add a second point near an edge with a normal of its own; there the
# deepest point is compared
ALL_POINTS = {("plane", "sphere"), ("plane", "capsule"), ("plane", "ellipsoid"),
              ("plane", "cylinder"), ("plane", "box"), ("sphere", "sphere"),
              ("sphere", "capsule"), ("sphere", "box"), ("capsule", "capsule"), ("box", "box")}


def _load(xml):
    m = mujoco.MjModel.from_xml_string(xml)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")           # pairs mbjax does not detect are named there
        return m, mbjax.model.from_mujoco(m)


def test_every_detected_pair_matches_mujocos_narrow_phase():
    m, model = _load(SCENE)
    system = ContactSystem(TreeSystem(model), timestep=0.002)
    detect = jax.jit(lambda q: system.contacts(q))
    geoms = model.geoms
    ids = {mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, name): k
           for k, name in enumerate(geoms.names)}
    d = mujoco.MjData(m)
    rng = np.random.default_rng(1)
    checked = {}
    for _ in range(150):
        for j in range(m.njnt):
            adr = m.jnt_qposadr[j]
            d.qpos[adr:adr + 3] = rng.uniform([-0.3, -0.3, 0.0], [0.3, 0.3, 0.4])
            quat = rng.normal(size=4)
            d.qpos[adr + 3:adr + 7] = quat / np.linalg.norm(quat)
        mujoco.mj_forward(m, d)
        found = detect(jnp.asarray(d.qpos))
        dist, pos, frame = (np.asarray(x) for x in (found.distance, found.position, found.frame))
        theirs = {}
        for c in d.contact[:d.ncon]:
            theirs.setdefault((ids[c.geom1], ids[c.geom2]), []).append(c)
        pairs = np.asarray(found.geoms)
        for pair in set(map(tuple, pairs)):
            mine = np.flatnonzero((pairs == pair).all(1) & (dist < 0))
            points = [c for c in theirs.get(pair, []) if c.dist < 0]
            if (mine.size and dist[mine].min() < -0.02) or \
                    (points and min(c.dist for c in points) < -0.02):
                continue                                   # deep: MuJoCo's own choice varies
            kinds = (geoms.kinds[pair[0]], geoms.kinds[pair[1]])
            assert bool(mine.size) == bool(points), (kinds, dist[mine], points)
            if not points:
                continue
            deepest, k = min(points, key=lambda c: c.dist), mine[np.argmin(dist[mine])]
            assert abs(deepest.dist - dist[k]) < 1e-8, kinds
            np.testing.assert_allclose(frame[k, 0], deepest.frame[:3], atol=1e-7)
            if kinds in ALL_POINTS:
                for c in points:
                    assert np.linalg.norm(pos[mine] - c.pos, axis=1).min() < 1e-9, kinds
            checked[kinds] = checked.get(kinds, 0) + 1
    assert len(checked) == 11, checked                  # every pair kind mbjax detects
    # derivatives finite where the geometry is degenerate: everything at one point, and every
    # body upright at its start (parallel faces and edges, a cylinder on its disc)
    jacobian = jax.jit(jax.jacfwd(lambda q: system.contacts(q).distance))
    stacked = np.asarray(m.qpos0, float)
    together = stacked.copy()
    together[np.arange(m.njnt)[:, None] * 7 + np.arange(3)] = [0.0, 0.0, 0.1]
    for q in (stacked, together):
        assert np.isfinite(np.asarray(jacobian(jnp.asarray(q)))).all()


@pytest.mark.parametrize("body, rest", [
    ('<geom type="box" size="0.1 0.1 0.1" mass="1"/>', 0.3),
    ('<geom type="box" size="0.05 0.05 0.05" euler="0 0 30" mass="1"/>', 0.25),
    pytest.param('<geom type="capsule" size="0.05 0.15" euler="0 90 20" mass="1"/>', 0.25,
                 marks=pytest.mark.slow),      # the narrow-phase test checks its contacts
], ids=["box-on-box", "turned-box-on-box", "capsule-on-box"])
def test_bodies_come_to_rest_on_a_box_as_in_mujoco(body, rest):
    """A fixed box on the floor and a body dropped on it: the same fall and rest as MuJoCo's
    (its Euler step is semi-implicit Euler)."""
    xml = ('<mujoco><worldbody><geom type="plane" size="5 5 .1"/>'
           '<geom type="box" size="0.2 0.2 0.1" pos="0 0 0.1"/>'
           f'<body pos="0.02 0.01 0.45"><freejoint/>{body}</body></worldbody></mujoco>')
    m, model = _load(xml)
    d = mujoco.MjData(m)
    reference = []
    for _ in range(300):
        mujoco.mj_step(m, d)
        reference.append(d.qpos[:3].copy())
    system = ContactSystem(TreeSystem(model), timestep=m.opt.timestep)
    sol = mbjax.simulate(system, SemiImplicitEuler(), jnp.asarray(m.qpos0), jnp.zeros(6),
                         dt=m.opt.timestep, t1=0.6)
    assert int(sol.status) == 0
    np.testing.assert_allclose(np.asarray(sol.qs[1:, :3]), np.asarray(reference), atol=1e-3)
    assert abs(float(sol.qs[-1, 2]) - rest) < 2e-3
