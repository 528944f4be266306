"""Anderson 1993 §3.1 (Figs. 4-5): a slider-crank with a flexible connecting rod.

Crank O-P, 6 in, rigid, turning at a constant 125.6 rad/s counter-clockwise from P(0) = (0, 6 in);
rod P-Q, 12 in, round, 0.25 in diameter, E = 3.0e7 psi, 0.1667 lbm (steel); a massless slider at Q
on the x axis. At t = 0 the rod is straight and undeformed with the rigid mechanism's velocities
(then a pure translation: the rod's angular velocity is zero with P at the top). No gravity. SI
inside; the deflection is reported in inches.

mbjax's model: the crank a rigid body on a revolute joint whose angle is prescribed (pi/2 + Omega t,
a rheonomic `Prescribed` constraint); the rod a flexible body on a revolute joint at P, beam
elements clamped at P (its joint grid J), all of its in-plane modes (Anderson 1993: "all available
modes ... associated with motion of B in the x-y plane": 3 per element, so the basis spans what a
Craig-Bampton basis with Q as interface would); the massless slider a cut joint putting Q's grid point on the plane y = 0
(`PointOnPlane()`, one equation). Anderson 1993's route (`ClosedSystem(..., method=Stabilized())`) solves the loads;
(q, v) are projected back onto the constraints after every step.
The midpoint deflection is the signed distance of the rod's material midpoint from the chord PQ,
positive away from O at t = 0 (the rod frame's +y).
"""

import jax
import jax.numpy as jnp
import numpy as np

from mbjax._src.flex import Beam, FlexibleModel, FlexibleSystem, beam_body, craig_bampton, shape_at
from mbjax._src.flex.references import slider_crank_reference as reference  # noqa: F401 (the ANCF reference: mbjax.scenes.flexible_slider_crank.reference)
from mbjax._src.integrate import RK4, simulate
from mbjax._src.loops import GROUND, ClosedSystem, CutJoint, Prescribed, Stabilized
from mbjax._src.model.closures import PointOnPlane
from mbjax._src.model import Model

INCH, LBF, LBM = 0.0254, 4.4482216152605, 0.45359237
CRANK, ROD, DIAMETER = 6 * INCH, 12 * INCH, 0.25 * INCH
E = 3.0e7 * LBF / INCH**2
MASS = 0.1667 * LBM
OMEGA = 125.6
DURATION = 0.15


def rod(n_elements: int) -> Beam:
    """The connecting rod as a steel beam, 12 in long, 0.25 in diameter.

    Args:
        n_elements: the number of beam elements.

    Returns:
        The `mbjax.flex.Beam`.
    """
    area = np.pi * DIAMETER**2 / 4
    return Beam.round(ROD, DIAMETER, E, MASS / (ROD * area), nu=0.3, n_elements=n_elements)


def build(n_elements: int = 2, stiffening: bool = True):
    """The scene: the slider-crank with a flexible rod, the crank driven at OMEGA.

    q = (crank angle, rod angle relative to the crank, modal coordinates).

    Args:
        n_elements: the rod's number of beam elements (3 in-plane modes each).
        stiffening: include geometric stiffening.

    Returns:
        system: the `ClosedSystem` (Anderson 1993's route, projected after every step).
        q0: the initial configuration, shape (nq,).
        v0: the initial velocity, shape (nv,).
        midpoint: the modal shape of the rod's midpoint, shape (3, mu), for
            `midpoint_deflection`.
    """
    structure = rod(n_elements)
    basis = craig_bampton(structure, n_modes=3 * n_elements, planar="xy")
    body = beam_body(structure, basis, nodes=(n_elements,), stiffening=stiffening)
    m_crank = 0.1
    rigid = Model([-1, 0], ["revolute", "revolute"], mass=[m_crank, MASS],
                  com=[[CRANK / 2, 0, 0], [ROD / 2, 0, 0]],
                  inertia=[np.diag([1e-9, 1.0, 1.0]) * m_crank * CRANK**2 / 12,
                           np.diag([1e-9, 1.0, 1.0]) * MASS * ROD**2 / 12],
                  axis=[[0.0, 0.0, 1.0]] * 2, placement_translation=[[0, 0, 0], [CRANK, 0, 0]],
                  gravity=(0.0, 0.0, 0.0))
    model = FlexibleModel(rigid, {1: body}, markers=((1, 0),))
    slider = CutJoint(PointOnPlane(), model.n, GROUND, rotation_b=[[1, 0, 0], [0, 0, 1], [0, -1, 0]])
    phi0 = np.arcsin(-CRANK / ROD)                          # the rod's angle at t = 0 (-30 deg)
    q0 = model.join(jnp.array([np.pi / 2, phi0 - np.pi / 2]), jnp.zeros((model.n, model.mu)))
    v0 = model.join(jnp.array([OMEGA, -OMEGA]), jnp.zeros((model.n, model.mu)))
    midpoint, _ = shape_at(structure, basis, ROD / 2)
    system = ClosedSystem(FlexibleSystem(model), [Prescribed(0, q0=np.pi / 2, rate=OMEGA), slider],
                          method=Stabilized(), projection=True)
    return system, q0, v0, midpoint


def midpoint_deflection(system, midpoint, qs):
    """The signed distance of the rod's midpoint from the chord PQ along a trajectory.

    Positive away from O at t = 0 (the rod frame's +y).

    Args:
        system: the scene's system (`build`).
        midpoint: the midpoint's modal shape from `build`, shape (3, mu).
        qs: saved configurations, shape (T, nq).

    Returns:
        The deflection [m], shape (T,).
    """
    model = system.tree.model
    tip = model.bodies.node_phi[1, 0]
    _, qf = jax.vmap(model.split)(qs)
    d_mid = jnp.einsum("is,ts->ti", midpoint, qf[:, 1])
    d_tip = jnp.einsum("is,ts->ti", tip, qf[:, 1])
    chord = jnp.stack([ROD + d_tip[:, 0], d_tip[:, 1]], 1)
    mid = jnp.stack([ROD / 2 + d_mid[:, 0], d_mid[:, 1]], 1)
    return (chord[:, 0] * mid[:, 1] - chord[:, 1] * mid[:, 0]) / jnp.linalg.norm(chord, axis=1)


def run(n_elements: int = 2, stiffening: bool = True, dt: float = 1e-5, t1: float = DURATION,
        every: float = 5e-4, integrator=None, **tolerance):
    """One run of the scene.

    Args:
        n_elements: the rod's number of beam elements.
        stiffening: include geometric stiffening.
        dt: the step [s].
        t1: the final time [s].
        every: the save interval [s].
        integrator: the integrator; None for `RK4()`.
        **tolerance: `simulate`'s rtol and atol.

    Returns:
        ts: the save times [s], shape (T,).
        deflection: the rod's midpoint deflection [in], shape (T,).
        solution: the `Solution`.
    """
    system, q0, v0, midpoint = build(n_elements, stiffening)
    saveat = np.round(np.arange(0.0, t1 + every / 2, every), 12)
    sol = simulate(system, integrator or RK4(), q0, v0, dt=dt, t1=t1, saveat=saveat, **tolerance)
    return sol.ts, midpoint_deflection(system, midpoint, sol.qs) / INCH, sol
