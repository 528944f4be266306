"""Kane's spin-up beam (Anderson 1993 §3.2, eq 109; Kane, Ryan & Banerjee 1987): a uniform cantilever
clamped on a vertical axis and spun up in its own plane,

    omega(t) = (6 / 15) (t - (15 / (2 pi)) sin(2 pi t / 15))   for t < 15 s,   6 rad/s after,

L = 10 m, A = 4e-4 m^2, I = 2e-7 m^4, E = 7e10 Pa, G = 3e10 Pa, mass 12 kg; in-plane bending and
axial motion; no gravity. The first bending frequency is 3.8 rad/s, so the spin passes it: a
modal model without geometric stiffening (eqs 32-33) softens, K - omega^2 M_yy turns indefinite,
and the tip diverges; with stiffening the deflection stays small and bounded.

mbjax's model: one flexible body (beam elements, `mbjax/_src/flex/beam.py`, Craig-Bampton modes clamped at
the hub, the lowest `n_bending` in-plane bending and `n_axial` axial modes) on a revolute joint
about z, whose angle is the prescribed motion theta(t) (a rheonomic `Prescribed` constraint, Anderson
1993 eq 87) solved by Anderson 1993's route (`ClosedSystem(..., method=Stabilized())`, eqs 101-108). The tip deflection is
read in the rotating body frame: y (transverse, negative when the tip lags) and x (axial).
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from mbjax._src.flex import Beam, FlexibleModel, FlexibleSystem, ModalBasis, beam_body, craig_bampton, spin_up_theta
from mbjax._src.flex.references import spin_up_beam_reference as reference  # noqa: F401 (the ANCF reference: mbjax.scenes.spin_up_beam.reference)
from mbjax._src.integrate import RK4, simulate
from mbjax._src.loops import ClosedSystem, Prescribed, Stabilized
from mbjax._src.model import Model

LENGTH, AREA, INERTIA, E, G, MASS = 10.0, 4e-4, 2e-7, 7e10, 3e10, 12.0
T_S, OMEGA_S, DURATION = 15.0, 6.0, 20.0
N_ELEMENTS = 20             # the basis mesh (see `build`)


def omega(t):
    """The prescribed spin rate of Anderson 1993 eq 109.

    Args:
        t: time [s].

    Returns:
        omega(t) [rad/s], t's shape.
    """
    return jnp.where(t < T_S, OMEGA_S / T_S * (t - T_S / (2 * np.pi) * jnp.sin(2 * np.pi * t / T_S)),
                     OMEGA_S)


def theta(t):
    """The prescribed hub angle, the integral of `omega`.

    Args:
        t: time [s].

    Returns:
        theta(t) [rad], t's shape.
    """
    return spin_up_theta(t, T_S, OMEGA_S)


def beam(n_elements: int = 10) -> Beam:
    """The uniform cantilever (L = 10 m, 12 kg) as beam elements.

    Args:
        n_elements: the number of beam elements.

    Returns:
        The `mbjax.flex.Beam`.
    """
    return Beam(LENGTH, E, G, MASS / (LENGTH * AREA), AREA, INERTIA, INERTIA, 2 * INERTIA,
                n_elements)


def modes(structure: Beam, n_bending: int, n_axial: int = 1) -> ModalBasis:
    """The lowest in-plane bending and axial modes of the hub-clamped beam (x-y plane).

    Modes are selected by count per kind, so a scene carries no more than it needs.

    Args:
        structure: the beam.
        n_bending: the number of bending modes.
        n_axial: the number of axial modes.

    Returns:
        The `mbjax.flex.ModalBasis`, its modes in increasing frequency.

    Raises:
        ValueError: the mesh has fewer modes of a kind than asked for.
    """
    full = craig_bampton(structure, n_modes=3 * structure.n_elements, planar="xy")
    shapes = np.asarray(full.shapes)
    axial = np.sum(shapes[0::6] ** 2, 0) > np.sum(shapes[1::6] ** 2, 0)
    bending_cols = np.flatnonzero(~axial)[:n_bending]
    axial_cols = np.flatnonzero(axial)[:n_axial]
    if len(bending_cols) < n_bending or len(axial_cols) < n_axial:
        raise ValueError(f"{structure.n_elements} elements have {np.sum(~axial)} bending and "
                         f"{np.sum(axial)} axial modes; asked for {n_bending} and {n_axial}")
    cols = np.sort(np.concatenate([bending_cols, axial_cols]))
    return ModalBasis(full.shapes[:, cols], full.frequencies[cols], tuple(full.kinds[c] for c in cols))


def build(n_bending: int = 4, n_axial: int = 1, n_elements: int = N_ELEMENTS, stiffening: bool = True,
          projection: bool = False):
    """The scene: the spun beam as a `ClosedSystem` (Anderson 1993's route), at rest and undeformed.

    q = (hub angle, modal coordinates). The basis mesh sets the geometric stiffness's accuracy
    (element-constant axial forces, O(h^2)), so a finer mesh tracks the converged ANCF beam
    more closely; see benchmarks/README.md.

    Args:
        n_bending: the number of in-plane bending modes.
        n_axial: the number of axial modes.
        n_elements: the basis mesh's number of beam elements.
        stiffening: include geometric stiffening (eqs 32-33); without it the tip diverges.
        projection: project the state onto the prescribed hub angle after each step (for a
            second-order integrator such as the implicit midpoint, whose angle would drift off
            the prescribed one; RK4's stays on it).

    Returns:
        system: the `ClosedSystem`.
        q0: zeros, shape (nq,).
        v0: zeros, shape (nv,).
    """
    structure = beam(n_elements)
    body = beam_body(structure, modes(structure, n_bending, n_axial), nodes=(n_elements,),
                     stiffening=stiffening)
    rigid = Model([-1], ["revolute"], mass=[MASS], com=[[LENGTH / 2, 0.0, 0.0]],
                  inertia=[np.diag([0.0, 1.0, 1.0]) * MASS * LENGTH**2 / 12 + 1e-9 * np.eye(3)],
                  axis=[[0.0, 0.0, 1.0]], gravity=(0.0, 0.0, 0.0))
    model = FlexibleModel(rigid, {0: body})
    system = ClosedSystem(FlexibleSystem(model), [Prescribed(0, motion=theta)], method=Stabilized(),
                          projection=projection)
    return system, jnp.zeros(model.nq), jnp.zeros(model.nv)


@eqx.filter_jit
def tip(system, qs):
    """The tip displacement in the rotating frame along a saved trajectory.

    Args:
        system: the scene's system (`build`).
        qs: saved configurations, shape (T, nq).

    Returns:
        transverse: the y displacement [m] (negative when the tip lags), shape (T,).
        axial: the x displacement [m], shape (T,).
    """
    model = system.tree.model
    phi = model.bodies.node_phi[0, 0]                        # (3, mu) at the tip
    _, qf = jax.vmap(model.split)(qs)
    d = jnp.einsum("is,ts->ti", phi, qf[:, 0])
    return d[:, 1], d[:, 0]


def run(n_bending: int = 4, n_axial: int = 1, n_elements: int = N_ELEMENTS, stiffening: bool = True,
        dt: float = 1e-3, t1: float = DURATION, every: float = 0.1, integrator=None):
    """One run of the scene, with RK4 or another integrator.

    Args:
        n_bending: the number of in-plane bending modes.
        n_axial: the number of axial modes.
        n_elements: the basis mesh's number of beam elements.
        stiffening: include geometric stiffening.
        dt: the step [s].
        t1: the final time [s].
        every: the save interval [s].
        integrator: None for `RK4()`, or an integrator, run projected onto the prescribed
            angle (see `build`), e.g. `ImplicitMidpoint(simplified=True)` at steps far past the
            axial mode's period.

    Returns:
        ts: the save times [s], shape (T,).
        transverse: the tip's transverse displacement [m], shape (T,).
        axial: the tip's axial displacement [m], shape (T,).
        solution: the `Solution`.
    """
    system, q0, v0 = build(n_bending, n_axial, n_elements, stiffening, projection=integrator is not None)
    saveat = np.round(np.arange(0.0, t1 + every / 2, every), 10)
    sol = simulate(system, integrator or RK4(), q0, v0, dt=dt, t1=t1, saveat=saveat)
    transverse, axial = tip(system, sol.qs)
    return sol.ts, transverse, axial, sol
