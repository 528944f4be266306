"""The tour's contacts: gymnasium's Ant and HalfCheetah dropped on the floor beside MuJoCo."""

import time
from functools import partial
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

import mbjax
from mbjax_harness import peers
from mbjax_harness.timing import measure
from mbjax_harness.tour._common import _needs, _save


CONTACT_ROBOTS = ("Ant", "HalfCheetah")


def contacts_tour(out: Path, quick: bool) -> dict:
    """gymnasium's Ant and HalfCheetah dropped on the floor, beside MuJoCo's runs. Each file
    (`mbjax.data.ANT`, `mbjax.data.HALF_CHEETAH`) is read by `mbjax.model.from_mujoco`, its
    geoms finding their own contacts in `mbjax.contact.ContactSystem` (MuJoCo's soft
    constraints, limited joints held), and dropped from its initial state with zero controls by
    the file's integrator (`mbjax_harness.bench.contact.mujoco_step`: RK4, or Euler as
    semi-implicit Euler with the damping implicit); MuJoCo runs the same files."""
    import warnings

    from mbjax.data import ANT, HALF_CHEETAH
    from mbjax.rigid import forward_kinematics
    from mbjax_harness.bench.contact import mujoco_step
    from mbjax_harness.plot.animate import geom_animation
    from mbjax_harness.plot.contact import drop_figure

    why = peers.missing("mujoco")
    if why is not None:                  # MuJoCo reads the MJCF files: nothing runs without it
        return _needs(out, "contacts", "The Ant and the HalfCheetah are MJCF files",
                      {"mujoco": {"status": why, "compares": "the same drops"}})
    import mujoco

    duration = 1.0 if quick else 2.0
    runs, plotted, panels = {}, {}, []
    for name, path in zip(CONTACT_ROBOTS, (ANT, HALF_CHEETAH)):
        m = mujoco.MjModel.from_xml_path(str(path))
        with warnings.catch_warnings(record=True) as caught:   # what mbjax leaves out: below
            warnings.simplefilter("always")
            model = mbjax.model.from_mujoco(m)
        dt = float(m.opt.timestep)
        steps = int(round(duration / dt))
        system, integrator = mujoco_step(m, model)
        sol, timing = measure(partial(mbjax.simulate, system, integrator, jnp.asarray(m.qpos0),
                                      jnp.zeros(m.nv), dt=dt, t1=steps * dt), repeats=3)
        d = mujoco.MjData(m)
        shown = np.flatnonzero(np.isin(m.geom_type, (int(mujoco.mjtGeom.mjGEOM_SPHERE),
                                                     int(mujoco.mjtGeom.mjGEOM_CAPSULE))))
        history = [(d.qpos.copy(), d.geom_xpos[shown].copy(), d.geom_xmat[shown].copy())]
        start = time.perf_counter()
        for _ in range(steps):
            mujoco.mj_step(m, d)
            history.append((d.qpos.copy(), d.geom_xpos[shown].copy(), d.geom_xmat[shown].copy()))
        mujoco_seconds = time.perf_counter() - start
        qpos, xpos, xmat = (np.asarray(x) for x in zip(*history))
        root = 2 if model.joint_types[0] == "free" else 1        # z, or the planar rootz
        ours = np.asarray(sol.qs[:, root])
        gap = np.abs(ours - qpos[:, root])
        ts = np.asarray(sol.ts)
        plotted[name] = {"ts": ts, "mbjax": ours, "mujoco": qpos[:, root],
                         "mbjax_seconds": timing.run_s / duration,
                         "mujoco_seconds": mujoco_seconds / duration}
        runs[name] = {"integrator": type(integrator).__name__, "dt": dt,
                      "steps": steps, "seconds": timing.run_s, "compile_seconds": timing.compile_s,
                      "mujoco_seconds": mujoco_seconds, "height_error_max_m": float(gap.max()),
                      "final_height_m": float(ours[-1]), "mujoco_final_height_m":
                          float(qpos[-1, root]), "status": sol.messages()[0],
                      "mbjax_ignores": "; ".join(str(w.message).split("ignored: ", 1)[-1]
                                                 for w in caught)}
        # the geoms along each run: capsules end to end, spheres as points
        R, p = (np.asarray(x) for x in jax.jit(jax.vmap(
            lambda q, model=model: forward_kinematics(model, q)))(sol.qs))
        geoms = model.geoms
        mine = [g for g, kind in enumerate(geoms.kinds) if kind in ("sphere", "capsule")]
        body = np.asarray(geoms.bodies)[mine]
        rot, pos = np.asarray(geoms.rotation)[mine], np.asarray(geoms.position)[mine]
        half = np.asarray(geoms.size)[mine, 1] * [geoms.kinds[g] == "capsule" for g in mine]
        centre = p[:, body] + np.einsum("tgij,gj->tgi", R[:, body], pos)
        axis = np.einsum("tgij,gj->tgi", R[:, body], rot[:, :, 2])
        ours_geoms = np.stack([centre - half[:, None] * axis, centre + half[:, None] * axis], 2)
        half_mj = m.geom_size[shown, 1] * (m.geom_type[shown] == int(mujoco.mjtGeom.mjGEOM_CAPSULE))
        axis_mj = xmat.reshape(*xmat.shape[:2], 3, 3)[..., 2]
        theirs = np.stack([xpos - half_mj[:, None] * axis_mj, xpos + half_mj[:, None] * axis_mj], 2)
        panels += [(f"{name}: mbjax", ours_geoms, np.asarray(geoms.size)[mine, 0]),
                   (f"{name}: MuJoCo", theirs, m.geom_size[shown, 0])]
    worst = max(run["height_error_max_m"] for run in runs.values())
    _save(drop_figure(plotted, f"dropped on the floor, contacts found each step: mbjax's root "
                               f"heights within {worst:.1e} m of MuJoCo's on the same files"),
          out, "contacts.png")
    animation = geom_animation(out / "contacts.gif", plotted[CONTACT_ROBOTS[0]]["ts"], panels,
                               title="dropped with zero controls", frames=30 if quick else 60)
    return {"figure": "contacts.png", "animation": Path(animation).name,
            "peers": {"mujoco": {"status": "compared", "compares": "the same drops"}},
            "runs": runs}
