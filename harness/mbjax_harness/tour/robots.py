"""The tour's URDF arm: servo and sampled torques against MuJoCo (controls), the model against
Pinocchio and MuJoCo (models)."""

from functools import partial
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from mbjax_harness import peers
from mbjax_harness.timing import measure
from mbjax.integrate import INTEGRATORS, simulate
from mbjax_harness.tour._common import _animate, _max_abs, _peer, _save


def controls_tour(out: Path, quick: bool) -> dict:
    """A URDF arm under a servo and sampled torques, with jax.grad through it. The 7-dof arm
    (`mbjax.scenes.arm`) is held by a PD servo with gravity feed-forward and pushed at its
    flange for 0.1 s; driven by a torque history sampled per step as MuJoCo applies it, against
    `mujoco.rollout` (when installed); and `jax.grad` of a reach loss with respect to a torque
    spline's knots and a link mass is checked against central differences."""

    from mbjax.control import ZeroOrderHold
    from mbjax_harness.plot.scenes import controls_figure
    from mbjax.rigid import TreeSystem
    from mbjax.scenes import arm as scene

    arm = scene.model()
    duration = 0.5 if quick else 1.0
    ts = np.linspace(0.0, duration, 51)                     # every 5 steps
    q0, v0 = jnp.asarray(scene.Q_REF), jnp.zeros(arm.nv)
    run = partial(simulate, integrator=INTEGRATORS["rk4"](), q0=q0, v0=v0, dt=scene.DT, t1=duration,
                  saveat=ts)
    held = run(TreeSystem(arm, scene.servo(arm)))
    pushed, timing = measure(partial(run, scene.pushed(arm)), repeats=3)
    track = jax.jit(jax.vmap(lambda q: scene.flange(arm, q)))
    displacement = np.asarray(track(pushed.qs) - track(held.qs))

    steps = 200
    history = np.random.default_rng(0).normal(0.0, 5.0, (steps, 3))
    sampled = simulate(TreeSystem(arm, ZeroOrderHold(history, scene.DT), actuation=[1, 3, 5]),
                       INTEGRATORS["rk4"](), q0, v0, dt=scene.DT, t1=steps * scene.DT,
                       saveat=[steps * scene.DT])
    mujoco_diff, mujoco = _peer(
        "mujoco", "the sampled-torque run against mujoco.rollout",
        lambda: _max_abs(_mujoco_sampled(arm, scene.Q_REF, history, [1, 3, 5], scene.DT, steps)
                         - np.asarray(sampled.qs[-1])))

    horizon = 100 if quick else 250
    knots, mass = 0.5 * jnp.ones((6, 7)), arm.mass[3]
    loss = jax.jit(lambda k, m: scene.reach_loss(arm, k, m, horizon))
    grads, grad_timing = measure(jax.jit(jax.grad(loss, argnums=(0, 1))), knots, mass, repeats=3)
    h = 1e-4            # the loss is about 60: smaller steps drown in its round-off
    fd_knot = float(loss(knots.at[2, 1].add(h), mass) - loss(knots.at[2, 1].add(-h), mass)) / (2 * h)
    fd_mass = float(loss(knots, mass + h) - loss(knots, mass - h)) / (2 * h)
    checks = {"d loss / d knot[2, 1]": (float(grads[0][2, 1]), fd_knot),
              "d loss / d mass of link 4": (float(grads[1]), fd_mass)}
    rows = {name: {"jax_grad": g, "central_difference": fd,
                   "relative_difference": abs(g - fd) / abs(fd)} for name, (g, fd) in checks.items()}
    sampled_note = (f"sampled control vs mujoco.rollout: {mujoco_diff:.1e} rad"
                    if mujoco_diff is not None else
                    f"sampled control not compared ({peers.note('mujoco', mujoco['status'])})")
    fig = controls_figure(np.asarray(ts), np.asarray(pushed.qs - q0), displacement, checks,
                          f"7-dof arm (mbjax.data.ARM7), PD servo + gravity feed-forward, RK4 "
                          f"{scene.DT * 1e3:g} ms; {sampled_note}")
    _save(fig, out, "controls.png")
    animation = _animate(out, "controls", TreeSystem(arm), ts, pushed.qs,
                         "arm under a PD servo, pushed at its flange", quick)
    return {"figure": "controls.png", "animation": animation, "duration": duration,
            "runs": {"pushed": {"peak_flange_displacement_m": float(np.abs(displacement).max()),
                                "seconds": timing.run_s, "status": pushed.messages()[0]},
                     "sampled": {"max_abs_diff_mujoco_rad": mujoco_diff,
                                 "status": sampled.messages()[0]}},
            "gradients": rows, "grad_seconds": grad_timing.run_s,
            "grad_compile_seconds": grad_timing.compile_s, "peers": {"mujoco": mujoco}}


def _mujoco_sampled(arm, q0, history, actuated, dt, steps):
    """The final qpos of `mujoco.rollout` with `history` as qfrc_applied on `actuated` and RK4
    (MuJoCo installed: `_peer` asks first)."""
    import mujoco
    from mujoco import rollout

    from mbjax.model import to_urdf

    mj = mujoco.MjModel.from_xml_string(to_urdf(arm))
    mj.opt.timestep, mj.opt.integrator = dt, mujoco.mjtIntegrator.mjINT_RK4
    mj.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT     # limits: data in mbjax
    data = mujoco.MjData(mj)
    data.qpos[:] = q0
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state = np.empty(mujoco.mj_stateSize(mj, spec))
    mujoco.mj_getState(mj, data, state, spec)
    qfrc = np.zeros((steps, mj.nv))
    qfrc[:, actuated] = history
    out, _ = rollout.rollout(mj, data, state[None], qfrc[None],
                             control_spec=mujoco.mjtState.mjSTATE_QFRC_APPLIED)
    return out[0, -1, 1:1 + mj.nq]


def models_tour(out: Path, quick: bool) -> dict:
    """A URDF arm as a user brings it: frames, joint limits, peers' dynamics. The arm
    (`mbjax.data.ARM7`) has its links and fixed joints as named frames, the flange's pose and
    Jacobian by name, its joint limits as data that `simulate`'s status checks (the unpowered arm
    falls through them), and the same arm through MuJoCo's compiler (`mbjax.model.from_mujoco`)
    and Pinocchio, when installed, against their dynamics."""
    from mbjax_harness.plot.scenes import models_figure
    from mbjax.rigid import TreeSystem, frame_jacobian, frame_pose
    from mbjax.scenes import arm as scene

    arm = scene.model()
    duration = 0.6 if quick else 1.5
    ts = np.round(np.arange(0.0, duration + 0.005, 0.01), 10)     # on the 2 ms step grid
    q0 = jnp.asarray(scene.Q_REF)
    fall = simulate(TreeSystem(arm), INTEGRATORS["rk4"](), q0, jnp.zeros(arm.nv), dt=scene.DT,
                    t1=duration, saveat=ts)
    flange = jax.jit(jax.vmap(lambda q: frame_pose(arm, q, "flange")[1]))(fall.qs)
    # how far each saved state lies beyond the arm's position and velocity limits (`Model.lower`,
    # `upper`, `velocity_limit`; what `simulate`'s status checks)
    qs, us = np.asarray(fall.qs), np.asarray(fall.vs)
    beyond = np.concatenate([np.maximum(np.asarray(arm.lower) - qs, 0.0)
                             + np.maximum(qs - np.asarray(arm.upper), 0.0),
                             np.maximum(np.abs(us) - np.asarray(arm.velocity_limit), 0.0)], axis=1)
    first = int(np.argmax(np.asarray(beyond).max(axis=1) > 0))
    J = frame_jacobian(arm, q0, "flange")
    manipulability = float(jnp.sqrt(jnp.linalg.det(J[3:] @ J[3:].T)))
    compared = _model_peers()
    fig = models_figure(np.asarray(ts), np.asarray(fall.qs), np.asarray(arm.lower),
                        np.asarray(arm.upper), np.asarray(flange), compared,
                        f"{len(arm.frame_names)} named frames; status: {fall.messages()[0]}")
    _save(fig, out, "models.png")
    animation = _animate(out, "models", TreeSystem(arm), ts, fall.qs,
                         "the URDF arm falling unpowered", quick)
    return {"figure": "models.png", "animation": animation, "frames": list(arm.frame_names),
            "flange_at_start_m": np.asarray(flange[0]).tolist(),
            "flange_manipulability": manipulability, "status": fall.messages()[0],
            "first_limit_exceeded_s": float(ts[first]) if np.asarray(beyond).any() else None,
            "peers": compared}



def _model_peers() -> dict:
    """{peer: record}: the arm against Pinocchio from the same URDF
    (`mbjax_harness.reproduce.urdf_corpus`: forward and inverse dynamics, mass matrix, frames) and
    against MuJoCo through MuJoCo's compiler and `from_mujoco` (`mbjax_harness.reproduce.mjcf_corpus`:
    accelerations), each record with its status (`_peer`) and, where compared, the largest
    relative difference."""
    from mbjax.data import ARM7

    def pinocchio():
        from mbjax_harness.reproduce import urdf_corpus
        return urdf_corpus.compare(ARM7, floating=False)["max_relative_difference"]

    def mujoco():
        import mujoco

        from mbjax.model import from_mujoco
        from mbjax_harness.reproduce import mjcf_corpus
        mj = mujoco.MjModel.from_xml_path(str(ARM7))
        return mjcf_corpus.compare(mj, from_mujoco(mj))["qacc"]

    out = {}
    for name, compares, compute in (
            ("pinocchio", "forward and inverse dynamics, mass matrix, frames from the URDF", pinocchio),
            ("mujoco", "accelerations through MuJoCo's compiler and from_mujoco", mujoco)):
        value, record = _peer(name, compares, compute)
        out[name] = {**record, "max_relative_difference": None if value is None else float(value)}
    return out
