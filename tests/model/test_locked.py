"""`Model.locked` (`mbjax._src.model.locked.lock_joints`) against Pinocchio's `buildReducedModel`:
mass matrices, forward dynamics and frame placements of example-robot-data robots with joints
locked (a gripper, a leg chain, two consecutive joints, a floating base's root joint), and its
errors."""

import warnings
from functools import lru_cache

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import mbjax
from mbjax._src.model.checks import ModelWarning
from mbjax._src.rigid.frames import frame_poses
from mbjax._src.rigid.kinematics import forward_kinematics
from mbjax_harness.peers import random_state

pin = pytest.importorskip("pinocchio")


@lru_cache(maxsize=None)
def _robot(stem: str, floating: bool):
    """(mbjax model, Pinocchio model) of an example-robot-data URDF."""
    from mbjax_harness.reproduce.urdf_corpus import corpus_paths
    try:
        path = str(next(p for p in corpus_paths() if p.stem == stem))
    except Exception as err:                          # PackageNotFoundError, StopIteration
        pytest.skip(f"example-robot-data's {stem} is not available ({err})")
    pm = pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer()) if floating else \
        pin.buildModelFromUrdf(path)
    with warnings.catch_warnings():          # the panda's mimic joint (its closure) is noted
        warnings.simplefilter("ignore", ModelWarning)
        return mbjax.load_urdf(path, floating_base=floating), pm


@jax.jit
def _mbjax(model, q, v, tau):
    return (mbjax.forward_dynamics(model, q, v, tau), mbjax.mass_matrix(model, q),
            frame_poses(model, q), forward_kinematics(model, q))


def _pin_state(model, q, v):
    return tuple(np.asarray(x) for x in mbjax.model.state_to_pinocchio(model, q, v))


def _rel(x, ref):
    """The largest difference relative to the reference's largest entry (at least 1)."""
    return np.abs(x - ref).max() / max(1.0, np.abs(ref).max())


def _check_reduced(stem, floating, joints, seed, values=None):
    """Lock `joints` at a random configuration (with `values` set by name) in mbjax and in
    Pinocchio; their mass matrices and accelerations (relative to their largest entries: a
    light leg accelerates at 1e3-1e4) and their frames agree at two random states. Returns the
    reduced model and the largest difference."""
    model, pm = _robot(stem, floating)
    q = np.array(random_state(model, seed)[0])
    starts = np.cumsum([0] + [{"free": 7, "spherical": 4}.get(t, 1) for t in model.joint_types])
    for name, value in (values or {}).items():
        q[starts[model.joint_names.index(name)]] = value
    reduced = model.locked(joints, q)
    q_pin, _ = _pin_state(model, q, np.zeros(model.nv))
    pr = pin.buildReducedModel(pm, [pm.getJointId(name) for name in joints], q_pin)
    pd = pr.createData()
    assert reduced.joint_names == tuple(pr.names[1:])
    assert reduced.nq == pr.nq and reduced.nv == pr.nv
    worst = 0.0
    for s in (seed + 1, seed + 2):
        qr, vr, tau = (jnp.asarray(x) for x in random_state(reduced, s))
        qp, vp = _pin_state(reduced, qr, vr)
        P = np.asarray(jax.jacfwd(lambda v_: mbjax.model.state_to_pinocchio(reduced, qr, v_)[1])(vr))
        a, M, (R_f, p_f), (R_b, p_b) = _mbjax(reduced, qr, vr, tau)
        M_pin = pin.crba(pr, pd, qp)
        M_pin = np.triu(M_pin) + np.triu(M_pin, 1).T
        a_pin = pin.aba(pr, pd, qp, vp, P @ np.asarray(tau - reduced.damping * vr))
        diffs = [_rel(P @ np.asarray(M) @ P.T, M_pin), _rel(P @ np.asarray(a), a_pin)]
        pin.framesForwardKinematics(pr, pd, qp)
        poses = {**{n: (R_f[i], p_f[i]) for i, n in enumerate(reduced.frame_names)},
                 **{n: (R_b[i], p_b[i]) for i, n in enumerate(reduced.names)}}
        compared = [n for n in poses if pr.existFrame(n)]
        assert set(joints) <= set(compared) and len(compared) > len(reduced.names)
        for name in compared:
            oMf = pd.oMf[pr.getFrameId(name)]
            diffs += [np.abs(np.asarray(poses[name][0]) - oMf.rotation).max(),
                      np.abs(np.asarray(poses[name][1]) - oMf.translation).max()]
        worst = max(worst, *diffs)
    assert worst < 1e-9, worst
    return reduced, worst


def test_panda_fingers_locked():
    """The fingers locked open: their mimic coupling goes with them; the hand's mass stays."""
    model, _ = _robot("panda", False)
    reduced, _ = _check_reduced("panda", False, ["panda_finger_joint1", "panda_finger_joint2"], 0,
                                {"panda_finger_joint1": 0.03, "panda_finger_joint2": 0.02})
    assert reduced.n == model.n - 2 and reduced.closures == ()
    assert {"panda_leftfinger", "panda_rightfinger"} <= set(reduced.frame_names)
    np.testing.assert_allclose(reduced.mass.sum(), model.mass.sum(), rtol=1e-14)
    np.testing.assert_array_equal(reduced.upper, model.upper[:7])


def test_panda_two_consecutive_joints_locked():
    """Joints 4 and 5 locked: joint 6 hangs from link 3 through both welded links."""
    reduced, _ = _check_reduced("panda", False, ["panda_joint4", "panda_joint5"], 3)
    assert reduced.topology.parents[3] == 2 and len(reduced.closures) == 1


def test_quadruped_leg_locked():
    """solo12 on a free base with its front-left leg (three joints, a chain) locked."""
    reduced, _ = _check_reduced("solo12", True, ["FL_KFE", "FL_HAA", "FL_HFE"], 5)
    assert reduced.joint_types[0] == "free" and reduced.nv == 15


def test_root_joint_locked():
    """Locking the free joint welds the base to the ground: the legs become base bodies."""
    reduced, _ = _check_reduced("solo12", True, ["root_joint", "HR_KFE"], 7)
    assert reduced.nv == 11 and reduced.topology.parents[0] == -1
    assert "base_link" in reduced.frame_names and reduced.frame_parents[
        reduced.frame_names.index("base_link")] == -1


def test_errors():
    model, _ = _robot("panda", False)
    q = np.asarray(model.neutral())
    with pytest.raises(ValueError, match="no joint named 'elbow'"):
        model.locked(["panda_joint1", "elbow"], q)
    with pytest.raises(ValueError, match="'panda_joint2' named more than once"):
        model.locked(["panda_joint2", "panda_joint2"], q)
    with pytest.raises(ValueError, match=r"q must have shape \(9,\)"):
        model.locked(["panda_joint1"], q[:8])
    with pytest.raises(ValueError, match="every joint"):
        model.locked(model.joint_names, q)
    with pytest.raises(ValueError, match="'panda_finger_joint1' is locked, but the closure"):
        model.locked(["panda_finger_joint1"], q)           # finger 2 mimics it
