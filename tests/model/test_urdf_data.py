"""URDF data beyond the tree: fixed-joint merging of unusual links, plausibility warnings and their
remedies, named frames and their Jacobians, joint limits, damping and armature, mimic joints, the
state converters, and the example-robot-data corpus against Pinocchio."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import mbjax
from mbjax import Dense, Recursive
from mbjax.integrate import RK4, simulate
from mbjax._src.integrate import Status
from mbjax.loops import ClosedSystem, Coupled, Coupling
from mbjax._src.model.checks import ModelWarning
from mbjax.rigid import TreeSystem
from tests.model.test_model_urdf import LIMIT, _inertial, _joint, _link, _robot
from mbjax_harness.peers import random_state

pin = pytest.importorskip("pinocchio")


def _pin_state(model, q, v):
    return tuple(np.asarray(x) for x in mbjax.model.state_to_pinocchio(model, q, v))


def _random_state(model, seed):
    return tuple(jnp.asarray(x) for x in random_state(model, seed))


# A robot with what real URDFs carry: a dummy root with a rank-1 inertia welded to the world, a
# zero-mass link with inertia on a fixed joint (a rotor), a point-mass sensor, a contact frame
# without <inertial>, a continuous joint, damping and friction, and limits.
PARTS = (
    _link("world_dummy", _inertial("0.0", 'ixx="1e-3" iyy="0" izz="0"')),
    _link("base", _inertial("2.0", 'ixx="0.02" iyy="0.03" izz="0.04"', "0 0 0.05")),
    _link("upper", _inertial("1.2", 'ixx="0.02" iyy="0.021" izz="0.004"', "0 0.01 -0.15")),
    _link("rotor", _inertial("0.0", 'ixx="0.003" iyy="0.003" izz="0.005"')),
    _link("imu", _inertial("0.05", 'ixx="0" iyy="0" izz="0"', "0.01 0 0")),
    '<link name="foot_contact"/>',
    _link("lower", _inertial("0.8", 'ixx="0.01" iyy="0.011" izz="0.002"', "0 0 -0.1", "0 0.1 0")),
    _joint("dummy_joint", "fixed", "world_dummy", "base", xyz="0 0 0.3"),
    '<joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>'
    '<origin xyz="0.1 0 0" rpy="0.2 0 0"/><axis xyz="0 1 0"/>'
    '<limit lower="-1.5" upper="2.0" effort="30" velocity="4"/>'
    '<dynamics damping="0.7" friction="0.2"/></joint>',
    _joint("rotor_mount", "fixed", "upper", "rotor", xyz="0 0.05 -0.1", rpy="0 0.4 0"),
    _joint("imu_mount", "fixed", "upper", "imu", xyz="0 0 -0.2", rpy="0.1 0.2 0.3"),
    '<joint name="elbow" type="continuous"><parent link="upper"/><child link="lower"/>'
    '<origin xyz="0 0 -0.3"/><axis xyz="1 0 1"/><dynamics damping="0.3"/></joint>',
    _joint("contact_joint", "fixed", "lower", "foot_contact", xyz="0 0 -0.25"),
)
ROBOT = _robot(*PARTS)
# MuJoCo refuses the dummy root's rank-1 inertia (it does not merge a body welded to the world)
# and drops the inertia of the zero-mass rotor (Pinocchio and mbjax keep it)
ROBOT_MJ = _robot(*(part for part in PARTS if "world_dummy" not in part and "rotor" not in part))


def test_unusual_links_merge_and_keep_their_frames():
    """The welded dummy root, the rotor, the sensor and the contact frame load silently; the
    rotor's inertia is merged (a zero-mass link's inertia is not dropped); every link and
    fixed joint is a named frame whose pose matches Pinocchio's."""
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        model = mbjax.load_urdf(ROBOT)
    assert model.names == ("upper", "lower")
    for frame in ("world_dummy", "base", "dummy_joint", "rotor", "rotor_mount", "imu",
                  "imu_mount", "foot_contact", "contact_joint"):
        assert frame in model.frame_names
    pm = pin.buildModelFromXML(ROBOT)
    pd = pm.createData()
    q, v, tau = _random_state(model, 0)
    q_pin, v_pin = _pin_state(model, q, v)
    M_pin = pin.crba(pm, pd, q_pin)
    M_pin = np.triu(M_pin) + np.triu(M_pin, 1).T
    np.testing.assert_allclose(mbjax.mass_matrix(model, q), M_pin, rtol=1e-12, atol=1e-14)
    pin.framesForwardKinematics(pm, pd, q_pin)
    for frame in model.frame_names + model.names:
        R, p = mbjax.rigid.frame_pose(model, q, frame)
        pose = pd.oMf[pm.getFrameId(frame)]
        np.testing.assert_allclose(R, pose.rotation, atol=1e-14)
        np.testing.assert_allclose(p, pose.translation, atol=1e-14)


def test_frame_jacobian_against_pinocchio_and_the_pose_rate():
    model = mbjax.load_urdf(ROBOT, floating_base=True)
    q, v, _ = _random_state(model, 1)
    for frame in ("foot_contact", "imu", "upper"):
        J = mbjax.rigid.frame_jacobian(model, q, frame)
        # identity: the pose's rate along q_dot(q, v) is (omega x R, v_origin) = J v
        (R, p), (R_dot, p_dot) = jax.jvp(lambda q_: mbjax.rigid.frame_pose(model, q_, frame), (q,),
                                         (model.q_dot(q, v),))
        W = R_dot @ R.T
        np.testing.assert_allclose(J @ v, jnp.concatenate([jnp.array([W[2, 1], W[0, 2], W[1, 0]]),
                                                           p_dot]), atol=1e-13)
        pm = pin.buildModelFromXML(ROBOT, pin.JointModelFreeFlyer())
        pd = pm.createData()
        q_pin, _ = _pin_state(model, q, v)
        J_pin = pin.computeFrameJacobian(pm, pd, q_pin, pm.getFrameId(frame),
                                         pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        P = np.asarray(jax.jacfwd(lambda v_: mbjax.model.state_to_pinocchio(model, q, v_)[1])(v))
        np.testing.assert_allclose(np.concatenate([J_pin[3:], J_pin[:3]]) @ P, J, atol=1e-13)
    with pytest.raises(KeyError, match="no frame, body or joint named 'nope'"):
        mbjax.rigid.frame_pose(model, q, "nope")


def test_joint_data_is_read():
    model = mbjax.load_urdf(ROBOT)
    np.testing.assert_array_equal(model.lower, [-1.5, -np.inf])
    np.testing.assert_array_equal(model.upper, [2.0, np.inf])
    np.testing.assert_array_equal(model.effort_limit, [30.0, np.inf])
    np.testing.assert_array_equal(model.velocity_limit, [4.0, np.inf])
    np.testing.assert_array_equal(model.damping, [0.7, 0.3])
    np.testing.assert_array_equal(model.friction, [0.2, 0.0])
    np.testing.assert_array_equal(model.armature, [0.0, 0.0])
    np.testing.assert_array_equal(mbjax.load_urdf(ROBOT, armature=0.01).armature, [0.01, 0.01])


def test_damping_and_armature_against_mujoco():
    """MuJoCo reads URDF damping; armature set on both models. Forward dynamics agree, and
    damping is the force -d v (the identity on mbjax's own routes)."""
    mujoco = pytest.importorskip("mujoco")
    model = mbjax.load_urdf(ROBOT_MJ, armature=0.02)
    mj = mujoco.MjModel.from_xml_string(ROBOT_MJ)
    mj.dof_armature[:] = 0.02
    mj.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT     # friction, limits: data
    np.testing.assert_array_equal(mj.dof_damping, model.damping)
    data = mujoco.MjData(mj)
    q, v, tau = _random_state(model, 2)
    data.qpos[:], data.qvel[:], data.qfrc_applied[:] = q, v, tau
    mujoco.mj_forward(mj, data)
    for method in (Recursive(), Dense()):
        a = mbjax.forward_dynamics(model, q, v, tau, method=method)
        np.testing.assert_allclose(a, data.qacc, rtol=1e-10, atol=1e-10)
    import equinox as eqx
    undamped = eqx.tree_at(lambda m: m.damping, model, jnp.zeros(2))
    np.testing.assert_allclose(mbjax.forward_dynamics(undamped, q, v, tau - model.damping * v),
                               mbjax.forward_dynamics(model, q, v, tau), rtol=1e-13)
    np.testing.assert_allclose(mbjax.inverse_dynamics(model, q, v, data.qacc), tau, atol=1e-10)


def test_limits_flag_the_status():
    model = mbjax.load_urdf(ROBOT)
    system = TreeSystem(model, jnp.array([0.0, 0.0]))
    inside = simulate(system, RK4(), jnp.array([0.0, 0.0]), jnp.zeros(2), dt=0.01, t1=0.1)
    assert int(inside.status) == 0
    fast = simulate(system, RK4(), jnp.array([0.0, 0.0]), jnp.array([5.0, 0.0]), dt=0.01, t1=0.1)
    assert int(fast.status) & Status.LIMIT_EXCEEDED and bool(fast.ok)   # a note, not a failure
    strong = simulate(TreeSystem(model, jnp.array([40.0, 0.0])), RK4(), jnp.zeros(2),
                      jnp.zeros(2), dt=0.01, t1=0.1)
    assert int(strong.status) & Status.LIMIT_EXCEEDED
    assert "limit exceeded" in fast.messages()[0]
    excess = mbjax._src.model.limits.excess(model, jnp.array([2.5, 9.0]), jnp.array([5.0, 0.0]))
    np.testing.assert_allclose(excess, [0.5, 0.0, 1.0, 0.0, 0.0, 0.0])


MASSLESS_LEAF = _robot(_link("base"), _link("a"), '<link name="tip"/>',
                       _joint("j1", "revolute", "base", "a", axis="0 1 0"),
                       _joint("j2", "revolute", "a", "tip", axis="1 0 0", xyz="0 0 -0.3"))


def test_massless_leaf_loads_with_a_warning_and_its_remedies():
    with pytest.warns(ModelWarning, match="body 'tip' is massless.*armature.*min_mass"):
        model = mbjax.load_urdf(MASSLESS_LEAF)
    q, v, tau = _random_state(model, 3)
    assert not np.all(np.isfinite(mbjax.forward_dynamics(model, q, v, tau)))   # M is singular
    with pytest.raises(ValueError, match="massless.*strict=True"):
        mbjax.load_urdf(MASSLESS_LEAF, strict=True)
    # remedies: armature (compared with Pinocchio's armature) or bounds (MuJoCo's boundmass)
    armed = mbjax.load_urdf(MASSLESS_LEAF, armature=0.01)
    pm = pin.buildModelFromXML(MASSLESS_LEAF)
    pm.armature[:] = 0.01
    a_pin = pin.aba(pm, pm.createData(), *_pin_state(armed, q, v), np.asarray(tau))
    np.testing.assert_allclose(mbjax.forward_dynamics(armed, q, v, tau), a_pin, rtol=1e-11)
    bounded = mbjax.load_urdf(MASSLESS_LEAF, min_mass=1e-3, min_inertia=1e-6)
    assert np.all(np.isfinite(mbjax.forward_dynamics(bounded, q, v, tau)))
    np.testing.assert_allclose(bounded.mass, [1.0, 1e-3])
    np.testing.assert_allclose(bounded.inertia[1], 1e-6 * np.eye(3), atol=1e-18)


def test_triangle_inequality_warns_and_computes_like_pinocchio():
    xml = _robot(_link("base"), _link("a", _inertial(inertia='ixx="0.01" iyy="0.01" izz="0.03"')),
                 _joint("j", "revolute", "base", "a", axis="0 1 1"))
    with pytest.warns(ModelWarning, match="body 'a'.*triangle inequality"):
        model = mbjax.load_urdf(xml)
    with pytest.raises(ValueError, match="triangle inequality.*strict=True"):
        mbjax.load_urdf(xml, strict=True)
    q, v, tau = _random_state(model, 4)
    pm = pin.buildModelFromXML(xml)
    np.testing.assert_allclose(mbjax.forward_dynamics(model, q, v, tau),
                               pin.aba(pm, pm.createData(), *_pin_state(model, q, v),
                                       np.asarray(tau)), rtol=1e-12)


MIMIC = _robot(_link("base"), _link("a"), _link("b"),
               _joint("j1", "revolute", "base", "a", axis="0 1 0"),
               '<joint name="j2" type="revolute"><parent link="a"/><child link="b"/>'
               '<origin xyz="0 0 -0.3"/><axis xyz="0 1 0"/>' + LIMIT +
               '<mimic joint="j1" multiplier="-2.0" offset="0.1"/></joint>')


def test_mimic_joints_load_independent_with_their_couplings():
    with pytest.warns(ModelWarning, match=r"j2 = -2.0 j1 \+ 0.1.*model.closures"):
        model = mbjax.load_urdf(MIMIC)
    assert model.nv == 2
    closures = model.closures
    (coupling,) = closures
    assert isinstance(coupling, Coupling) and (coupling.coordinate, coupling.reference) == (1, 0)
    system = ClosedSystem(TreeSystem(model), closures, Coupled(baumgarte=(10.0, 10.0)))
    q0 = jnp.array([0.3, -0.5])
    sol = simulate(system, RK4(), q0, system.initial_state(q0, jnp.array([1.0, -2.0])), dt=1e-3,
                   t1=0.5)
    np.testing.assert_allclose(sol.qs[:, 1], -2.0 * sol.qs[:, 0] + 0.1, atol=1e-8)
    assert abs(float(sol.qs[-1, 0] - 0.3)) > 0.05                  # it moved


def test_state_converters_round_trip_and_layout():
    model = mbjax.load_urdf(ROBOT, floating_base=True)
    q, v, _ = _random_state(model, 5)
    q_pin, v_pin = mbjax.model.state_to_pinocchio(model, q, v)
    assert q_pin.shape == (model.nq + 1,)                         # continuous: cos, sin
    np.testing.assert_allclose(q_pin[3:7], jnp.concatenate([q[4:7], q[3:4]]))   # xyzw
    np.testing.assert_allclose(v_pin[:6], jnp.concatenate([v[3:6], v[:3]]))     # (v; omega)
    for to, back in ((mbjax.model.state_to_pinocchio, mbjax.model.state_from_pinocchio),
                     (mbjax.model.state_to_mujoco, mbjax.model.state_from_mujoco)):
        q2, v2 = back(model, *to(model, q, v))
        np.testing.assert_allclose(q2, q, atol=1e-15)
        np.testing.assert_allclose(v2, v, atol=1e-15)
    with pytest.raises(ValueError, match=r"shapes \(10,\) and \(8,\).*got \(9,\) and \(8,\)"):
        mbjax.model.state_from_pinocchio(model, q, v)
    # every direction checks both lengths (a gather would clamp a short state's indices)
    for convert in (mbjax.model.state_to_pinocchio, mbjax.model.state_to_mujoco,
                    mbjax.model.state_from_mujoco):
        with pytest.raises(ValueError, match=r"shapes \(9,\) and \(8,\).*got \(8,\) and \(8,\)"):
            convert(model, q[:-1], v)
        with pytest.raises(ValueError, match=r"got \(9,\) and \(9,\)"):
            convert(model, q, jnp.concatenate([v, v[:1]]))


def test_floating_base_against_mujoco_free_joint_layout():
    """MuJoCo's URDF import with a free joint added: positions, velocities (world linear) and
    accelerations convert through the state converters."""
    mujoco = pytest.importorskip("mujoco")
    model = mbjax.load_urdf(ROBOT_MJ, floating_base=True, sibling_order=mbjax.model.InDocument())
    spec = mujoco.MjSpec.from_string(ROBOT_MJ)
    spec.worldbody.first_body().add_freejoint()
    mj = spec.compile()
    mj.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    data = mujoco.MjData(mj)
    q, v, tau = _random_state(model, 6)
    data.qpos[:], data.qvel[:] = (np.asarray(x) for x in mbjax.model.state_to_mujoco(model, q, v))
    mujoco.mj_forward(mj, data)
    a_mj = data.qacc.copy()
    data.qfrc_applied[:] = 0
    a = mbjax.forward_dynamics(model, q, v, jnp.zeros(model.nv))
    _, a_as_mj = jax.jvp(lambda q_, v_: mbjax.model.state_to_mujoco(model, q_, v_)[1], (q, v),
                         (model.q_dot(q, v), a))
    np.testing.assert_allclose(a_as_mj, a_mj, rtol=1e-9, atol=1e-9)


# -- the corpus -----------------------------------------------------------------------------------

QUICK_ROBOTS = ("romeo/romeo_small",)


def _corpus():
    from mbjax_harness.reproduce import urdf_corpus
    try:
        return urdf_corpus, urdf_corpus.corpus_paths()
    except Exception as err:          # PackageNotFoundError
        pytest.skip(f"example-robot-data is not installed ({err})")


def test_urdf_corpus_quick():
    """A humanoid of example-robot-data whose CAD inertias break the triangle inequality, on a
    floating base: it loads (with warnings) and agrees with Pinocchio (the slow test: all)."""
    corpus, paths = _corpus()
    chosen = [p for p in paths if corpus.name(p) in QUICK_ROBOTS]
    assert len(chosen) == len(QUICK_ROBOTS)
    for path in chosen:
        row = corpus.compare(path, floating=True)
        assert row["loads"], row
        assert row["max_relative_difference"] < 1e-10, row


@pytest.mark.slow
def test_urdf_corpus_every_robot():
    corpus, paths = _corpus()
    rows = corpus.rows(paths)
    for row in rows:
        if not row["loads"]:
            assert ("no links" in row["note"]
                    or ("no movable joint" in row["note"] and not row["floating"])), row
            continue
        assert row["max_relative_difference"] < 1e-10, row


def test_converters_match_the_name_matched_map():
    """The public converter (joint order) against the tests' own map, which matches joints by
    name: the same Pinocchio state for a floating base with a continuous joint."""
    from tests.model.test_model_urdf import FIXED_URDF
    from mbjax_harness.peers import pinocchio_maps

    model = mbjax.load_urdf(FIXED_URDF, floating_base=True)
    to_pin, vi = pinocchio_maps(model, pin.buildModelFromXML(FIXED_URDF, pin.JointModelFreeFlyer()))
    q, v, _ = random_state(model, 7)
    q_pin, v_pin = mbjax.model.state_to_pinocchio(model, jnp.asarray(q), jnp.asarray(v))
    expected_v = np.zeros(model.nv)
    expected_v[vi] = v
    np.testing.assert_allclose(q_pin, to_pin(q), atol=1e-15)
    np.testing.assert_allclose(v_pin, expected_v, atol=1e-15)
