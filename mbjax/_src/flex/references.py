"""Geometrically nonlinear ANCF references for Anderson 1993's flexible examples (§3.1, §3.2), to
validate the modal model with geometric stiffening (Anderson 1993 eqs 32-33). Parameterised: nothing
here is a stored result.
"""

from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from mbjax._src.flex.ancf import AncfBeam, AncfSolution, simulate_ancf, simulate_embedded

INCH = 0.0254


def spin_up_theta(t, T_s=15.0, omega_s=6.0):
    """Base angle of Kane's spin-up (Anderson 1993 eq 109, here for any T_s, omega_s): the integral of
    omega(t) = (omega_s / T_s) (t - (T_s / 2 pi) sin(2 pi t / T_s)) for t < T_s, omega_s after."""
    c = T_s / (2 * np.pi)
    def ramp(t):
        return omega_s / T_s * (t**2 / 2 + c**2 * (jnp.cos(t / c) - 1))
    return jnp.where(t < T_s, ramp(t), ramp(T_s) + omega_s * (t - T_s))


class SpinUpResult(NamedTuple):
    ts: jax.Array
    tip_deflection: jax.Array   # along the rotating y axis (-sin theta, cos theta), m; < 0 lagging
    tip_axial: jax.Array        # along (cos theta, sin theta), minus L, m
    solution: AncfSolution


def spin_up_beam_reference(n_elements=8, ts=None, *, dt=None, safety=0.5, length=10.0, E=7.0e10,
                           A=4.0e-4, I=2.0e-7, mass=12.0, T_s=15.0, omega_s=6.0,  # noqa: E741
                           free_root_stretch=True, throw: bool = False) -> SpinUpResult:
    """Kane's spin-up beam (Anderson 1993 §3.2, eq 109; Kane, Ryan & Banerjee 1987) as an ANCF beam in
    the x-y plane: node 0 clamped on the axis (position 0, slope (cos theta, sin theta)
    prescribed), starting straight along x at rest. ts defaults to 0 ... 20 s every 0.1 s.
    `free_root_stretch` (default): the clamp prescribes the root slope's direction only, r'(0) =
    lambda (cos theta, sin theta) with lambda free, since a clamp leaves the axial strain at the root
    free; False prescribes r'(0) = (cos theta, sin theta), which forces eps(0) = 0 and converges
    only as O(element length) (the centrifugal tension at the root is what stiffens the beam).

    The independent reference for `mbjax.scenes.spin_up_beam`'s modal model: absolute nodal
    coordinates and exact strains, so the geometric stiffening that the modal model adds by
    Anderson 1993 eqs 32-33 comes out of the kinematics here.

    Args:
        n_elements (int): ANCF elements along the beam.
        ts (ArrayLike | None): the times to report [s]; None for 0 ... 20 s every 0.1 s.
        dt (float | None): the largest RK4 step [s]; None for `safety` times RK4's stability
            limit at the start.
        safety (float): that fraction, where dt is None.
        length (float): the beam's length [m].
        E (float): Young's modulus [Pa].
        A (float): the cross-section's area [m^2].
        I (float): its second moment of area for in-plane bending [m^4].
        mass (float): the beam's mass [kg].
        T_s (float): the spin-up's duration [s].
        omega_s (float): the final spin rate [rad/s].
        free_root_stretch (bool): leave the root's axial strain free (see above).
        throw (bool): raise an error where the run blows up instead of returning it with its
            status (NONFINITE).

    Returns:
        (ts, tip_deflection, tip_axial, solution): the times, the tip's deflection along the
            hub's rotating y axis [m] (negative: lagging), its axial displacement minus the
            length [m], and the ANCF `solution` (coordinates and status).
    """
    ts = np.linspace(0.0, 20.0, 201) if ts is None else np.asarray(ts, float)
    beam = AncfBeam(length, E * A, E * I, mass / length, n_elements)
    def theta(t):
        return spin_up_theta(t, T_s, omega_s)
    e0 = beam.initial_coordinates()
    if free_root_stretch:
        # q = (lambda, coordinates of nodes 1 ... n)
        def embed(t, q):
            root = q[0] * jnp.stack([jnp.cos(theta(t)), jnp.sin(theta(t))])
            return jnp.concatenate([jnp.zeros(2), root, q[1:]])
        q0 = np.concatenate([np.ones(1), np.asarray(e0)[4:]])
        sol = simulate_embedded(beam, embed, q0, np.zeros_like(q0), ts, dt=dt, safety=safety,
                                throw=throw)
    else:
        def e_p(t):
            return jnp.stack([0.0 * t, 0.0 * t, jnp.cos(theta(t)), jnp.sin(theta(t))])
        sol = simulate_ancf(beam, e0, jnp.zeros_like(e0), ts, prescribed=range(4), e_p=e_p, dt=dt,
                       safety=safety, throw=throw)
    return SpinUpResult(sol.ts, *_rotating_tip(sol.ts, sol.e, length, T_s, omega_s), sol)


@jax.jit
def _rotating_tip(ts, e, length, T_s, omega_s):
    """The tip's (deflection, axial displacement) in the frame spun by the hub, from the beam's
    coordinates e (len(ts), 4 (n + 1))."""
    tip, th = e[:, -4:-2], spin_up_theta(ts, T_s, omega_s)
    return (-jnp.sin(th) * tip[:, 0] + jnp.cos(th) * tip[:, 1],
            jnp.cos(th) * tip[:, 0] + jnp.sin(th) * tip[:, 1] - length)


class SliderCrankResult(NamedTuple):
    ts: jax.Array
    midpoint_deflection: jax.Array   # inches, from chord PQ, + away from O at t = 0
    solution: AncfSolution


def slider_crank_reference(n_elements=4, ts=None, *, dt=None, safety=0.5, crank=6 * INCH,
                           rod=12 * INCH, diameter=0.25 * INCH, E=3.0e7 * 4.4482216152605 / INCH**2,
                           mass=0.1667 * 0.45359237, Omega=125.6,
                           throw: bool = False) -> SliderCrankResult:
    """Anderson 1993 §3.1 flexible slider-crank (SI inside, deflection reported in inches): rigid crank
    O-P at constant Omega counter-clockwise from P(0) = (0, crank); elastic rod P-Q as an ANCF
    beam with P's position prescribed and Q's y prescribed 0 (massless slider on the x axis), both
    slopes and Q's x free. Initial state: the rigid mechanism's rod, straight and unstrained, with
    the velocities of the rigid mechanism (jax.jvp of its coordinates in time; at t = 0 a pure
    translation with P's velocity). ts defaults to 0 ... 0.15 s every 0.5 ms.

    The independent reference for `mbjax.scenes.flexible_slider_crank`'s modal model.

    Args:
        n_elements (int): ANCF elements along the rod.
        ts (ArrayLike | None): the times to report [s]; None for 0 ... 0.15 s every 0.5 ms.
        dt (float | None): the largest RK4 step [s]; None for `safety` times RK4's stability
            limit at the start.
        safety (float): that fraction, where dt is None.
        crank (float): the crank's length [m].
        rod (float): the rod's length [m].
        diameter (float): the rod's (round) section's diameter [m].
        E (float): the rod's Young's modulus [Pa].
        mass (float): the rod's mass [kg].
        Omega (float): the crank's constant rate [rad/s].
        throw (bool): raise an error where the run blows up instead of returning it with its
            status (NONFINITE).

    Returns:
        (ts, midpoint_deflection, solution): the times, the rod's midpoint deflection from the
            chord PQ [in] (positive away from O at t = 0), and the ANCF `solution`.
    """
    ts = np.linspace(0.0, 0.15, 301) if ts is None else np.asarray(ts, float)
    area, inertia = np.pi * diameter**2 / 4, np.pi * diameter**4 / 64
    beam = AncfBeam(rod, E * area, E * inertia, mass / rod, n_elements)
    def P(t):
        return crank * jnp.stack([jnp.cos(np.pi / 2 + Omega * t), jnp.sin(np.pi / 2 + Omega * t)])

    def rigid(t):
        """Coordinates of the rigid rod from P(t) to Q(t) = (P_x + sqrt(rod^2 - P_y^2), 0)."""
        p = P(t)
        q = jnp.stack([p[0] + jnp.sqrt(rod**2 - p[1] ** 2), 0.0 * t])
        return beam.initial_coordinates(p, jnp.arctan2(q[1] - p[1], q[0] - p[0]))

    e0, e_dot0 = jax.jvp(rigid, (jnp.array(0.0),), (jnp.array(1.0),))
    q_y = 4 * n_elements + 1
    sol = simulate_ancf(beam, e0, e_dot0, ts, prescribed=(0, 1, q_y), dt=dt, safety=safety,
                   e_p=lambda t: jnp.concatenate([P(t), jnp.zeros(1) * t]), throw=throw)
    p, q = sol.e[:, :2], sol.e[:, q_y - 1:q_y + 1]
    u = (q - p) / jnp.linalg.norm(q - p, axis=1, keepdims=True)
    mid = jax.vmap(beam.position, (0, None))(sol.e, rod / 2)
    # n = u rotated by +90 deg points away from O at t = 0 (and keeps n_y > 0 since Q_x > P_x)
    d = jnp.sum((mid - p) * jnp.stack([-u[:, 1], u[:, 0]], 1), axis=1)
    return SliderCrankResult(sol.ts, d / INCH, sol)
