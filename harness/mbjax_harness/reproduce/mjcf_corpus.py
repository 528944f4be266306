"""The MJCF corpus: every MuJoCo model shipped by the installed packages (dm_control's suite,
locomotion walkers, third-party arms and test models, gymnasium's and gymnasium_robotics' MuJoCo
assets, the mujoco package's own), loaded with
`mbjax.model.from_mujoco` and checked against MuJoCo's forward dynamics and kinematics.

A file is a model when MuJoCo compiles it on its own and it has joints; the others (include
fragments, files that need a parent's assets, jointless scenes) are listed as skipped with
MuJoCo's reason. For each model, at one random state (qpos0 plus noise, quaternions normalized,
random qvel and qfrc_applied) `compare` sets both engines side by side:

    qacc            mbjax's `forward_dynamics`, mapped to MuJoCo's qvel coordinates by `jax.jvp`
                    of `state_to_mujoco`, against `mj_forward`'s qacc: max |difference| /
                    max(1, max |qacc|);
    poses           every body's and site's world pose (looked up as `frame_pose` does: a
                    named frame, from `frame_poses`, else a body, from `forward_kinematics`)
                    against xpos/xmat and site_xpos/site_xmat: max abs difference.

MuJoCo computes what mbjax models and nothing else: `comparable` disables contacts, constraints
(limits, dry friction, equality) and actuator forces by flag (mjDSBL_CONTACT,
mjDSBL_CONSTRAINT, mjDSBL_ACTUATION) and zeroes, in a copy of the model, what mbjax does not
model but mjDSBL_DAMPER or mjDSBL_SPRING would not remove alone or would remove with the joint
damping and springs mbjax does model: tendon damping, armature and springs, polynomial damping
and springs, ball and free joints' springs, gravity compensation, fluid forces (opt.density,
viscosity) and free joints' translational armature; sleeping is disabled. Joint damping, hinge
and slide springs, armature (actuators' included), gravity and the rigid-body dynamics stay on. A row's note is what the model's `from_mujoco` warning listed as ignored.

`mbjax reproduce model-corpus` (`mbjax_harness.reproduce.model_corpus`) writes the rows with the URDF
corpus's.
"""

import copy
import importlib.util
import time
import warnings
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from mbjax.model import Model, ModelWarning, from_mujoco, state_from_mujoco, state_to_mujoco
from mbjax.rigid import forward_dynamics, forward_kinematics, frame_poses
from mbjax_harness.progress import step

TOLERANCE = 1e-8
# (package, folder in it, glob): where the MJCF files are
SOURCES = (("dm_control", "suite", "*.xml", "dm_control"),
           ("dm_control", "locomotion", "**/*.xml", "dm_control/locomotion"),
           ("dm_control", "third_party", "**/*.xml", "dm_control/third_party"),
           ("dm_control", "mujoco/testing", "**/*.xml", "dm_control/testing"),
           ("dm_control", "mjcf/test_assets", "**/*.xml", "dm_control/mjcf"),
           ("gymnasium", "envs/mujoco/assets", "*.xml", "gymnasium"),
           ("gymnasium_robotics", "envs", "**/*.xml", "gymnasium_robotics"),
           ("mujoco", ".", "**/*.xml", "mujoco"))
# A small representative subset for the default test suite: planar hinge/slide chains, free
# floating bases, ball joints, several joints per body, tendons, equality constraints, ref offsets.
QUICK = ("dm_control/cartpole", "dm_control/cheetah", "dm_control/humanoid",
         "dm_control/manipulator", "gymnasium/ant", "mujoco/testdata/model")


def _sources():
    for package, folder, pattern, label in SOURCES:
        spec = importlib.util.find_spec(package)
        if spec is not None and spec.submodule_search_locations:
            yield label, Path(spec.submodule_search_locations[0]) / folder, pattern


def short_name(path: Path) -> str:
    """"dm_control/cheetah" for .../dm_control/suite/cheetah.xml."""
    path = Path(path)
    for label, root, _ in _sources():
        if path.is_relative_to(root):
            return f"{label}/{path.relative_to(root).with_suffix('').as_posix()}"
    return path.stem


def corpus_paths() -> list[Path]:
    """Every .xml file under the corpus folders of the installed packages (sorted)."""
    return [path for _, root, pattern in _sources() for path in sorted(root.glob(pattern))]


def comparable(mjmodel):
    """A copy of mjmodel computing only what mbjax models (see the module docstring)."""
    import mujoco

    m = copy.deepcopy(mjmodel)
    bits = mujoco.mjtDisableBit
    m.opt.disableflags |= int(bits.mjDSBL_CONTACT | bits.mjDSBL_CONSTRAINT
                              | bits.mjDSBL_ACTUATION)
    m.opt.enableflags &= ~int(mujoco.mjtEnableBit.mjENBL_SLEEP)
    m.opt.density = m.opt.viscosity = 0.0
    for j in np.flatnonzero(m.jnt_type == int(mujoco.mjtJoint.mjJNT_FREE)):
        m.dof_armature[m.jnt_dofadr[j]:m.jnt_dofadr[j] + 3] = 0.0    # translational armature
    scalar = np.isin(m.jnt_type, (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)))
    m.jnt_stiffness[~scalar] = 0.0                        # ball and free joints' springs
    for field in ("tendon_damping", "tendon_armature", "tendon_dampingpoly", "dof_dampingpoly",
                  "actuator_dampingpoly", "body_gravcomp", "tendon_stiffness",
                  "tendon_stiffnesspoly", "jnt_stiffnesspoly"):
        if getattr(m, field, None) is not None:
            getattr(m, field)[:] = 0.0
    return m


@jax.jit
def _mbjax_side(model: Model, qpos, qvel, qfrc_applied):
    """MuJoCo's qacc as mbjax computes it, the body poses and the named frames' (the sites), at
    MuJoCo's state. Compiled: one jit per model costs 1-2.5 s on the 2-core CI machine, the same
    model eagerly 2-10 s."""
    q, v = state_from_mujoco(model, qpos, qvel)
    to_qvel = lambda q_, v_: state_to_mujoco(model, q_, v_)[1]  # noqa: E731
    tau = jax.vjp(lambda v_: to_qvel(q, v_), v)[1](qfrc_applied)[0]    # tau = T^T qfrc_applied
    a = forward_dynamics(model, q, v, tau)
    qacc = jax.jvp(to_qvel, (q, v), (model.q_dot(q, v), a))[1]
    return qacc, forward_kinematics(model, q), frame_poses(model, q)


def object_name(mjmodel, kind: str, i: int) -> str:
    """The name of MuJoCo object i of `kind` ("body", "site"), or kind + index where it has
    none (as `from_mujoco` names it)."""
    import mujoco

    obj = {"body": mujoco.mjtObj.mjOBJ_BODY, "site": mujoco.mjtObj.mjOBJ_SITE}[kind]
    return mujoco.mj_id2name(mjmodel, obj, i) or f"{kind}{i}"


def site_frame_name(model: Model, site: str) -> str:
    """The named frame `from_mujoco` makes of a MuJoCo site: "site/NAME" where the site's name
    is taken (by a body, a joint or another frame), else the site's name."""
    return f"site/{site}" if f"site/{site}" in model.frame_names else site


def random_state(mjmodel, seed: int):
    """(m, d): `comparable(mjmodel)` and its data after `mj_forward` at qpos0 plus noise
    (quaternions normalized), random qvel and qfrc_applied."""
    import mujoco

    m = comparable(mjmodel)
    d = mujoco.MjData(m)
    rng = np.random.default_rng(seed)
    d.qpos[:] = m.qpos0 + 0.5 * rng.normal(size=m.nq)
    mujoco.mj_normalizeQuat(m, d.qpos)
    d.qvel[:] = rng.normal(size=m.nv)
    d.qfrc_applied[:] = rng.normal(size=m.nv)
    mujoco.mj_forward(m, d)
    return m, d


def compare(mjmodel, model: Model, seed: int = 0) -> dict:
    """{"qacc": relative qacc difference, "poses": max body and site pose difference} at one
    random state of `comparable(mjmodel)`."""
    m, d = random_state(mjmodel, seed)

    qacc, bodies, frames = _mbjax_side(model, *(jnp.asarray(x) for x in (d.qpos, d.qvel,
                                                                          d.qfrc_applied)))
    qacc_error = float(np.max(np.abs(np.asarray(qacc) - d.qacc)) / max(1.0, np.abs(d.qacc).max()))
    R, p, R_frames, p_frames = (np.asarray(x) for x in (*bodies, *frames))

    def pose(name):
        """The world pose of a named frame (a site, a welded body or one whose joint is off its
        origin), else of a body: `frame_pose`'s lookup."""
        if name in model.frame_names:
            i = model.frame_names.index(name)
            return R_frames[i], p_frames[i]
        k = model.names.index(name)
        return R[k], p[k]

    pose_error = 0.0
    targets = [(object_name(m, "body", b), d.xmat[b], d.xpos[b]) for b in range(1, m.nbody)]
    targets += [(site_frame_name(model, object_name(m, "site", s)), d.site_xmat[s],
                 d.site_xpos[s]) for s in range(m.nsite)]
    for name, xmat, xpos in targets:
        R_w, p_w = pose(name)
        pose_error = max(pose_error, np.abs(R_w.reshape(9) - xmat).max(),
                         np.abs(p_w - xpos).max())
    return {"qacc": qacc_error, "poses": float(pose_error)}


def survey(paths=None) -> tuple[list[dict], list[dict]]:
    """(rows, skipped): a row per model (see `rows`), and {"model", "reason"} per file that is
    not a model on its own."""
    import mujoco

    found, skipped = [], []
    for path in corpus_paths() if paths is None else [Path(p) for p in paths]:
        name = short_name(path)
        step(name)
        try:
            mjmodel = mujoco.MjModel.from_xml_path(str(path))
        except ValueError as err:
            skipped.append({"model": name, "reason": str(err).splitlines()[0]})
            continue
        if mjmodel.nv == 0:
            skipped.append({"model": name, "reason": "compiles, but has no joints"})
            continue
        start = time.perf_counter()
        row = {"model": name, "nv": int(mjmodel.nv), "loads": False,
               "max_relative_difference": None, "max_pose_difference": None, "note": ""}
        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always", ModelWarning)
                model = from_mujoco(mjmodel)
            row["loads"] = True
            row["note"] = "; ".join(str(w.message).removeprefix(
                "from_mujoco: mbjax does not model, and ignored: ") for w in caught)
            errors = compare(mjmodel, model)
            row["max_relative_difference"], row["max_pose_difference"] = (errors["qacc"],
                                                                         errors["poses"])
        except Exception as err:                      # a failure is a row, not a crash
            row["note"] = f"{type(err).__name__}: {err}"
        row["seconds"] = time.perf_counter() - start
        found.append(row)
        jax.clear_caches()   # a compiled program per model: hundreds of them exhaust mmap
    return found, skipped


def rows(paths=None) -> list[dict]:
    """One dict per model that MuJoCo compiles (all of `corpus_paths()` by default): {"model",
    "nv", "loads", "max_relative_difference", "max_pose_difference" (None where not compared),
    "note" (what was ignored, or the error), "seconds"}."""
    return survey(paths)[0]


def quick_paths() -> list[Path]:
    """The `QUICK` subset's files (those installed)."""
    return [path for path in corpus_paths() if short_name(path) in QUICK]
