"""Controls and external wrenches against the peers, in the same run:

- a 7-link chain driven by a time-varying joint-torque history and pushed by a history of body
  wrenches, with `mbjax.control.ZeroOrderHold` and RK4, against `mujoco.rollout` given the same
  histories as `qfrc_applied` and `xfrc_applied` (held over each RK4 step, as mbjax's `hold`);
- external wrenches against Pinocchio's `aba` with `fext`, on a random chain and on a
  floating-base tree.
"""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import mbjax
from mbjax import Dense
from mbjax.control import ZeroOrderHold
from mbjax.integrate import RK4, simulate
from mbjax.model import Model, chain, random_tree
from mbjax._src.model.urdf import to_urdf
from mbjax.rigid import TreeSystem
from mbjax_harness.peers import pinocchio_maps, random_state

DT, STEPS = 1e-3, 400


def test_driven_and_pushed_chain_matches_mujoco_rollout():
    mujoco = pytest.importorskip("mujoco")
    from mujoco import rollout

    model = chain(7, seed=5)
    rng = np.random.default_rng(7)
    t = np.arange(STEPS) * DT
    torques = 2.0 * np.sin(np.outer(t, 3.0 + np.arange(7.0)) + rng.uniform(0, 6, 7)) + rng.normal(0, 0.3, (STEPS, 7))
    wrenches = 0.5 * np.sin(np.outer(t, 2.0 + np.arange(42.0))).reshape(STEPS, 7, 6)  # (torque; force)
    q0, v0, _ = random_state(model, 11)

    system = TreeSystem(model, ZeroOrderHold(torques, DT), external=ZeroOrderHold(wrenches, DT),
                        external_point=model.com)          # MuJoCo pushes at the centres of mass
    ours = simulate(system, RK4(), jnp.asarray(q0), jnp.asarray(v0), dt=DT, t1=STEPS * DT,
                    saveat=[STEPS * DT])

    mj = mujoco.MjModel.from_xml_string(to_urdf(model))
    mj.opt.timestep, mj.opt.integrator = DT, mujoco.mjtIntegrator.mjINT_RK4
    assert (mj.nq, mj.nv, mj.nbody) == (7, 7, 8)
    data = mujoco.MjData(mj)
    data.qpos[:], data.qvel[:] = q0, v0
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    initial = np.empty(mujoco.mj_stateSize(mj, spec))
    mujoco.mj_getState(mj, data, initial, spec)
    xfrc = np.zeros((STEPS, 8, 6))
    xfrc[:, 1:] = np.concatenate([wrenches[..., 3:], wrenches[..., :3]], -1)   # (force; torque)
    control = np.concatenate([torques, xfrc.reshape(STEPS, -1)], 1)[None]
    control_spec = mujoco.mjtState.mjSTATE_QFRC_APPLIED | mujoco.mjtState.mjSTATE_XFRC_APPLIED
    states, _ = rollout.rollout(mj, data, initial[None], control, control_spec=control_spec)
    qpos, qvel = states[0, -1, 1:8], states[0, -1, 8:15]

    assert ours.messages() == ["success"]
    assert np.abs(qpos - q0).max() > 0.5                          # it did move
    np.testing.assert_allclose(ours.qs[-1], qpos, rtol=0, atol=1e-12)      # measured 1.5e-14
    np.testing.assert_allclose(ours.vs[-1], qvel, rtol=0, atol=1e-11)      # measured 1.5e-13


def _pinocchio_fext(pin, pin_model, data, model, q_pin, wrenches):
    """mbjax's world wrenches (torque about the body origin; force) as Pinocchio's local joint
    forces (linear; angular, in the joint frame), one per joint (the universe's zero)."""
    pin.forwardKinematics(pin_model, data, q_pin)
    fext = pin.StdVec_Force()
    for _ in range(pin_model.njoints):
        fext.append(pin.Force.Zero())
    for k, name in enumerate(model.joint_names):
        jid = pin_model.getJointId(name)
        R = data.oMi[jid].rotation
        fext[jid] = pin.Force(R.T @ wrenches[k, 3:], R.T @ wrenches[k, :3])
    return fext


@pytest.mark.parametrize("floating", [False, True])
def test_external_wrenches_match_pinocchio_aba_with_fext(floating):
    pin = pytest.importorskip("pinocchio")
    base = chain(6, seed=8)
    if floating:                    # a branching tree on a free-flying root body
        t = random_tree(6, seed=9)
        base = Model(t.topology, ("free", *t.joint_types[1:]), mass=t.mass, inertia=t.inertia,
                     com=t.com, axis=t.axis, axis2=t.axis2, placement_rotation=t.placement_rotation,
                     placement_translation=t.placement_translation, gravity=t.gravity)
    xml = to_urdf(base)
    model = mbjax.load_urdf(xml)
    assert model.joint_types[0] == ("free" if floating else "revolute")
    pin_model = pin.buildModelFromXML(xml)
    to_pin, vi = pinocchio_maps(model, pin_model)
    data = pin_model.createData()
    rng = np.random.default_rng(3)
    wrenches = rng.normal(size=(model.n, 6))

    @jax.jit
    def ours(q, v, tau):
        system = TreeSystem(model, tau, external=lambda t, q_, v_: jnp.asarray(wrenches))
        return system.acceleration(0.0, q, v), mbjax.forward_dynamics(model, q, v, tau, f_ext=wrenches,
                                                                     method=Dense())

    for seed in (0, 1):
        q, v, tau = random_state(model, seed)
        qp, vp, tp = to_pin(q), np.zeros(model.nv), np.zeros(model.nv)
        vp[vi], tp[vi] = v, tau
        fext = _pinocchio_fext(pin, pin_model, data, model, qp, wrenches)
        expected = pin.aba(pin_model, data, qp, vp, tp, fext)[vi]
        unpushed = pin.aba(pin_model, data, qp, vp, tp)[vi]
        assert np.abs(expected - unpushed).max() > 0.1                # the wrenches matter
        for a in ours(jnp.asarray(q), jnp.asarray(v), jnp.asarray(tau)):
            np.testing.assert_allclose(a, expected, rtol=1e-10, atol=1e-10)
