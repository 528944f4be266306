"""The weld and prismatic cut joints (the README's claim, issue 23): a bead cut free from a
swinging rod and tied back to it by the cut joint moves as the tree that holds it by a joint.
References: the same mechanism as a tree (a prismatic child), and as one body (welded)."""

import jax.numpy as jnp
import numpy as np
import pytest

from mbjax import simulate
from mbjax.integrate import RK4
from mbjax._src.lie.quaternion import quat_from_rotvec, quat_to_matrix
from mbjax import loops
from mbjax.loops import ClosedSystem, CutJoint, consistent_state
from mbjax.loops import Prismatic, Weld
from mbjax.model import Model
from mbjax.rigid import TreeSystem

ROD = dict(mass=1.2, com=(0.4, 0.0, 0.0), inertia=np.diag([0.01, 0.08, 0.08]))
BEAD = dict(mass=0.5, com=(0.0, 0.0, 0.0), inertia=np.diag([0.002, 0.003, 0.004]))
ALONG_X = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])   # z -> x (a turn about y)
THETA0, S0 = 0.3, 0.5
TS = np.linspace(0.0, 0.6, 7)


def _rod_and_free_bead():
    return Model([-1, -1], ["revolute", "free"], axis=[[0, 1, 0], [0, 0, 1]],
                 mass=[ROD["mass"], BEAD["mass"]], com=[ROD["com"], BEAD["com"]],
                 inertia=[ROD["inertia"], BEAD["inertia"]])


def _bead_state(theta, s):
    """The free bead's q at distance s along the rod turned by theta about y."""
    R = np.array([[np.cos(theta), 0, np.sin(theta)], [0, 1, 0], [-np.sin(theta), 0, np.cos(theta)]])
    return jnp.concatenate([jnp.asarray(R @ [s, 0.0, 0.0]),
                            quat_from_rotvec(jnp.array([0.0, theta, 0.0]))])


def test_prismatic_cut_joint_is_the_prismatic_tree():
    closed = ClosedSystem(TreeSystem(_rod_and_free_bead()),
                          [CutJoint(Prismatic(), 1, 0, rotation_a=ALONG_X, rotation_b=ALONG_X)])
    q0, v0 = consistent_state(closed, jnp.concatenate([jnp.array([THETA0]), _bead_state(THETA0, S0)]),
                              jnp.zeros(7))
    sol = simulate(closed, RK4(), q0, v0, dt=1e-3, t1=0.6, saveat=TS)
    tree = Model([-1, 0], ["revolute", "prismatic"], axis=[[0, 1, 0], [1, 0, 0]],
                 mass=[ROD["mass"], BEAD["mass"]], com=[ROD["com"], BEAD["com"]],
                 inertia=[ROD["inertia"], BEAD["inertia"]])
    ref = simulate(TreeSystem(tree), RK4(), jnp.array([THETA0, S0]), jnp.zeros(2), dt=1e-3,
                   t1=0.6, saveat=TS)
    assert sol.messages() == ref.messages() == ["success"]
    bead_along_rod = jnp.linalg.norm(sol.qs[:, 1:4], axis=1)       # the bead's distance from O
    assert float(jnp.ptp(ref.qs[:, 1])) > 0.05                     # it does slide
    np.testing.assert_allclose(sol.qs[:, 0], ref.qs[:, 0], atol=1e-7)
    np.testing.assert_allclose(bead_along_rod, jnp.abs(ref.qs[:, 1]), atol=1e-7)


def test_weld_cut_joint_is_one_rigid_body():
    offset = np.array([0.3, 0.0, 0.0])                              # the bead welded here
    closed = ClosedSystem(TreeSystem(_rod_and_free_bead()),
                          [CutJoint(Weld(), 1, 0, origin_b=offset)])
    q0 = jnp.concatenate([jnp.array([THETA0]), _bead_state(THETA0, offset[0])])
    q0, v0 = consistent_state(closed, q0, jnp.zeros(7))
    sol = simulate(closed, RK4(), q0, v0, dt=1e-3, t1=0.6, saveat=TS)
    # one body: masses added, inertias moved to the joint centre of mass (parallel axes)
    m = ROD["mass"] + BEAD["mass"]
    com = (ROD["mass"] * np.array(ROD["com"]) + BEAD["mass"] * offset) / m
    inertia = sum(part["inertia"] + part["mass"] * ((c - com) @ (c - com) * np.eye(3)
                                                    - np.outer(c - com, c - com))
                  for part, c in ((ROD, np.array(ROD["com"])), (BEAD, offset)))
    one = Model([-1], ["revolute"], axis=[[0, 1, 0]], mass=[m], com=[com], inertia=[inertia])
    ref = simulate(TreeSystem(one), RK4(), jnp.array([THETA0]), jnp.zeros(1), dt=1e-3, t1=0.6,
                   saveat=TS)
    assert sol.messages() == ref.messages() == ["success"]
    assert float(jnp.ptp(ref.qs[:, 0])) > 0.1                      # it does swing
    np.testing.assert_allclose(sol.qs[:, 0], ref.qs[:, 0], atol=1e-7)


def _old_string_residual(kind, d, RA, RB):
    """The residual rows as the string kinds gave them (before the kinds were objects)."""
    (x_A, _, z_A), (x_B, y_B, z_B) = RA.T, RB.T
    R = RB.T @ RA
    orientation = 0.5 * jnp.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    across = jnp.stack([d @ x_B, d @ y_B])
    return {"spherical": d, "revolute": jnp.concatenate([d, jnp.stack([z_A @ x_B, z_A @ y_B])]),
            "universal": jnp.concatenate([d, (x_A @ y_B)[None]]),
            "weld": jnp.concatenate([d, orientation]),
            "spatial_weld": jnp.concatenate([0.5 * (RA + RB).T @ d, orientation]),
            "prismatic": jnp.concatenate([across, orientation]), "point_on_line": across,
            "point_on_plane": (d @ z_B)[None]}[kind]


def test_cut_joint_kinds_are_objects_with_the_string_kinds_rows():
    """Each kind object gives the rows (and size) its string gave; strings are refused."""
    rng = np.random.default_rng(0)
    R_a, R_b = (np.asarray(quat_to_matrix(quat_from_rotvec(jnp.asarray(rng.normal(size=3)))))
                for _ in range(2))
    p_a, p_b = rng.normal(size=3), rng.normal(size=3)
    frames = dict(origin_a=rng.normal(size=3), origin_b=rng.normal(size=3),
                  rotation_a=np.asarray(quat_to_matrix(quat_from_rotvec(
                      jnp.array([0.3, -0.2, 0.5])))),
                  rotation_b=ALONG_X)
    kinds = {"spherical": loops.Spherical(), "revolute": loops.Revolute(),
             "universal": loops.Universal(), "weld": loops.Weld(),
             "spatial_weld": loops.SpatialWeld(), "prismatic": loops.Prismatic(),
             "point_on_line": loops.PointOnLine(), "point_on_plane": loops.PointOnPlane()}
    for name, kind in kinds.items():
        joint = CutJoint(kind, 1, 0, **frames)
        Ra, pa, Rb, pb = map(jnp.asarray, (R_a, p_a, R_b, p_b))
        RA, pA = Ra @ joint.rotation_a, pa + Ra @ joint.origin_a
        RB, pB = Rb @ joint.rotation_b, pb + Rb @ joint.origin_b
        expected = _old_string_residual(name, pA - pB, RA, RB)
        got = joint.pose_residual(Ra, pa, Rb, pb)
        assert joint.size == expected.shape[0] == got.shape[0], name
        np.testing.assert_array_equal(np.asarray(got), np.asarray(expected), err_msg=name)
        with pytest.raises(TypeError, match="kind must be a cut-joint kind"):
            CutJoint(name, 1, 0)
