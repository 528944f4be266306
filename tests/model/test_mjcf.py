"""`load_mjcf` / `from_mujoco` against MuJoCo: every orientation form, defaults and includes,
several joints per body, ball and free joints, inertias, joint data, connect and weld closures,
the ignored-features warning, and the corpus of MJCF models shipped by the installed packages.

Every dynamic comparison runs `mbjax_harness.reproduce.mjcf_corpus.compare`: MuJoCo with contacts,
constraints and actuators disabled (joint damping, hinge and slide springs and armature kept) at a random state
(qpos, qvel, qfrc_applied), mbjax's `forward_dynamics` mapped to MuJoCo's qacc by `jax.jvp` of
`state_to_mujoco`, relative difference below 1e-8; poses are `mbjax.rigid.frame_pose` of every body
and site against xpos/xmat and site_xpos/site_xmat.
"""

import sys
import warnings

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import mbjax
from mbjax.loops import ClosedSystem, CutJoint, Loops, Spherical, Weld
from mbjax._src.model.checks import ModelWarning
from mbjax._src.model.mjcf import object_name, site_frame_name
from mbjax_harness.reproduce.mjcf_corpus import (
    TOLERANCE,
    compare,
    quick_paths,
    random_state,
    rows,
    survey,
)
from mbjax.rigid import TreeSystem

mujoco = pytest.importorskip("mujoco", reason="load_mjcf needs MuJoCo (pip install mujoco)")

NO_CONTACT = '<default><geom contype="0" conaffinity="0"/></default>'


def _load(xml: str, **kwargs):
    """(MuJoCo's compiled model, mbjax's), with no ignored-feature warning allowed."""
    mjmodel = mujoco.MjModel.from_xml_string(xml)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ModelWarning)
        return mjmodel, mbjax.model.from_mujoco(mjmodel, **kwargs)


def _check(mjmodel, model, seeds=(0, 1)):
    """Accelerations and every body and site pose agree with MuJoCo's."""
    for seed in seeds:
        errors = compare(mjmodel, model, seed)
        assert errors["qacc"] < TOLERANCE, errors
        assert errors["poses"] < 1e-12, errors
    m, d = random_state(mjmodel, seeds[0])
    q, _ = mbjax.model.state_from_mujoco(model, jnp.asarray(d.qpos), jnp.asarray(d.qvel))
    named = [(object_name(m, "body", b), d.xmat[b], d.xpos[b]) for b in range(1, m.nbody)]
    named += [(site_frame_name(model, object_name(m, "site", s)), d.site_xmat[s], d.site_xpos[s])
              for s in range(m.nsite)]
    for name, xmat, xpos in named:
        R, p = mbjax.rigid.frame_pose(model, q, name)
        np.testing.assert_allclose(np.asarray(R).reshape(9), xmat, atol=1e-12, err_msg=name)
        np.testing.assert_allclose(p, xpos, atol=1e-12, err_msg=name)


# --------------------------------------------------------------------------------------------
# Orientations, defaults, includes
# --------------------------------------------------------------------------------------------

ORIENTATIONS = [
    ('angle="radian"', 'quat="0.9 0.1 -0.3 0.2"'),
    ('angle="degree" eulerseq="zyx"', 'euler="30 -20 45"'),
    ('angle="radian" eulerseq="XYZ"', 'euler="0.5 -0.3 0.8"'),
    ('angle="degree"', 'axisangle="1 1 0 60"'),
    ('angle="radian"', 'axisangle="0 1 1 1.2"'),
    ('angle="degree"', 'xyaxes="1 1 0 -1 1 1"'),
    ('angle="radian"', 'zaxis="0 1 1"'),
]


def _arm(compiler: str, orient: str, hinge_range: str) -> str:
    return f"""
<mujoco><compiler {compiler}/><option gravity="0.3 -0.2 -9.81"/>{NO_CONTACT}
 <worldbody>
  <body name="base" pos="0.1 0.2 0.3" {orient}>
   <site name="base_site" pos="0.1 0 0.2" {orient}/>
   <body name="upper" pos="0.2 0 0.1" {orient}>
    <joint name="shoulder" axis="0 1 0.5" pos="0 0.05 0.1" range="{hinge_range}" limited="true"/>
    <geom type="box" size="0.1 0.2 0.3" pos="0.05 0 0.1" {orient}/>
    <site name="elbow_site" pos="0.1 0 -0.2" {orient}/>
    <body name="lower" pos="0 0 -0.5" {orient}>
     <joint name="elbow" axis="1 0 0" pos="0 0.1 0.2"/>
     <joint name="slide" type="slide" axis="0 1 1" ref="0.1"/>
     <geom type="ellipsoid" size="0.1 0.05 0.2" pos="0.1 0.1 0" {orient}/>
     <geom type="capsule" fromto="0 0 0 0.3 0.1 -0.4" size="0.05"/>
    </body>
   </body>
  </body>
 </worldbody>
</mujoco>"""


@pytest.mark.parametrize("compiler, orient", ORIENTATIONS)
def test_orientation_forms(compiler, orient):
    degree = "degree" in compiler
    mjmodel, model = _load(_arm(compiler, orient, "-45 90" if degree else "-0.8 1.5"))
    assert model.names == ("upper", "lower/elbow", "lower")
    assert model.joint_names == ("shoulder", "elbow", "slide")
    expected = np.deg2rad([-45.0, 90.0]) if degree else np.array([-0.8, 1.5])
    np.testing.assert_allclose([model.lower[0], model.upper[0]], expected, rtol=1e-12)
    assert model.frame_parents[model.frame_names.index("base")] == -1      # welded to the world
    _check(mjmodel, model, seeds=(0,))


def test_orientation_by_hand():
    """A body turned 90 degrees about z (MuJoCo's default angle unit is degrees)."""
    xml = f"""<mujoco>{NO_CONTACT}<worldbody><body name="b" pos="1 2 3" axisangle="0 0 1 90">
              <joint name="j" axis="1 0 0"/><geom size="0.1"/></body></worldbody></mujoco>"""
    _, model = _load(xml)
    R, p = mbjax.rigid.frame_pose(model, model.neutral(), "b")
    np.testing.assert_allclose(R, [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-12)
    np.testing.assert_allclose(p, [1, 2, 3], atol=1e-12)


DEFAULTS = """
<mujoco>
 <default>
  <geom contype="0" conaffinity="0" density="500"/>
  <joint damping="0.3" armature="0.02"/>
  <default class="arm">
   <joint type="hinge" axis="0 1 0" range="-60 60" limited="true" damping="0.7"/>
   <geom type="capsule" size="0.04"/>
   <default class="wrist"><joint axis="1 0 0" armature="0.1" frictionloss="0.2"/></default>
  </default>
 </default>
 <worldbody>
  <body name="a" childclass="arm" pos="0 0 1">
   <joint name="j1"/>
   <geom fromto="0 0 0 0.4 0 0"/>
   <body name="b" pos="0.4 0 0">
    <joint name="j2" class="wrist"/>
    <geom fromto="0 0 0 0 0 -0.3"/>
    <body name="c" pos="0 0 -0.3"><joint name="j3" class="main" axis="0 0 1"/>
     <geom type="sphere" size="0.05"/></body>
   </body>
  </body>
 </worldbody>
</mujoco>"""


def test_defaults_and_classes():
    mjmodel, model = _load(DEFAULTS)
    np.testing.assert_allclose(model.damping, [0.7, 0.7, 0.3])
    np.testing.assert_allclose(model.armature, [0.02, 0.1, 0.02])
    np.testing.assert_allclose(model.friction, [0.0, 0.2, 0.0])
    np.testing.assert_allclose(model.upper, [np.pi / 3, np.pi / 3, np.inf])
    np.testing.assert_allclose(model.axis, [[0, 1, 0], [1, 0, 0], [0, 0, 1]])
    _check(mjmodel, model)


def test_include_and_paths(tmp_path):
    (tmp_path / "arm.xml").write_text(
        '<mujoco><body name="arm" pos="0 0 1"><joint name="j" axis="0 1 0"/>'
        '<geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.05"/></body></mujoco>')
    main = tmp_path / "main.xml"
    main.write_text(f'<mujoco>{NO_CONTACT}<worldbody><include file="arm.xml"/></worldbody></mujoco>')
    for source in (main, str(main)):
        model = mbjax.load_mjcf(source)
        assert model.names == ("arm",) and model.joint_names == ("j",)
    _check(mujoco.MjModel.from_xml_path(str(main)), model)


# --------------------------------------------------------------------------------------------
# Joints, inertias, joint data
# --------------------------------------------------------------------------------------------


def test_several_joints_per_body_and_anchors():
    """A body with two hinges (anchors off its origin, one with a ref angle): a massless
    intermediate body, the body's frame at the last anchor and a frame at MuJoCo's origin; a
    joint's name is the frame at its anchor (MuJoCo's xanchor)."""
    xml = f"""
<mujoco>{NO_CONTACT}<worldbody>
 <body name="link" pos="0.3 0 1" quat="0.9 0.2 0.1 0.3">
  <joint name="yaw" axis="0 0 1" pos="0.1 0.2 0"/>
  <joint name="pitch" axis="0 1 0" pos="-0.1 0 0.3" ref="20"/>
  <geom type="box" size="0.2 0.05 0.05" pos="0.2 0 0"/>
  <site name="tip" pos="0.5 0 0"/>
  <body name="child" pos="0.5 0 0"><joint name="roll" axis="1 0 0" pos="0 0 0.1"/>
   <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03"/></body>
 </body>
</worldbody></mujoco>"""
    mjmodel, model = _load(xml)
    assert model.names == ("link/yaw", "link", "child")
    assert model.topology.parents == (-1, 0, 1)
    assert model.mass[0] == 0 and model.mass[1] > 0
    assert {"link", "child", "tip"} <= set(model.frame_names)
    _check(mjmodel, model)
    m, d = random_state(mjmodel, 3)
    q, _ = mbjax.model.state_from_mujoco(model, jnp.asarray(d.qpos), jnp.asarray(d.qvel))
    for j, name in enumerate(model.joint_names):
        np.testing.assert_allclose(mbjax.rigid.frame_pose(model, q, name)[1], d.xanchor[j], atol=1e-12)


BALL_AND_FREE = f"""
<mujoco>{NO_CONTACT}<option gravity="0 0 -9.81"/><worldbody>
 <body name="torso" pos="0 0 1" euler="10 20 30">
  <joint name="root" type="free" damping="0.2" armature="0.05"/>
  <geom type="box" size="0.2 0.1 0.05"/>
  <body name="head" pos="0 0 0.2"><joint name="neck" type="ball" pos="0 0 -0.05" damping="0.1"/>
   <geom type="sphere" size="0.08" pos="0 0.02 0.05"/><site name="eye" pos="0.05 0 0.05"/></body>
  <body name="arm" pos="0.2 0 0" zaxis="1 0 1">
   <joint name="shoulder" axis="0 1 0" pos="-0.1 0 0"/>
   <joint name="upper_arm" type="ball" pos="0.3 0 0" armature="0.01"/>
   <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.03"/></body>
 </body>
 <body name="ball" pos="1 0 0.5"><freejoint/><geom type="ellipsoid" size="0.1 0.2 0.3"/></body>
</worldbody></mujoco>"""


def test_ball_and_free_joints():
    """Free and ball joints; a free joint's damping and rotational armature map exactly, its
    translational armature (MuJoCo's, on the world-frame velocity) is left out with a warning."""
    mjmodel = mujoco.MjModel.from_xml_string(BALL_AND_FREE)
    with pytest.warns(ModelWarning, match=r"armature on free joints' translation \(1\)"):
        model = mbjax.model.from_mujoco(mjmodel)
    np.testing.assert_allclose(model.armature[:6], [0.05] * 3 + [0.0] * 3)
    assert model.joint_types == ("free", "spherical", "revolute", "spherical", "free")
    assert (model.nq, model.nv) == (mjmodel.nq, mjmodel.nv)
    np.testing.assert_allclose(model.damping[:6], 0.2)          # isotropic: frame-independent
    _check(mjmodel, model, seeds=(0, 1, 2))


def test_fullinertia_diaginertia_and_welded_bodies():
    """Explicit inertias are read as compiled; a welded body merges its mass into its parent
    (parallel axes) and stays a named frame; MuJoCo's body frame is off the joint anchor."""
    xml = f"""
<mujoco>{NO_CONTACT}<worldbody>
 <body name="a" pos="0 0 1"><joint name="j1" axis="0 1 0" pos="0.1 0 0"/>
  <inertial pos="0.2 0.1 0" mass="2" fullinertia="0.3 0.2 0.25 0.01 -0.02 0.03"/>
  <body name="b" pos="0.5 0 0" euler="0 30 0">
   <inertial pos="0.1 0 0" quat="0.9 0.1 0.2 0.3" mass="1" diaginertia="0.05 0.04 0.03"/>
   <site name="bs" pos="0 0.1 0"/>
   <body name="c" pos="0.3 0 0"><joint name="j2" type="slide" axis="1 0 0"/>
    <inertial pos="0 0 0" mass="0.5" diaginertia="0.01 0.01 0.01"/></body>
  </body>
 </body>
</worldbody></mujoco>"""
    mjmodel, model = _load(xml)
    assert model.names == ("a", "c") and model.frame_parents[model.frame_names.index("b")] == 0
    assert model.mass[0] == pytest.approx(3.0)
    R_b = mbjax._src.model.mjcf.quat_matrix(mjmodel.body_quat[2])
    com_b = np.array([0.5, 0, 0]) + R_b @ [0.1, 0, 0]
    np.testing.assert_allclose(model.com[0], (2 * np.array([0.2, 0.1, 0]) + com_b) / 3
                               - [0.1, 0, 0], atol=1e-12)             # in the frame at the anchor
    _check(mjmodel, model)

    _, model = _load(f"""<mujoco>{NO_CONTACT}<worldbody><body><joint pos="0.1 0 0"/><inertial
        pos="0.2 0.1 0" mass="2" fullinertia="0.3 0.2 0.25 0.01 -0.02 0.03"/></body></worldbody>
        </mujoco>""")
    np.testing.assert_allclose(model.com[0], [0.1, 0.1, 0.0], atol=1e-12)
    np.testing.assert_allclose(model.inertia[0], [[0.3, 0.01, -0.02], [0.01, 0.2, 0.03],
                                                  [-0.02, 0.03, 0.25]], atol=1e-12)


def test_joint_data():
    """Limits, armature, damping, dry friction and actuator force limits as MJCF gives them;
    actuators' armature and damping (MuJoCo >= 4) join the joint's, scaled by gear^2."""
    has_actuator_armature = hasattr(mujoco.MjModel, "actuator_armature")
    extra = ' armature="0.2" damping="0.4"' if has_actuator_armature else ""
    xml = f"""
<mujoco>{NO_CONTACT}<compiler angle="radian"/><worldbody>
 <body name="a"><joint name="j1" axis="0 1 0" range="-1 1" limited="true" damping="0.5"
   armature="0.1" frictionloss="0.3" actuatorfrcrange="-5 7" actuatorfrclimited="true"/>
  <geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.05"/>
  <body name="b" pos="0.4 0 0"><joint name="j2" type="slide" axis="1 0 0" range="-0.1 0.2"
    limited="true" armature="0.03"/><geom type="sphere" size="0.1"/></body>
 </body>
</worldbody>
<actuator><motor joint="j2" gear="3"{extra}/></actuator></mujoco>"""
    mjmodel = mujoco.MjModel.from_xml_string(xml)
    with pytest.warns(ModelWarning, match="actuator forces"):
        model = mbjax.model.from_mujoco(mjmodel)
    np.testing.assert_allclose(model.lower, [-1, -0.1])
    np.testing.assert_allclose(model.upper, [1, 0.2])
    np.testing.assert_allclose(model.friction, [0.3, 0])
    np.testing.assert_allclose(model.effort_limit, [7, np.inf])
    scale = 9.0 if has_actuator_armature else 0.0
    np.testing.assert_allclose(model.armature, [0.1, 0.03 + 0.2 * scale])
    np.testing.assert_allclose(model.damping, [0.5, 0.4 * scale])
    _check(mjmodel, model)


# --------------------------------------------------------------------------------------------
# Connect and weld closures
# --------------------------------------------------------------------------------------------

SOFT = 'solimp="0.9999 0.9999 0.001"'    # MuJoCo's stiffest equality: 1e-4 regularization

CONNECT = f"""
<mujoco>{NO_CONTACT}<worldbody>
 <site name="pin" pos="0.1 0.05 0.6"/>
 <body name="l1" pos="0 0 1"><joint name="h1" axis="0 1 0"/>
  <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.03"/>
  <body name="l2" pos="0.5 0 0"><joint name="h2" axis="0 1 0"/>
   <geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.03"/>
   <body name="l3" pos="0 0 -0.5"><joint name="b3" type="ball"/>
    <geom type="capsule" fromto="0 0 0 -0.4 0.05 0.1" size="0.03"/>
    <site name="end" pos="-0.4 0.05 0.1"/>
   </body>
  </body>
 </body>
</worldbody>
<equality>{{}}</equality></mujoco>"""

WELD = f"""
<mujoco>{NO_CONTACT}<worldbody>
 <body name="a1" pos="0 0 1"><joint name="ax" axis="1 0 0"/><joint name="ay" axis="0 1 0"/>
  <geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.03"/>
  <body name="a2" pos="0.4 0 0"><joint name="az" axis="0 0 1"/><joint name="as" type="slide"
    axis="1 0 0"/><geom type="capsule" fromto="0 0 0 0.3 0 -0.2" size="0.03"/></body>
 </body>
 <body name="b1" pos="0.7 0 0.5" euler="0 20 0"><joint name="bb" type="ball"/>
  <geom type="capsule" fromto="0 0 0 0 0 0.3" size="0.03"/></body>
</worldbody>
<equality><weld body1="a2" body2="b1" anchor="0.05 0.1 0.2" {SOFT}/></equality></mujoco>"""


def _constrained_qacc(xml, qpos, qfrc):
    """MuJoCo at rest at qpos under qfrc with its equality constraints on: (hard, soft, qacc).
    From MuJoCo's M, constraint Jacobian J, qacc_smooth a0 and regularization R: the hard
    solution a0 - M^-1 J^T (J M^-1 J^T)^-1 J a0, the soft one with J M^-1 J^T + R (what MuJoCo
    solves; at rest and on the constraint the reference acceleration is zero), and MuJoCo's."""
    m = mujoco.MjModel.from_xml_string(xml)
    bits = mujoco.mjtDisableBit
    m.opt.disableflags |= int(bits.mjDSBL_CONTACT | bits.mjDSBL_LIMIT | bits.mjDSBL_FRICTIONLOSS
                              | bits.mjDSBL_ACTUATION | bits.mjDSBL_SPRING)
    m.opt.jacobian = mujoco.mjtJacobian.mjJAC_DENSE
    d = mujoco.MjData(m)
    d.qpos[:], d.qfrc_applied[:] = qpos, qfrc
    mujoco.mj_forward(m, d)
    M = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, M)
    J, a0 = d.efc_J.reshape(d.nefc, m.nv), d.qacc_smooth
    MiJt = np.linalg.solve(M, J.T)
    hard = a0 - MiJt @ np.linalg.solve(J @ MiJt, J @ a0)
    soft = a0 - MiJt @ np.linalg.solve(J @ MiJt + np.diag(d.efc_R), J @ a0 - d.efc_aref)
    return hard, soft, d.qacc.copy()


def _check_closure(xml, kind, assembled=True):
    """The cut joint has MuJoCo's residual and, where qpos0 is assembled (Phi(qpos0) = 0), the
    loop's acceleration is MuJoCo's with the constraint hard."""
    mjmodel = mujoco.MjModel.from_xml_string(xml)
    with pytest.warns(ModelWarning, match="model.closures"):
        model = mbjax.model.from_mujoco(mjmodel)
    cuts = model.closures
    assert len(cuts) == 1 and isinstance(cuts[0], CutJoint) and cuts[0].kind == kind
    loops = Loops(TreeSystem(model), cuts)
    phi = jax.jit(Loops.phi)

    # the residual's zero set is MuJoCo's: the same position error and, for a weld, the rotation
    # error vee(R - R^T) / 2 = 2 w * (x, y, z) of MuJoCo's quaternion error (w, x, y, z)
    m, d = random_state(mjmodel, 0)
    m.opt.disableflags &= ~int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
    mujoco.mj_forward(m, d)
    efc = d.efc_pos[d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY]
    residual = np.asarray(phi(loops, jnp.asarray(d.qpos)))
    np.testing.assert_allclose(residual[:3], efc[:3], atol=1e-12)
    if kind == Weld():
        ids = [m.eq_obj1id[0], m.eq_obj2id[0]]
        if m.eq_objtype[0] == int(mujoco.mjtObj.mjOBJ_SITE):      # the two sites' frames
            bodies, turns = m.site_bodyid[ids], m.site_quat[ids]
        else:                                                   # body 1 turned by relpose
            bodies, turns = ids, np.array([m.eq_data[0, 6:10], [1.0, 0, 0, 0]])
        quat_a, quat_b, error = np.zeros(4), np.zeros(4), np.zeros(4)
        mujoco.mju_mulQuat(quat_a, d.xquat[bodies[0]], turns[0])
        mujoco.mju_mulQuat(quat_b, d.xquat[bodies[1]], turns[1])
        mujoco.mju_negQuat(quat_b, quat_b.copy())
        mujoco.mju_mulQuat(error, quat_b, quat_a)               # neg(q_b) * q_a
        np.testing.assert_allclose(efc[3:], error[1:], atol=1e-12)
        np.testing.assert_allclose(residual[3:], 2 * error[0] * error[1:], atol=1e-12)
    if not assembled:
        return
    np.testing.assert_allclose(phi(loops, jnp.asarray(mjmodel.qpos0)), 0.0, atol=1e-12)

    # at rest at qpos0 under random forces, the loop's acceleration is the hard limit of the
    # regularized problem MuJoCo solves
    qfrc = np.random.default_rng(1).normal(size=model.nv)
    hard, soft, qacc = _constrained_qacc(xml, mjmodel.qpos0, qfrc)
    system = ClosedSystem(TreeSystem(model, control=jnp.asarray(qfrc)), cuts)
    a = jax.jit(ClosedSystem.acceleration)(system, 0.0, jnp.asarray(mjmodel.qpos0),
                                           jnp.zeros(model.nv))
    scale = max(1.0, np.abs(hard).max())
    assert np.abs(np.asarray(a) - hard).max() / scale < TOLERANCE
    assert np.abs(qacc - soft).max() / scale < 1e-6


@pytest.mark.parametrize("equality", [
    f'<connect body1="l3" body2="world" anchor="-0.4 0.05 0.1" {SOFT}/>',
    f'<connect body1="l3" body2="l1" anchor="-0.4 0.05 0.1" {SOFT}/>',
    f'<connect site1="end" site2="pin" {SOFT}/>',
])
def test_connect_closure(equality):
    _check_closure(CONNECT.format(equality), Spherical())


def test_weld_closure():
    _check_closure(WELD, Weld())
    sites = WELD.replace('<geom type="capsule" fromto="0 0 0 0 0 0.3" size="0.03"/>',
                         '<geom type="capsule" fromto="0 0 0 0 0 0.3" size="0.03"/>'
                         '<site name="sb" pos="0 0.1 0.3" euler="10 0 40"/>')
    sites = sites.replace('axis="1 0 0"/><geom', 'axis="1 0 0"/><site name="sa" pos="0.3 0 -0.2" '
                          'euler="0 -30 5"/><geom')
    sites = sites.replace('body1="a2" body2="b1" anchor="0.05 0.1 0.2"', 'site1="sa" site2="sb"')
    assert 'site1="sa"' in sites and 'name="sa"' in sites and 'name="sb"' in sites
    _check_closure(sites, Weld(), assembled=False)


# --------------------------------------------------------------------------------------------
# What mbjax does not model; strict; errors
# --------------------------------------------------------------------------------------------

IGNORED = """
<mujoco><worldbody><geom type="plane" size="1 1 0.1"/>
 <body name="a" pos="0 0 1"><joint name="j1" axis="0 1 0" stiffness="10"/>
  <geom type="sphere" size="0.1"/>
  <body name="b" pos="0.3 0 0"><joint name="j2" axis="0 1 0"/><geom type="sphere" size="0.1"/>
  </body>
 </body>
</worldbody>
<tendon><fixed name="t"><joint joint="j1" coef="1"/><joint joint="j2" coef="-1"/></fixed></tendon>
<equality><joint joint1="j1" joint2="j2"/><connect body1="b" body2="world" anchor="0 0 0"/></equality>
<actuator><motor joint="j1"/></actuator></mujoco>"""


def test_ignored_features_are_named_in_one_warning():
    mjmodel = mujoco.MjModel.from_xml_string(IGNORED)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        model = mbjax.model.from_mujoco(mjmodel)
    assert len(caught) == 1 and issubclass(caught[0].category, ModelWarning)
    message = str(caught[0].message)
    for what in ("contacts in TreeSystem(model) (2 geom pairs", "actuator forces (1", "tendons (1)",
                 "joint, tendon, flex and distance equality constraints (1)",
                 "connect and weld equality constraints in TreeSystem(model) (1; they are "
                 "model.closures"):
        assert what in message, message
    assert model.nv == 2
    assert len(model.closures) == 1 and model.closures[0].kind == Spherical()
    _check(mjmodel, model)       # with what mbjax ignores switched off in MuJoCo


SPRINGS = f"""
<mujoco><compiler angle="radian"/>{NO_CONTACT}<worldbody>
 <body name="a" pos="0 0 1"><joint name="h" axis="0 1 0" stiffness="30" springref="0.4" ref="0.2"
   damping="0.3"/><geom type="capsule" size="0.05" fromto="0 0 0 0.3 0 0"/>
  <body name="b" pos="0.3 0 0"><joint name="s" type="slide" axis="1 0 0" stiffness="50"
    springref="-0.1"/><geom type="sphere" size="0.1"/>
   <body name="c" pos="0.2 0 0"><joint name="ball" type="ball" stiffness="5"/>
    <geom type="box" size="0.1 0.05 0.02"/></body>
  </body>
 </body>
</worldbody></mujoco>"""


def test_hinge_and_slide_springs_are_modelled_as_mujoco():
    """Hinge and slide springs (stiffness, springref, with a joint ref) give MuJoCo's qacc; a
    ball joint's spring is named as left out, and the tree's energy counts the springs'."""
    mjmodel = mujoco.MjModel.from_xml_string(SPRINGS)
    with pytest.warns(ModelWarning, match=r"springs on ball and free joints \(1\)"):
        model = mbjax.model.from_mujoco(mjmodel)
    np.testing.assert_array_equal(model.stiffness, [30, 50, 0, 0, 0])
    np.testing.assert_array_equal(model.spring_reference[:2], [0.4, -0.1])
    _check(mjmodel, model)
    # the energy with the springs is conserved along an undamped, unforced motion
    undamped = eqx.tree_at(lambda m: m.damping, model, jnp.zeros(model.nv))
    q = jnp.concatenate([jnp.array([0.7, 0.1]), jnp.array([0.9, 0.1, 0.3, 0.3])])
    q = q.at[2:].set(q[2:] / jnp.linalg.norm(q[2:]))
    system = TreeSystem(undamped)
    sol = mbjax.simulate(system, mbjax.integrate.RK4(), q, jnp.array([0.0, 0.5, 1.0, 0.0, -1.0]),
                         dt=1e-3, t1=0.5, saveat=jnp.array([0.0, 0.5]))
    energy = jax.jit(TreeSystem.energy)
    start, end = (energy(system, sol.qs[i], sol.vs[i]) for i in (0, -1))
    assert abs(end - start) < 1e-8 * abs(start), (start, end)
    spring = 0.5 * (30 * (0.7 - 0.4) ** 2 + 50 * (0.1 + 0.1) ** 2)
    no_spring = eqx.tree_at(lambda m: m.stiffness, undamped, jnp.zeros(model.nv))
    assert abs(energy(system, q, jnp.zeros(5)) - energy(TreeSystem(no_spring), q, jnp.zeros(5))
               - spring) < 1e-12


def test_strict():
    """strict=True refuses implausible inertias, not the features mbjax leaves out."""
    with pytest.warns(ModelWarning, match="contacts"):
        mbjax.model.from_mujoco(mujoco.MjModel.from_xml_string(IGNORED), strict=True)
    mjmodel, _ = _load(DEFAULTS, strict=True)
    mjmodel.body_inertia[1] = [0.01, 0.01, 0.05]            # J1 + J2 < J3: passed on to Model
    with pytest.warns(ModelWarning, match="triangle inequality"):
        mbjax.model.from_mujoco(mjmodel)
    with pytest.raises(ValueError, match="triangle inequality"):
        mbjax.model.from_mujoco(mjmodel, strict=True)


def test_errors(monkeypatch):
    with pytest.raises(ValueError, match="no joints"):
        mbjax.load_mjcf("<mujoco><worldbody><geom size='1'/></worldbody></mujoco>")
    with pytest.raises(ValueError):
        mbjax.load_mjcf("/nonexistent/model.xml")
    monkeypatch.setitem(sys.modules, "mujoco", None)
    with pytest.raises(ImportError, match="pip install mujoco"):
        mbjax.load_mjcf(DEFAULTS)


def test_parameters_are_differentiable():
    """The loaded model's arrays are leaves: the acceleration differentiates w.r.t. the masses."""
    _, model = _load(DEFAULTS)
    q, v, tau = model.neutral() + 0.1, jnp.ones(model.nv), jnp.zeros(model.nv)

    @jax.jit
    @jax.grad
    def gradient(scale):
        scaled = eqx.tree_at(lambda m: m.mass, model, model.mass * scale)
        return mbjax.forward_dynamics(scaled, q, v, tau).sum()

    assert np.isfinite(gradient(1.0)) and gradient(1.0) != 0


# --------------------------------------------------------------------------------------------
# The corpus: every MJCF model of the installed packages
# --------------------------------------------------------------------------------------------


def _assert_rows(found):
    bad = [row for row in found if not (row["loads"]
                                        and row["max_relative_difference"] is not None
                                        and row["max_relative_difference"] < TOLERANCE
                                        and row["max_pose_difference"] < 1e-10)]
    assert not bad, bad


def test_corpus_subset():
    """A representative subset (`mjcf_corpus.QUICK`): planar chains, free bases, ball joints,
    several joints per body, tendons and equality constraints ignored, ref offsets."""
    paths = quick_paths()
    if not paths:
        pytest.skip("no package of the MJCF corpus is installed")
    _assert_rows(rows(paths))


@pytest.mark.slow
def test_corpus():
    found, skipped = survey()
    if not found:
        pytest.skip("no package of the MJCF corpus is installed")
    _assert_rows(found)
    assert all(row["reason"] for row in skipped)
