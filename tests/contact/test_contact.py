"""Contacts with the ground (issue 45) against Pinocchio's `constraintDynamics` and
`impulseDynamics` on robots no one here wrote: ANYmal on its four feet (point contacts) and
Talos on its two soles (surface contacts), both from example-robot-data, with Crocoddyl's
Baumgarte gains (Kp, Kd) = (0, 50) in both engines; the O(n + m^3) route against the dense one."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import mbjax
from mbjax._src.contact.stance import CROCODDYL_GAINS
from mbjax.contact import PointContact, SurfaceContact, contact_wrenches, impulse, stance
from mbjax.control import Constant
from mbjax.loops import Coupled, Stabilized
from mbjax.model import state_to_pinocchio
from mbjax.rigid import TreeSystem, frame_jacobian
from tests.conftest import example_robots

pin = pytest.importorskip("pinocchio")

ANYMAL = ("anymal_b_simple/anymal", ["LF_FOOT", "LH_FOOT", "RF_FOOT", "RH_FOOT"], PointContact)
TALOS = ("talos_data/talos_reduced", ["left_sole_link", "right_sole_link"], SurfaceContact)


def _path(name: str):
    return example_robots([name])[0]


def _pinocchio(path, feet, kind, q_pin, v_pin, tau_pin, gains, v_before, anchors=None):
    """Pinocchio's constrained accelerations and contact forces (LOCAL_WORLD_ALIGNED, (f; tau)
    per contact) at (q, v), and its impulse map's velocity and impulses from v_before; each
    contact anchored at its frame's placement, or at `anchors` (SE3s)."""
    pm = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    pd = pm.createData()
    contact_type = pin.ContactType.CONTACT_3D if kind is PointContact else pin.ContactType.CONTACT_6D
    models = []
    for foot in feet:
        frame = pm.frames[pm.getFrameId(foot)]
        model = pin.RigidConstraintModel(contact_type, pm, frame.parentJoint, frame.placement,
                                         pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        model.setBaumgarteCorrectorParameters(pin.BaumgarteCorrectorParameters(*gains))
        if anchors is not None:
            model.joint2_placement = anchors[len(models)]
        models.append(model)
    models = pin.StdVec_RigidConstraintModel(models)
    datas = pin.StdVec_RigidConstraintData([m.createData() for m in models])
    settings = pin.ProximalSettings(1e-14, 1e-14, 1)
    pin.initConstraintDynamics(pm, pd, models, datas)
    a = pin.constraintDynamics(pm, pd, q_pin, v_pin, tau_pin, models, datas, settings).copy()
    forces = pd.lambda_c.copy()
    pin.initConstraintDynamics(pm, pd, models, datas)
    v_plus = pin.impulseDynamics(pm, pd, q_pin, v_before, models, datas, 0.0, settings).copy()
    return a, forces, v_plus, pd.impulse_c.copy()


def _world_pairs(wrenches, size):
    """mbjax's (torque; force) per contact as Pinocchio's (f; tau), or (f) for a point."""
    w = np.asarray(wrenches)
    return (w[:, 3:] if size == 3 else np.concatenate([w[:, 3:], w[:, :3]], 1)).ravel()


def _random_state(model, rng):
    """(q, v, tau): a configuration within the joints' limits near home, a velocity and a
    torque, random."""
    q = model.normalize(jnp.clip(model.home() + jnp.asarray(rng.uniform(-0.2, 0.2, model.nq)),
                                 model.lower, model.upper))
    return q, jnp.asarray(rng.normal(size=model.nv)), jnp.asarray(rng.normal(size=model.nv))


def _rel(a, b):
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / max(1.0, np.max(np.abs(b))))


@pytest.mark.parametrize("robot", [ANYMAL, TALOS], ids=["anymal", "talos"])
def test_contact_dynamics_agree_with_pinocchio(robot):
    """At a random configuration, velocity and torque: the accelerations and the ground's
    reactions of `stance` (Coupled, Crocoddyl's gains) equal Pinocchio's `constraintDynamics` on
    the same contacts; the impulse map equals its `impulseDynamics`. At a state on the contacts
    (velocity in A's null space) the O(n + m^3) route gives the same motion and reactions."""
    name, feet, kind = robot
    path = _path(name)
    model = mbjax.load_urdf(path, floating_base=True)
    rng = np.random.default_rng(0)
    q, v, tau = _random_state(model, rng)
    contacts = [kind(foot) for foot in feet]
    v_before = v
    v_plus, impulses = impulse(model, q, v_before, contacts)
    if kind is SurfaceContact:
        # a moving sole's constraint acceleration is a convention: Pinocchio's 6-D contact holds
        # the frame's spatial acceleration at zero, a weld its classical one (they differ by
        # omega x v); on the ground, where the sole is at rest, they are one
        v = v_plus
    phase = stance(TreeSystem(model, Constant(tau)), q, contacts)
    a = phase.acceleration(0.0, q, v)
    wrenches = contact_wrenches(phase, 0.0, q, v)

    q_pin, v_pin = (np.asarray(x) for x in state_to_pinocchio(model, q, v))
    P = np.asarray(jax.jacfwd(lambda v_: state_to_pinocchio(model, q, v_)[1])(v))   # v_pin = P v
    a_pin, forces, v_plus_pin, impulses_pin = _pinocchio(
        path, feet, kind, q_pin, v_pin, P @ np.asarray(tau - model.damping * v),   # URDF damping:
        (0.0, 2 * CROCODDYL_GAINS[0]), P @ np.asarray(v_before))                  # Pinocchio's none
    assert _rel(P @ np.asarray(a), a_pin) < 1e-9
    assert _rel(_world_pairs(wrenches, kind.size), forces) < 1e-9
    assert _rel(P @ np.asarray(v_plus), v_plus_pin) < 1e-9
    assert _rel(_world_pairs(impulses, kind.size), impulses_pin) < 1e-9
    # after the impulse every contact frame is at rest
    for foot in feet:
        rows = slice(3, 6) if kind is PointContact else slice(0, 6)
        assert np.abs(np.asarray(frame_jacobian(model, q, foot) @ v_plus)[rows]).max() < 1e-9

    # the first foot in the air (active=False): Pinocchio's dynamics on the other feet alone,
    # and a zero wrench on the lifted one
    lifted = [kind(foot, active=i > 0) for i, foot in enumerate(feet)]
    phase = stance(TreeSystem(model, Constant(tau)), q, lifted)
    a_pin, forces, v_plus_pin, impulses_pin = _pinocchio(
        path, feet[1:], kind, q_pin, v_pin, P @ np.asarray(tau - model.damping * v),
        (0.0, 2 * CROCODDYL_GAINS[0]), P @ np.asarray(v_before))
    wrenches = contact_wrenches(phase, 0.0, q, v)
    v_up, impulses_up = impulse(model, q, v_before, lifted)
    assert _rel(P @ np.asarray(phase.acceleration(0.0, q, v)), a_pin) < 1e-9
    assert _rel(_world_pairs(wrenches[1:], kind.size), forces) < 1e-9
    assert _rel(P @ np.asarray(v_up), v_plus_pin) < 1e-9
    assert _rel(_world_pairs(impulses_up[1:], kind.size), impulses_pin) < 1e-9
    assert not np.any(np.asarray(wrenches[0])) and not np.any(np.asarray(impulses_up[0]))

    # on the contacts, the O(n + m^3) route equals the dense one (no stabilization acts)
    coupled = stance(TreeSystem(model, Constant(tau)), q, contacts, method=Coupled())
    recursive = stance(TreeSystem(model, Constant(tau)), q, contacts, method=Stabilized())
    on = v_plus
    a_dense = coupled.acceleration(0.0, q, on)
    np.testing.assert_allclose(recursive.acceleration(0.0, q, on), a_dense, rtol=1e-8,
                               atol=1e-8 * float(jnp.abs(a_dense).max()))
    w_dense = contact_wrenches(coupled, 0.0, q, on)
    np.testing.assert_allclose(contact_wrenches(recursive, 0.0, q, on), w_dense,
                               rtol=1e-8, atol=1e-8 * float(jnp.abs(w_dense).max()))


def test_bad_contacts_are_refused_by_name():
    model = mbjax.load_urdf(mbjax.data.ARM7)
    q = model.home()
    with pytest.raises(KeyError, match="no frame, body or joint named 'toe'"):
        stance(TreeSystem(model), q, [PointContact("toe")])
    with pytest.raises(ValueError, match="normal must be a nonzero vector"):
        PointContact("flange", normal=(0.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="normal"):
        SurfaceContact("flange", normal=(0.0, float("nan"), 1.0))
    with pytest.raises(ValueError, match="active must be True or False, got 0.5"):
        PointContact("flange", active=0.5)
    with pytest.raises(TypeError, match="contacts must be one or more PointContact"):
        stance(TreeSystem(model), q, [])
    with pytest.raises(TypeError, match="tree must be a rigid tree system"):
        stance(model, q, [PointContact("flange")])


def test_anymal_stands_on_its_four_feet():
    """ANYmal with its legs servoed to a pose, simulated for 1 s on its four feet: the run
    succeeds, the feet stay where they were (the stabilized closures), and once it has settled
    the ground carries its weight, the vertical reactions summing to m g (the whole robot's
    momentum balance, an identity no part of the stance computes)."""
    from mbjax.control import PD
    from mbjax.integrate import RK4
    model = mbjax.load_urdf(_path(ANYMAL[0]), floating_base=True)
    q0, v0 = model.home().at[2].set(0.5), jnp.zeros(model.nv)
    feet = [PointContact(foot) for foot in ANYMAL[1]]
    legs = PD(kp=200.0, kd=10.0, q_ref=q0[7:], q_index=range(7, 19), v_index=range(6, 18))
    phase = stance(TreeSystem(model, legs, actuation=range(6, 18)), q0, feet)
    sol = mbjax.simulate(phase, RK4(), q0, v0, dt=1e-3, t1=1.0, saveat=[1.0])
    assert sol.messages() == ["success"]
    for foot in feet:
        moved = (mbjax.rigid.frame_pose(model, sol.qs[-1], foot.frame)[1]
                 - mbjax.rigid.frame_pose(model, q0, foot.frame)[1])
        assert float(jnp.abs(moved).max()) < 1e-8
    wrenches = contact_wrenches(phase, 1.0, sol.qs[-1], sol.vs[-1])
    weight = float(model.mass.sum()) * 9.81
    assert float(wrenches[:, 5].sum()) == pytest.approx(weight, rel=1e-6)
    assert np.all(np.asarray(wrenches[:, :3]) == 0.0)       # a point contact carries no torque


@pytest.mark.slow
def test_a_schedule_flags_a_foot_that_pulls():
    """ANYmal servoed to a pose, on four feet and then on three: on four the run succeeds and
    the lifted foot carries nothing afterwards; on three, with the pose held, the diagonal
    foot must pull on the ground to keep the body up (its centre of mass lies outside the
    support triangle: it first pushes, then pulls), which the friction watch reports as
    PULLING in that phase alone; at
    the touchdown of the next phase the landing foot stops at once (the impulse)."""
    from mbjax.contact import simulate_schedule
    from mbjax.control import PD
    from mbjax import Status
    from mbjax.integrate import RK4
    model = mbjax.load_urdf(_path(ANYMAL[0]), floating_base=True)
    q0, v0 = model.home().at[2].set(0.5), jnp.zeros(model.nv)
    feet = [PointContact(foot) for foot in ANYMAL[1]]
    legs = PD(kp=200.0, kd=10.0, q_ref=q0[7:], q_index=range(7, 19), v_index=range(6, 18))
    tree = TreeSystem(model, legs, actuation=range(6, 18))
    lifted = feet[3]                                                  # RH_FOOT
    sol = simulate_schedule(tree, RK4(), q0, v0, [(feet, 0.1), (feet[:3], 0.2), (feet, 0.02)],
                            dt=2e-3, mu=0.7)
    codes = [int(c) for c in sol.phase_status]
    assert codes[0] == 0 and codes[1] & Status.PULLING and not sol.ok
    assert "pulling (in phase 1" in sol.messages()[0]
    off = np.asarray(sol.phases) == 1
    assert np.all(np.asarray(sol.wrenches)[off, sol.frames.index(lifted.frame)] == 0.0)
    diagonal = np.asarray(sol.wrenches)[off][:, sol.frames.index("LF_FOOT"), 5]
    assert diagonal[0] > 0.0 and diagonal.min() < 0.0               # first pushes, then pulls
    # the landing foot is at rest right after its touchdown
    first = int(np.flatnonzero(np.asarray(sol.phases) == 2)[0])
    J = frame_jacobian(model, sol.qs[first], lifted.frame)
    assert float(jnp.abs(J[3:] @ sol.vs[first]).max()) < 1e-2


def test_a_moving_sole_holds_pinocchios_spatial_acceleration():
    """Talos on its two soles with `SurfaceContact(spatial=True)`, at a velocity that moves
    both soles, with Pinocchio's Baumgarte gains (Kp, Kd) = (100, 50): the accelerations and
    the soles' wrenches equal Pinocchio's `constraintDynamics` with `CONTACT_6D` (which holds
    the spatial acceleration) to 1e-9, while the classical weld differs by omega x v. Off the
    anchors, where the position term acts, the wrenches of both conventions stay exact (the
    soles' frame Jacobians' transpose of them is the constraint force A^t K), and the spatial
    convention's motion agrees with Pinocchio's to first order in the anchor's offset (its
    position error agrees with Pinocchio's SE(3) logarithm to first order)."""
    name, feet, _ = TALOS
    path = _path(name)
    model = mbjax.load_urdf(path, floating_base=True)
    rng = np.random.default_rng(3)
    q, v, tau = _random_state(model, rng)
    gains = (100.0, 50.0)                                # Pinocchio's (Kp, Kd)
    method = Coupled(baumgarte=(gains[1] / 2, np.sqrt(gains[0])))
    tree = TreeSystem(model, Constant(tau))
    q_pin, v_pin = (np.asarray(x) for x in state_to_pinocchio(model, q, v))
    P = np.asarray(jax.jacfwd(lambda v_: state_to_pinocchio(model, q, v_)[1])(v))
    pm = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    pd = pm.createData()

    def pinocchio(q_anchor):
        pin.framesForwardKinematics(pm, pd, np.asarray(state_to_pinocchio(model, q_anchor, v)[0]))
        anchors = [pd.oMf[pm.getFrameId(f)].copy() for f in feet]
        return _pinocchio(path, feet, SurfaceContact, q_pin, v_pin,
                          P @ np.asarray(tau - model.damping * v), gains, v_pin, anchors)[:2]

    def phases(q_anchor):
        return [stance(tree, q_anchor, [SurfaceContact(f, spatial=spatial) for f in feet],
                       method=method) for spatial in (True, False)]

    a_pin, forces = pinocchio(q)
    spatial, weld = phases(q)
    assert _rel(P @ np.asarray(spatial.acceleration(0.0, q, v)), a_pin) < 1e-9
    assert _rel(_world_pairs(contact_wrenches(spatial, 0.0, q, v), 6), forces) < 1e-9
    assert _rel(P @ np.asarray(weld.acceleration(0.0, q, v)), a_pin) > 1e-3

    errors = []
    for offset in (1e-2, 1e-3):
        q_anchor = model.integrate(q, jnp.asarray(rng.normal(size=model.nv)) * offset)
        a_pin, _ = pinocchio(q_anchor)
        for phase in phases(q_anchor):
            w = np.asarray(contact_wrenches(phase, 0.0, q, v))
            generalized = np.asarray(phase.loops.force(q, phase.multipliers(0.0, q, v)))
            from_wrenches = sum(np.asarray(frame_jacobian(model, q, f)).T @ w[i]
                                for i, f in enumerate(feet))
            assert _rel(from_wrenches, generalized) < 1e-10
        errors.append(_rel(P @ np.asarray(phases(q_anchor)[0].acceleration(0.0, q, v)), a_pin))
    assert errors[1] < errors[0] / 5         # first order in the offset
