"""The URDF corpus: every robot of `example-robot-data` loaded by `mbjax.load_urdf` and compared
with Pinocchio, fixed and floating base.

Per robot and base: forward dynamics (ABA), inverse dynamics (RNEA) and the mass matrix (CRBA) at
a random state, and the world pose and Jacobian of every frame Pinocchio names (links, joints,
fixed joints). Pinocchio reads URDF damping but its ABA does not apply it; mbjax does, so the
comparison gives Pinocchio the joint forces tau - damping * v. The difference is
max |mbjax - Pinocchio| / max(1, max |Pinocchio|) over every quantity.

A file that is not a robot (an empty <robot>, as `ur3.urdf` of the package) is listed but not
counted, and a robot whose only joint is its free base (a quadrotor) has no fixed-base row.
"""

import time
import warnings
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from mbjax.model.states import state_to_pinocchio
from mbjax.model.urdf import load_urdf
from mbjax.rigid import aba, forward_kinematics, inverse_dynamics, mass_matrix
from mbjax.rigid.frames import frame_jacobian, frame_poses


def corpus_paths() -> list[Path]:
    """Every URDF that the example-robot-data package ships (PackageNotFoundError when it is
    not installed)."""
    from importlib.metadata import distribution
    root = Path(distribution("example-robot-data").locate_file(
        "cmeel.prefix/share/example-robot-data/robots"))
    return sorted(root.rglob("*.urdf"))


def name(path: Path) -> str:
    """The robot's short name: package/file."""
    parts = path.parts
    package = next((p for p in parts if p.endswith(("_description", "_data"))), parts[-2])
    return f"{package.removesuffix('_description')}/{path.stem}"


def _pinocchio(path: Path, floating: bool):
    import pinocchio as pin
    if floating:
        return pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    return pin.buildModelFromUrdf(str(path))


@jax.jit
def _mbjax(model, q, v, tau):
    a = aba(model, q, v, tau)
    return (a, inverse_dynamics(model, q, v, a), mass_matrix(model, q), frame_poses(model, q),
            forward_kinematics(model, q))


def compare(path: Path, floating: bool, seed: int = 0) -> dict:
    """One row: load, and the largest relative difference from Pinocchio."""
    import pinocchio as pin
    row = {"robot": name(path), "floating": floating, "loads": False, "nv": None,
           "max_relative_difference": None, "warnings": [], "note": ""}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            model = load_urdf(path, floating_base=floating)
        except ValueError as err:
            row["note"] = str(err)
            return row
    row["warnings"] = [str(w.message) for w in caught]
    row.update(loads=True, nv=model.nv)
    pm = _pinocchio(path, floating)
    pd = pm.createData()
    rng = np.random.default_rng(seed)
    q = model.neutral() + jnp.asarray(rng.uniform(-1, 1, model.nq))
    q = model.normalize(jnp.clip(q, model.lower, model.upper))
    v, tau = jnp.asarray(rng.normal(size=model.nv)), jnp.asarray(rng.normal(size=model.nv))
    q_pin, v_pin = (np.asarray(x) for x in state_to_pinocchio(model, q, v))
    P = np.asarray(jax.jacfwd(lambda v_: state_to_pinocchio(model, q, v_)[1])(v))  # v_pin = P v
    a, tau_back, M, (R, p), (R_body, p_body) = _mbjax(model, q, v, tau)
    a_pin = pin.aba(pm, pd, q_pin, v_pin, P @ np.asarray(tau - model.damping * v))
    diffs = [_rel(P @ np.asarray(M) @ P.T, _symmetric(pin.crba(pm, pd, q_pin)))]
    if np.all(np.isfinite(a_pin)):
        diffs += [_rel(P @ np.asarray(a), a_pin),
                  _rel(P @ np.asarray(tau_back - model.damping * v),
                       pin.rnea(pm, pd, q_pin, v_pin, P @ np.asarray(a)))]
    else:      # a massless leaf: M is singular, and Pinocchio's ABA returns NaN
        row["note"] = "singular mass matrix: forward dynamics not compared (Pinocchio's is NaN)"
        a_any = jnp.asarray(rng.normal(size=model.nv))
        tau_id = inverse_dynamics(model, q, v, a_any)
        diffs.append(_rel(P @ np.asarray(tau_id - model.damping * v),
                          pin.rnea(pm, pd, q_pin, v_pin, P @ np.asarray(a_any))))
    pin.framesForwardKinematics(pm, pd, q_pin)
    names = {n: i for i, n in enumerate(model.frame_names)}
    compared = 0
    for fid, frame in enumerate(pm.frames):
        if frame.name not in names and frame.name not in model.names:
            continue
        pose = pd.oMf[fid]
        if frame.name in names:
            Rf, pf = R[names[frame.name]], p[names[frame.name]]
        else:
            Rf, pf = R_body[model.names.index(frame.name)], p_body[model.names.index(frame.name)]
        diffs += [_rel(np.asarray(Rf), pose.rotation), _rel(np.asarray(pf), pose.translation)]
        compared += 1
    last = model.names[-1]
    J = pin.computeFrameJacobian(pm, pd, q_pin, pm.getFrameId(last),
                                 pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
    diffs.append(_rel(np.asarray(frame_jacobian(model, q, last)) @ P.T,
                      np.concatenate([J[3:], J[:3]])))
    row["max_relative_difference"] = float(max(diffs))
    row["frames_compared"] = compared
    return row


def _symmetric(M):
    return np.triu(M) + np.triu(M, 1).T


def _rel(x, ref) -> float:
    ref = np.asarray(ref)
    return float(np.abs(np.asarray(x) - ref).max() / max(1.0, np.abs(ref).max()))


def rows(paths=None) -> list[dict]:
    """Every robot of the corpus, fixed and floating base."""
    out = []
    for path in paths or corpus_paths():
        for floating in (False, True):
            start = time.perf_counter()
            row = compare(path, floating)
            row["seconds"] = time.perf_counter() - start
            out.append(row)
    return out
