"""The URDF corpus: every robot of `example-robot-data` loaded by `mbjax.load_urdf` and compared
with Pinocchio, fixed and floating base.

Per robot and base: forward dynamics (ABA), inverse dynamics (RNEA) and the mass matrix (CRBA) at
a random state, and the world pose and Jacobian of every frame Pinocchio names (links, joints,
fixed joints). Pinocchio reads URDF damping but its ABA does not apply it; mbjax does, so the
comparison gives Pinocchio the joint forces tau - damping * v. The difference is
max |mbjax - Pinocchio| / max(1, max |Pinocchio|) over every quantity. Where the mass matrix is
ill-conditioned (a near-massless body, cond(M) > 1e5) the accelerations of both engines carry
cond(M) times round-off; there mbjax's accelerations are put into Pinocchio's equations of motion
instead (their residual relative to the size of its terms, max(|tau|, |M| |a|): the backward
error).

A file that is not a robot (an empty <robot>, as `ur3.urdf` of the package) is listed but not
counted, and a robot whose only joint is its free base (a quadrotor) has no fixed-base row.
"""

import time
import warnings
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from mbjax import Recursive
from mbjax.model import load_urdf, state_to_pinocchio
from mbjax.rigid import (forward_dynamics, forward_kinematics, frame_jacobian, frame_poses,
                         inverse_dynamics, mass_matrix)
from mbjax_harness.common import corpus_paths
from mbjax_harness.progress import step

# Above this condition number of the mass matrix, forward dynamics are compared by their backward
# error: cond(M) eps exceeds 1e-10 there, so neither engine's accelerations are accurate to it.
ILL_CONDITIONED = 1e5


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
    a = forward_dynamics(model, q, v, tau, method=Recursive())          # the ABA
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
    M_pin = _symmetric(pin.crba(pm, pd, q_pin))
    diffs = [_rel(P @ np.asarray(M) @ P.T, M_pin)]
    condition = float(np.linalg.cond(M_pin))
    row["mass_matrix_condition"] = condition
    tau_pin = P @ np.asarray(tau - model.damping * v)
    if not np.all(np.isfinite(a_pin)):      # a massless leaf: M is singular, Pinocchio's ABA NaN
        row["note"] = "singular mass matrix: forward dynamics not compared (Pinocchio's is NaN)"
        a_any = jnp.asarray(rng.normal(size=model.nv))
        tau_id = inverse_dynamics(model, q, v, a_any)
        diffs.append(_rel(P @ np.asarray(tau_id - model.damping * v),
                          pin.rnea(pm, pd, q_pin, v_pin, P @ np.asarray(a_any))))
    elif condition > ILL_CONDITIONED:
        # a near-massless body: both engines' accelerations carry cond(M) times round-off, so
        # mbjax's go into Pinocchio's equations of motion (the backward error: the residual
        # against the size of its terms)
        row["note"] = (f"ill-conditioned mass matrix (cond {condition:.0e}): forward dynamics "
                       "compared by the residual of Pinocchio's equations of motion")
        residual = pin.rnea(pm, pd, q_pin, v_pin, P @ np.asarray(a)) - tau_pin
        scale = max(1.0, np.abs(tau_pin).max(), np.abs(M_pin).max() * np.abs(np.asarray(a)).max())
        diffs.append(float(np.abs(residual).max() / scale))
    else:
        diffs += [_rel(P @ np.asarray(a), a_pin),
                  _rel(P @ np.asarray(tau_back - model.damping * v),
                       pin.rnea(pm, pd, q_pin, v_pin, P @ np.asarray(a)))]
    pin.framesForwardKinematics(pm, pd, q_pin)
    compared = 0
    for fid, frame in enumerate(pm.frames):
        pose = _mbjax_frame(model, frame, R, p, R_body, p_body)
        if pose is None:
            continue
        expected = pd.oMf[fid]
        diffs += [_rel(np.asarray(pose[0]), expected.rotation),
                  _rel(np.asarray(pose[1]), expected.translation)]
        compared += 1
    last = model.names[-1]
    J = pin.computeFrameJacobian(pm, pd, q_pin, pm.getFrameId(last),
                                 pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
    diffs.append(_rel(np.asarray(frame_jacobian(model, q, last)) @ P.T,
                      np.concatenate([J[3:], J[:3]])))
    row["max_relative_difference"] = float(max(diffs))
    row["frames_compared"] = compared
    return row


def _mbjax_frame(model, frame, R, p, R_body, p_body):
    """mbjax's pose of a Pinocchio frame, matched by name and type (a URDF may name a link like a
    joint): a JOINT frame is its body's frame, a BODY frame a link (a body, or a named frame if
    merged), a FIXED_JOINT frame a named frame; None for the others (the universe, operational
    frames)."""
    import pinocchio as pin
    kind = frame.type
    if kind == pin.FrameType.JOINT and frame.name in model.joint_names:
        k = model.joint_names.index(frame.name)
        return R_body[k], p_body[k]
    if kind == pin.FrameType.BODY and frame.name in model.names:
        k = model.names.index(frame.name)
        return R_body[k], p_body[k]
    if kind in (pin.FrameType.BODY, pin.FrameType.FIXED_JOINT) and frame.name in model.frame_names:
        i = model.frame_names.index(frame.name)
        return R[i], p[i]
    return None


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
            step(f"{name(path)}{', floating' if floating else ''}")
            start = time.perf_counter()
            row = compare(path, floating)
            row["seconds"] = time.perf_counter() - start
            out.append(row)
        jax.clear_caches()   # a compiled program per robot: hundreds of them exhaust mmap
    return out
