"""Contacts that find themselves (`mbjax.contact.ContactSystem`): geoms read from MJCF, detected
each step and solved by MuJoCo's soft constraints, against MuJoCo itself on the same files
(a sphere, a box dropped and slid, gymnasium's Ant), joint limits, gradients against central
differences, and bad geometry named."""

import os
import warnings

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import mbjax
from mbjax.contact import ContactSystem, SoftConstraints
from mbjax.integrate import RK4, SemiImplicitEuler
from mbjax.model import Geoms, ground_plane, state_from_mujoco
from mbjax.rigid import TreeSystem

mujoco = pytest.importorskip("mujoco")

FLOOR = '<geom type="plane" size="5 5 .1"/>'


def _load(xml):
    m = mujoco.MjModel.from_xml_string(xml) if xml.lstrip().startswith("<") else \
        mujoco.MjModel.from_xml_path(xml)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = mbjax.model.from_mujoco(m)
    return m, model


def _mujoco_run(m, steps, qvel=None):
    d = mujoco.MjData(m)
    if qvel is not None:
        d.qvel[:] = qvel
    out = []
    for _ in range(steps):
        mujoco.mj_step(m, d)
        out.append(d.qpos.copy())
    return np.asarray(out)


@pytest.mark.parametrize("body, qvel, atol, rest", [
    ('<geom type="sphere" size="0.1" mass="1"/>', None, 1e-9, 0.1),
    ('<geom type="box" size="0.1 0.2 0.05" mass="1"/>', None, 1e-9, 0.05),
    ('<geom type="box" size="0.1 0.2 0.05" mass="1"/>', [1.0, 0.3, 0, 0, 0, 0], 1e-4, 0.05),
], ids=["sphere-drop", "box-drop", "box-slide"])
def test_dropped_and_slid_bodies_follow_mujoco(body, qvel, atol, rest):
    """MuJoCo's Euler step is semi-implicit Euler; the same soft constraints give the same
    motion, from the file's geoms or from the same ones written in code (the slide's remaining difference is the two integrators' free-joint coordinates:
    mbjax's body-frame velocity, MuJoCo's world-frame one)."""
    xml = (f'<mujoco><worldbody>{FLOOR}<body pos="0 0 0.3"><freejoint/>{body}</body>'
           '</worldbody></mujoco>')
    m, model = _load(xml)
    reference = _mujoco_run(m, 400, qvel)
    geoms = None
    if "sphere" in body:              # the same geometry written in code: a ball and a floor
        geoms = Geoms(("sphere",), (0,), [[0.1, 0.0, 0.0]]).join(ground_plane())
    system = ContactSystem(TreeSystem(model), geoms, timestep=m.opt.timestep)
    v0 = np.zeros(6) if qvel is None else state_from_mujoco(model, m.qpos0, np.asarray(qvel))[1]
    sol = mbjax.simulate(system, SemiImplicitEuler(), jnp.asarray(m.qpos0), jnp.asarray(v0),
                         dt=m.opt.timestep, t1=0.8)
    assert int(sol.status) == 0
    np.testing.assert_allclose(np.asarray(sol.qs[1:, :3]), reference[:, :3], atol=atol)
    assert abs(float(sol.qs[-1, 2]) - rest) < 2e-3            # resting on the floor


def test_ant_accelerations_and_fall_follow_mujoco():
    """gymnasium's Ant (capsule legs, a sphere torso, limited hips and ankles, margins): the
    accelerations at MuJoCo's own states, contacts and limits pushing, agree to round-off, and
    the torso's height through a 1 s fall and settle (RK4, as the file asks) within 1 cm."""
    gymnasium = pytest.importorskip("gymnasium")
    path = os.path.join(os.path.dirname(gymnasium.__file__), "envs/mujoco/assets/ant.xml")
    m, model = _load(path)
    system = ContactSystem(TreeSystem(model), timestep=m.opt.timestep)   # neutral(): qpos0
    acceleration = jax.jit(lambda q, v: system.acceleration(0.0, q, v))
    d = mujoco.MjData(m)
    pushing = 0
    for step in range(100):
        mujoco.mj_step(m, d)
        if step % 5 == 4:
            mujoco.mj_forward(m, d)
            q, v = state_from_mujoco(model, d.qpos, d.qvel)
            a = np.asarray(acceleration(q, v))
            np.testing.assert_allclose(a[6:], d.qacc[6:], atol=1e-9 * (1 + np.abs(d.qacc).max()))
            pushing += d.nefc > 0
    assert pushing >= 5
    reference = _mujoco_run(m, 100)
    sol = mbjax.simulate(system, RK4(), jnp.asarray(m.qpos0), jnp.zeros(m.nv),
                         dt=m.opt.timestep, t1=1.0)
    assert int(sol.status) == 0
    np.testing.assert_allclose(np.asarray(sol.qs[1:, 2]), reference[:, 2], atol=1e-2)


def test_joint_limit_holds_as_mujoco():
    """A damped hinge pendulum falling onto its limit: the limit's soft constraint stops it as
    MuJoCo's does, MuJoCo's Euler step (damping taken implicitly) to round-off."""
    xml = ('<mujoco><worldbody><body><joint type="hinge" axis="0 1 0" range="-30 30" '
           'damping="0.2"/>'
           '<geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.05" mass="1" contype="0" '
           'conaffinity="0"/></body></worldbody></mujoco>')
    m, model = _load(xml)
    reference = _mujoco_run(m, 500)
    system = ContactSystem(TreeSystem(model), timestep=m.opt.timestep, implicit_damping=True)
    sol = mbjax.simulate(system, SemiImplicitEuler(), jnp.asarray(m.qpos0), jnp.zeros(1),
                         dt=m.opt.timestep, t1=1.0)
    np.testing.assert_allclose(np.asarray(sol.qs[1:, 0]), reference[:, 0], atol=1e-9)
    explicit = mbjax.simulate(ContactSystem(TreeSystem(model), timestep=m.opt.timestep),
                              SemiImplicitEuler(),
                              jnp.asarray(m.qpos0), jnp.zeros(1), dt=m.opt.timestep, t1=1.0)
    assert np.abs(np.asarray(explicit.qs[1:, 0]) - reference[:, 0]).max() > 1e-6
    assert abs(float(sol.qs[-1, 0]) - np.radians(30)) < 0.01       # held at its bound
    free = mbjax.simulate(ContactSystem(TreeSystem(model), limits=False), SemiImplicitEuler(),
                          jnp.asarray(m.qpos0), jnp.zeros(1), dt=m.opt.timestep, t1=1.0)
    assert np.asarray(free.qs).max() > 1.0                          # without limits it swings


def test_derivatives_through_landing_and_sliding_match_central_differences():
    """A box dropped from 0.3 m with a forward speed lands and slides: the derivatives of where
    it ends in the drop height, the speed and the friction coefficient (the implicit function
    theorem at each step's solution) agree with central differences, in forward and reverse
    mode; finite at first touch."""
    _, model = _load(f'<mujoco><worldbody>{FLOOR}<body pos="0 0 0.3"><freejoint/>'
                     '<geom type="box" size="0.1 0.2 0.05" mass="1"/></body></worldbody></mujoco>')
    base = ContactSystem(TreeSystem(model))
    q0 = model.neutral()

    def stop(h, speed, mu):
        system = eqx_set(base, mu)
        sol = mbjax.simulate(system, SemiImplicitEuler(), q0.at[2].set(h),
                             jnp.zeros(6).at[3].set(speed), dt=0.002, t1=0.6, saveat=[0.6])
        return jnp.stack([sol.qs[-1, 0], sol.qs[-1, 2]])

    x = (0.3, 1.0, 0.3)
    jacobian = jax.jit(jax.jacfwd(stop, argnums=(0, 1, 2)))
    J = np.stack(jacobian(*x), 1)
    f = jax.jit(stop)
    h = 1e-5
    for k in range(3):
        up, down = list(x), list(x)
        up[k] += h
        down[k] -= h
        np.testing.assert_allclose(J[:, k], (f(*up) - f(*down)) / (2 * h), rtol=1e-6, atol=1e-8)
    touching = np.stack(jacobian(0.05, 0.0, 0.3), 1)       # resting at first touch, at rest
    assert np.all(np.isfinite(touching))
    # reverse mode (the solve's derivative rule transposed) gives the same gradient
    gradient = jax.jit(jax.grad(lambda *x: stop(*x)[0], argnums=(0, 1, 2)))(*x)
    np.testing.assert_allclose(np.asarray(gradient), J[0], rtol=1e-9, atol=1e-12)


def eqx_set(system, mu):
    friction = jnp.asarray(system.geoms.friction).at[:, 0].set(mu)
    return eqx.tree_at(lambda s: s.geoms.friction, system, friction)


def test_penetration_and_an_unconverged_solve_are_named_failures():
    """A box landing sinks past a tight `penetration` bound, and one Newton iteration does not
    solve its four corners' contacts (the default run succeeds: the other tests)."""
    from mbjax import Status

    _, model = _load(f'<mujoco><worldbody>{FLOOR}<body pos="0 0 0.3"><freejoint/>'
                     '<geom type="box" size="0.1 0.2 0.05" mass="1"/></body></worldbody></mujoco>')
    q0 = model.neutral().at[2].set(0.3)

    def status(**options):
        sol = mbjax.simulate(ContactSystem(TreeSystem(model), **options), SemiImplicitEuler(),
                             q0, jnp.zeros(6), dt=0.002, t1=0.3)
        return int(sol.status), sol

    flags, sol = status(penetration=1e-4, method=SoftConstraints(iterations=1))
    assert flags & Status.PENETRATING and flags & Status.NOT_CONVERGED and not sol.ok
    assert "penetrating" in sol.messages()[0] and "not converged" in sol.messages()[0]
    # a contact stiffer than two steps can follow: a time constant of 1 ms without MuJoCo's
    # safety bound, or a direct stiffness of 1e6 (1 / sqrt(k) = 1 ms), at 2 ms steps
    assert int(status()[0]) == 0
    fast = eqx.tree_at(lambda m: m.geoms.solref, model,
                       jnp.broadcast_to(jnp.array([0.001, 1.0]), model.geoms.solref.shape))
    stiff = eqx.tree_at(lambda m: m.geoms.solref, model,
                        jnp.broadcast_to(jnp.array([-1e6, -3e3]), model.geoms.solref.shape))
    for changed, method in ((fast, SoftConstraints(refsafe=False)), (stiff, SoftConstraints())):
        sol = mbjax.simulate(ContactSystem(TreeSystem(changed), method=method), SemiImplicitEuler(),
                             q0, jnp.zeros(6), dt=0.002, t1=0.3)
        assert int(sol.status) & Status.UNRESOLVED and "unresolved" in sol.messages()[0]
    sol = mbjax.simulate(ContactSystem(TreeSystem(fast)), SemiImplicitEuler(), q0, jnp.zeros(6),
                         dt=0.002, t1=0.3)                       # refsafe keeps two steps
    assert not int(sol.status) & Status.UNRESOLVED


def test_bad_geometry_is_named():
    with pytest.raises(ValueError, match="size"):
        Geoms(("sphere",), (0,), [[-0.1, 0, 0]])
    with pytest.raises(ValueError, match="friction"):
        Geoms(("sphere",), (0,), [[0.1, 0, 0]], friction=[[-1.0, 0, 0]])
    with pytest.raises(ValueError, match="solref"):
        Geoms(("sphere",), (0,), [[0.1, 0, 0]], solref=[[0.02, -1.0]])
    with pytest.raises(ValueError, match="kinds"):
        Geoms(("torus",), (0,), [[0.1, 0, 0]])
    with pytest.raises(ValueError, match="condim"):
        Geoms(("sphere",), (0,), [[0.1, 0, 0]], condim=[2])
    with pytest.raises(ValueError, match="solimp"):
        Geoms(("sphere",), (0,), [[0.1, 0, 0]], solimp=[[0.9, 1.5, 0.001, 0.5, 2]])
    model = mbjax.model.random_tree(2, seed=0)
    undetected = Geoms(("sphere", "cylinder"), (0, 1), [[0.1] * 3] * 2)
    with pytest.raises(ValueError, match="sphere and a cylinder"):
        ContactSystem(TreeSystem(model), undetected)
    with pytest.raises(ValueError, match="ellipsoid geom 'egg': its semi-axes"):
        Geoms(("ellipsoid",), (0,), [[0.1, 0.0, 0.2]], names=["egg"])
    with pytest.raises(ValueError, match="iterations"):
        SoftConstraints(iterations=0)
    with pytest.raises(ValueError, match="penetration"):
        ContactSystem(TreeSystem(model), penetration=0.0)
    floor = ground_plane()
    assert floor.kinds == ("plane",) and floor.bodies == (-1,)


def test_geoms_are_kept_from_mjcf_and_swept_as_data():
    """`from_mujoco` keeps the Ant's geoms on the bodies that carry them, with MuJoCo's
    candidate pairs; the geometry is array data, so a vmapped sweep of the friction slides a
    box as far as separate runs do, less the rougher the floor."""
    import equinox as eqx

    gymnasium = pytest.importorskip("gymnasium")
    path = os.path.join(os.path.dirname(gymnasium.__file__), "envs/mujoco/assets/ant.xml")
    m, model = _load(path)
    geoms = model.geoms
    assert geoms.kinds.count("capsule") == 12 and geoms.kinds[0] == "plane"
    assert geoms.bodies[0] == -1 and len(geoms.pairs) == 13       # the floor with each geom
    np.testing.assert_allclose(np.asarray(geoms.size)[:, :2], m.geom_size[:, :2])

    _, box = _load(f'<mujoco><worldbody>{FLOOR}<body pos="0 0 0.049"><freejoint/>'
                   '<geom type="box" size="0.1 0.2 0.05" mass="1"/></body></worldbody></mujoco>')
    base = ContactSystem(TreeSystem(box))

    def slide(mu):
        friction = jnp.asarray(base.geoms.friction).at[:, 0].set(mu)
        system = eqx.tree_at(lambda s: s.geoms.friction, base, friction)
        sol = mbjax.simulate(system, SemiImplicitEuler(), box.neutral().at[2].set(0.049),
                             jnp.zeros(6).at[3].set(1.0), dt=0.002, t1=0.3, saveat=[0.3])
        return sol.qs[-1, 0]

    mus = jnp.asarray([0.2, 0.5, 1.0])
    swept = np.asarray(jax.jit(jax.vmap(slide))(mus))
    assert np.all(np.diff(swept) < 0)
    np.testing.assert_allclose(swept[1], float(slide(0.5)), rtol=1e-9)


def test_locked_joints_carry_their_geoms():
    """Locking the Ant's ankles welds each lower leg's capsule to its upper leg: the contacts
    found are the same at the same pose."""
    _, ant = _load(str(mbjax.data.ANT))
    q = ant.neutral().at[2].set(0.4).at[7:].set(jnp.array([0.3, 1.0, -0.2, -1.0, 0.1, -1.0,
                                                          0.0, 1.0]))
    ankles = [name for name in ant.joint_names if name.startswith("ankle")]
    reduced = ant.locked(ankles, q)
    kept = np.r_[0:7, 7, 9, 11, 13]                       # the free joint and the hips
    contacts = eqx.filter_jit(lambda system, q: system.contacts(q))
    full = contacts(ContactSystem(TreeSystem(ant)), q)
    welded = contacts(ContactSystem(TreeSystem(reduced)), q[kept])
    assert reduced.geoms.n == ant.geoms.n and welded.geoms == full.geoms
    np.testing.assert_allclose(welded.distance, full.distance, atol=1e-12)
    np.testing.assert_allclose(welded.position, full.position, atol=1e-12)


@pytest.mark.parametrize("geom, qvel, spin", [
    ('<geom type="box" size="0.1 0.2 0.05" mass="1" condim="4" friction="0.8 0.02 0"/>',
     [0, 0, 0, 0, 0, 10.0], True),
    ('<geom type="sphere" size="0.1" mass="1" condim="6" friction="0.8 0.01 0.005"/>',
     [1.0, 0, 0, 0, 3.0, 2.0], False),
], ids=["torsional-box", "rolling-sphere"])
def test_torsional_and_rolling_friction_follow_mujoco(geom, qvel, spin):
    """condim 4 and 6 (MuJoCo's pyramids over the spin and the rolling): a box spinning on the
    floor slows as MuJoCo's does, to round-off; a ball rolling and spinning has MuJoCo's
    accelerations at MuJoCo's own states."""
    xml = (f'<mujoco><worldbody>{FLOOR}<body pos="0 0 {0.05 if spin else 0.1}"><freejoint/>'
           f'{geom}</body></worldbody></mujoco>')
    m, model = _load(xml)
    assert model.geoms.condim[-1] == (4 if spin else 6)
    system = ContactSystem(TreeSystem(model), timestep=m.opt.timestep)
    acceleration = jax.jit(lambda q, v: system.acceleration(0.0, q, v))
    d = mujoco.MjData(m)
    d.qvel[:] = qvel
    spins = []
    for step in range(250):
        mujoco.mj_step(m, d)
        spins.append(d.qvel[5])
        if step % 50 == 10:
            mujoco.mj_forward(m, d)
            q, v = state_from_mujoco(model, d.qpos, d.qvel)
            a = np.asarray(acceleration(q, v))
            # MuJoCo's (world linear; body angular) rates in mbjax's body twist (omega; v):
            # v_body = R^T v_world, so its rate is R^T a_world - omega x v_body
            R, omega, v_body = d.xmat[1].reshape(3, 3), np.asarray(v[:3]), np.asarray(v[3:])
            expected = np.r_[d.qacc[3:], R.T @ d.qacc[:3] - np.cross(omega, v_body)]
            assert d.nefc > 0
            np.testing.assert_allclose(a, expected, atol=1e-9 * (1 + np.abs(a).max()))
    if spin:
        v0 = state_from_mujoco(model, m.qpos0, np.asarray(qvel, float))[1]
        sol = mbjax.simulate(system, SemiImplicitEuler(), jnp.asarray(m.qpos0), v0,
                             dt=m.opt.timestep, t1=0.5)
        np.testing.assert_allclose(np.asarray(sol.vs[1:, 2]), spins, atol=1e-9)
        assert spins[-1] < 0.8 * qvel[5]                   # the torsional friction slows it
