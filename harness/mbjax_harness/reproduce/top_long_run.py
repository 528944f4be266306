"""`mbjax reproduce top-long-run`: long vertical-top runs: the primal form fails, the mixed does not.
Where the primal form fails and the mixed form does not (Borri 1990 §6-8), as long runs of the
vertical top.

The top (`mbjax.scenes.vertical_top`) spins at Omega = 1.01 Omega_c: a sleeping top, physically
stable, a slightly tilted one nutates with a bounded tilt. Two-node elements 0.5 s long lie
between the physical boundary and the primal form's exact-integration boundary of eq 7.10,
Omega_c sqrt(1 + (omega dt)^2 / 12) = 1.0285 Omega_c, so there the transition matrix (eq 6.8)
of the primal form has an eigenvalue outside the unit circle while the reduced primal form and the
mixed form (eq 6.12) keep theirs on it. Each run starts tilted by 1e-4 rad and lasts 80 s; the
tilt, the energy error and the error in the vertical angular momentum (conserved: gravity's
moment about the suspension point is horizontal) are recorded at every element boundary, next to
the physical tilt from an adaptive Dopri8 reference.

Two ways of marching:

- "steady": every element about the steady rotation of eq 7.1, the increments carried over
  (§6's setting, eq 6.7). The growth rate predicted by the transition matrix, max ln|lambda| / h,
  and the one measured from the tilt agree: the primal form's tilt grows exponentially until it
  saturates, the mixed form's follows the physical one.
- "constant_velocity": `solve_tfe`'s default (`ConstantVelocityReference()`), a reference built
  afresh from each element's initial state. The perturbation then also moves the reference, so
  the one-element map is no longer eq 6.8 / 6.12; its Jacobian (jax.jacfwd through the whole
  step) gives the predicted rate, and at this coarse step both forms drift.

JSON: {"scene", "spin", "critical_spin", "exact_boundary", "dt", "nodes", "tilt0", "duration",
"physical": {"t", "tilt"}, "runs": [{"form": "primal" | "primal_reduced" | "mixed", "march":
"steady" | "constant_velocity", "t", "tilt", "energy_error", "momentum_error",
"predicted_growth", "measured_growth", "max_tilt", "seconds", "status"}, ...]}; growth rates in
1/s, tilt in rad, energy and momentum errors relative to their initial values.
"""

import json
from functools import partial
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from mbjax import lie
from mbjax.integrate import solve_reference
from mbjax.scenes import vertical_top as vt
from mbjax.tfe import (ConstantVelocityReference, Element, ExactQuadrature, Mixed, PrimalUnsymmetric,
                       ReducedQuadrature, initial_state, solve_tfe)
from mbjax_harness.common import DT, NODES, SPIN_RATIO, TILT0, steady_rotation
from mbjax_harness.reproduce.vertical_top import top_transition
from mbjax_harness.timing import measure

NAME = "top-long-run"
DURATION = 80.0
# (run name, form, quadrature)
FORMS = (("primal", PrimalUnsymmetric(), ExactQuadrature()),
         ("primal_reduced", PrimalUnsymmetric(), ReducedQuadrature()),
         ("mixed", Mixed(), ExactQuadrature()))
MARCHES = ("steady", "constant_velocity")
WINDOW = 5.0        # s, for the tilt envelope
LINEAR_TILT = 3e-2  # rad, below which the growth is fitted
# what a run is held to (`solve_tfe`'s rtol and atol): this scene is about stability, so the
# state to 1e-2 (the tilt to about 0.01 rad) and the energy and momentum to 1 %; at DT = 0.5 s
# the spin's phase error alone is 1.4e-3 in the rotation matrix's components
TOLERANCE = {"rtol": 1e-2, "atol": 1e-2}


@partial(jax.jit, static_argnames=("form", "element"))
def step_transition(form, element: Element, spin, dt) -> jax.Array:
    """Jacobian of one `solve_tfe` step with a reference built from the element's own initial
    state, about the steady rotation: (dh_1, dr_1) -> (dh_2, dr_2), the perturbations of the
    spatial momentum and rotation seen from the steady frame (time-invariant by the top's symmetry
    about e_3)."""
    body = vt.build()
    h_ss = body.mass_matrix(jnp.eye(3)) @ jnp.array([0.0, 0.0, spin])
    length = element.length(dt)
    turn = lie.exp(jnp.array([0.0, 0.0, spin * length]))

    def step(d):
        R1, h1 = lie.exp(d[3:]), h_ss + d[:3]
        # the state (R1, h1): the body angular velocity R1^T omega of the momentum h1
        state = initial_state(body, R1, R1.T @ body.momentum_to_velocity(R1, h1)[:3])
        sol = solve_tfe(body, state, dt=dt, n_elements=1, form=form, element=element, tol=1e-14)
        R2, h2 = sol.R[-1], sol.p_hat[-1]
        return jnp.concatenate([turn.T @ (h2 - h_ss), turn.T @ lie.log(R2 @ turn.T, check=False)])

    return jax.jacfwd(step)(jnp.zeros(6))


def growth_rate(T, length) -> float:
    """max ln|lambda| / h over the eigenvalues of a one-element map."""
    return float(np.max(np.log(np.abs(np.linalg.eigvals(np.asarray(T)))))) / length


def measured_growth(t, tilt) -> float:
    """Slope of ln(max tilt) over windows of WINDOW seconds, fitted while the motion is linear."""
    t, tilt = np.asarray(t), np.asarray(tilt)
    edges = np.arange(0.0, t[-1] + 1e-9, WINDOW)
    centres, peaks = [], []
    for a, b in zip(edges[:-1], edges[1:]):
        inside = (t >= a) & (t < b)
        if inside.any() and tilt[inside].max() < LINEAR_TILT:
            centres.append(0.5 * (a + b))
            peaks.append(tilt[inside].max())
    if len(peaks) < 2:
        return float("nan")
    return float(np.polyfit(centres, np.log(peaks), 1)[0])


def tilt_of(R) -> np.ndarray:
    """Angle between the body's symmetry axis R e_3 and the vertical."""
    return np.arccos(np.clip(np.asarray(R)[..., 2, 2], -1.0, 1.0))


def run(form_name: str, form, quadrature, march: str, duration: float, repeats: int,
        rotations: bool = False) -> dict:
    """One march of the top: its tilt, invariants, growth rates, time and status; with
    `rotations`, also "R", the body's rotation at every node (an array, for an animation)."""
    body = vt.build()
    spin = SPIN_RATIO * vt.CRITICAL_SPIN
    element = Element(NODES, quadrature)
    R0 = lie.exp(jnp.array([TILT0, 0.0, 0.0]))
    state0 = initial_state(body, R0, jnp.array([0.0, 0.0, spin]))
    reference = steady_rotation(spin) if march == "steady" else ConstantVelocityReference()
    n_elements = int(round(duration / element.length(DT)))
    sol, timing = measure(lambda: solve_tfe(body, state0, dt=DT, n_elements=n_elements, form=form,
                                            element=element, reference=reference),
                          repeats=repeats)
    # the accuracy status, from one more march (its estimate is not in the timing)
    checked = solve_tfe(body, state0, dt=DT, n_elements=n_elements, form=form, element=element,
                        reference=reference, **TOLERANCE)
    if march == "steady":
        T = top_transition(spin, DT, form=form, element=element)     # eq 6.8 / 6.12
    else:
        T = step_transition(form, element, spin, DT)
    t, tilt = np.asarray(sol.ts), tilt_of(sol.R)
    E = np.asarray(sol.energy(body))
    h = np.asarray(sol.angular_momentum(body))
    return {"form": form_name, "march": march, "t": t.tolist(), "tilt": tilt.tolist(),
            "energy_error": (E / E[0] - 1.0).tolist(),
            "momentum_error": ((h[:, 2] - h[0, 2]) / np.linalg.norm(h[0])).tolist(),
            "predicted_growth": growth_rate(T, element.length(DT)),
            "measured_growth": measured_growth(t, tilt), "max_tilt": float(np.max(tilt)),
            "seconds": timing.run_s, "error_estimate": float(checked.error),
            "invariant_drift": float(checked.drift), "status": checked.messages()[0],
            **({"R": np.asarray(sol.R)} if rotations else {})}


def physical(duration: float) -> dict:
    """The tilt of the top itself (adaptive Dopri8, rtol 1e-11)."""
    body = vt.rigid_body()
    spin = SPIN_RATIO * vt.CRITICAL_SPIN
    q0, u0 = body.initial_state(lie.exp(jnp.array([TILT0, 0.0, 0.0])), jnp.array([0.0, 0.0, spin]))
    ts = jnp.linspace(0.0, duration, int(duration * 10) + 1)
    sol = solve_reference(body, q0, u0, ts, rtol=1e-11, atol=1e-11)
    return {"t": np.asarray(ts).tolist(),
            "tilt": tilt_of(jax.jit(jax.vmap(body.rotation_matrix))(sol.qs)).tolist()}


def reproduce(out: Path, quick: bool = False) -> dict:
    """All runs (quick: 40 s instead of 80 s); writes JSON and PNG."""
    from mbjax_harness.plot.tfe import top_long_run_figure

    duration = DURATION / 2 if quick else DURATION
    spin = SPIN_RATIO * vt.CRITICAL_SPIN
    data = {
        "scene": f"vertical top at {SPIN_RATIO:g} Omega_c, tilted {TILT0:g} rad, {NODES}-node "
                 f"elements {DT:g} s between nodes, {duration:g} s",
        "spin": spin, "critical_spin": vt.CRITICAL_SPIN,
        "exact_boundary": float(vt.exact_boundaries(DT)[0]), "dt": DT, "nodes": NODES,
        "tilt0": TILT0, "duration": duration, "physical": physical(duration),
        "runs": [run(name, form, quadrature, march, duration, repeats=1 if quick else 3)
                 for march in MARCHES for name, form, quadrature in FORMS],
    }
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{NAME}.json").write_text(json.dumps(data, indent=1))
    top_long_run_figure(data).savefig(out / f"{NAME}.png", dpi=120)
    return data
