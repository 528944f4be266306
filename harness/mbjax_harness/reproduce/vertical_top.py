"""`mbjax reproduce vertical-top`: time elements' stability on a vertical top at its critical speed.
As in Borri 1990 Tables 1-2, with the boundaries of eq 7.10.

The vertical top (`mbjax.scenes.vertical_top`, omega = 5/3) spins at its critical speed; each
element's transition matrix about that steady motion (eqs 6.8, 6.12, from jacfwd of the full
3-D residual, `mbjax.tfe.stability`) gives exponents ln(lambda) / h, h = (nodes - 1) dt the
element length. Reported is the transverse exponent with positive imaginary part and the
largest real part (the exact ones are +- i 5/3, a double pair at the critical speed):

- "exact", "reduced": the primal form of eq 4.1 (Tables 1 and 2), 2-, 3-, 4-node elements,
  dt = 0.02 ... 0.20 between nodes;
- "mixed": the mixed form of eq 4.9 with full quadrature, the same grid (not in the paper's
  tables; its text says the mixed form keeps the physical boundary);
- "stability_boundary": for the two-node elements, the least spin rate at which the transition
  matrix's spectral radius stays at 1, by bisection, next to eq 7.10's closed forms.

JSON: {"exact": {"2": [{"dt", "re", "im"}, ...], "3": [...], "4": [...]}, "reduced": {...},
"mixed": {...}, "paper": {"exact": ..., "reduced": ...}, "stability_boundary": {"omega", "dt",
"exact", "reduced", "mixed", "exact_closed_form", "physical"}}.
"""

import json
from functools import partial
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from mbjax.scenes import vertical_top as vt
from mbjax.tfe import (Element, ExactQuadrature, Mixed, PrimalUnsymmetric, ReducedQuadrature,
                       Reference, stability)
from mbjax_harness.progress import step

NAME = "vertical-top"
DTS = tuple(round(0.02 * k, 2) for k in range(1, 11))
NODES = (2, 3, 4)
# the tables' names for the quadratures (the JSON's keys, the paper's words)
QUADRATURES = {"exact": ExactQuadrature(), "reduced": ReducedQuadrature()}
# Tables 1 and 2 of Borri 1990 as printed: (real, imaginary) per node count, rows dt = 0.02 ... 0.20.
PAPER = {
    "exact": {
        "2": [(1.6031e-02, 1.6663), (3.2027e-02, 1.6654), (4.7952e-02, 1.6638), (6.3772e-02, 1.6617),
              (7.9453e-02, 1.6590), (9.4963e-02, 1.6557), (0.1102, 1.6518), (0.1253, 1.6474),
              (0.1401, 1.6424), (0.1546, 1.6370)],
        "3": [(2.7599e-04, 1.6666), (1.1032e-03, 1.6666), (2.4795e-03, 1.6666), (4.4010e-03, 1.6666),
              (6.8623e-03, 1.6665), (9.8564e-03, 1.6664), (1.3374e-02, 1.6663), (1.7404e-02, 1.6661),
              (2.1934e-02, 1.6658), (2.6949e-02, 1.6653)],
        "4": [(1.7240e-05, 1.6666), (4.1751e-05, 1.6666), (1.4113e-04, 1.6666), (3.3443e-04, 1.6666),
              (6.5150e-04, 1.6666), (1.1222e-03, 1.6666), (1.7753e-03, 1.6666), (2.6385e-03, 1.6666),
              (3.7381e-03, 1.6666), (5.0991e-03, 1.6666)],
    },
    "reduced": {
        "2": [(2.3881e-05, 1.6665), (2.3211e-05, 1.6660), (1.6634e-05, 1.6652), (1.0443e-05, 1.6642),
              (1.2153e-05, 1.6628), (1.3460e-05, 1.6611), (7.2016e-06, 1.6591), (7.5157e-06, 1.6568),
              (7.6967e-06, 1.6543), (7.7657e-06, 1.6514)],
        "3": [(2.3261e-05, 1.6666), (1.0527e-05, 1.6666), (1.3681e-05, 1.6666), (7.7153e-06, 1.6666),
              (8.0605e-06, 1.6666), (8.0266e-06, 1.6666), (7.7597e-06, 1.6665), (7.4664e-06, 1.6664),
              (7.4116e-06, 1.6663), (7.8648e-06, 1.6662)],
        "4": [(1.6713e-05, 1.6666), (1.3681e-05, 1.6666), (7.9443e-06, 1.6666), (8.0284e-06, 1.6666),
              (7.6044e-06, 1.6666), (7.4198e-06, 1.6666), (8.3770e-06, 1.6666), (6.2104e-06, 1.6666),
              (6.1258e-06, 1.6666), (6.0095e-06, 1.6666)],
    },
}
# Spectral radius above 1 + this counts as unstable: far above the round-off of the double
# eigenvalue at the boundary (~1e-8), and its effect on the located boundary is ~(1e-7)^2.
RADIUS_TOL = 1e-7


def moving_with(body, R1, p_hat1) -> Reference:
    """The reference moving with the top's initial velocity (`solve_tfe`'s
    `ConstantVelocityReference()`, Borri 1990 eqs 2.2-2.3): from R1, at the angular velocity of
    the momentum p_hat1 about the fixed point."""
    omega = body.momentum_to_velocity(R1, p_hat1)[:3]
    return Reference(R1, jnp.zeros(3), omega, jnp.zeros(3))


@partial(jax.jit, static_argnames=("form", "element"))
def top_transition(spin, dt, *, form, element):
    """Transition matrix of one element about the top spinning steadily at `spin` (eq 7.1)."""
    body = vt.build()
    R1 = jnp.eye(3)
    p_hat1 = body.mass_matrix(R1) @ jnp.array([0.0, 0.0, 1.0]) * spin
    ref = moving_with(body, R1, p_hat1)
    q1 = jnp.zeros(3)
    z1 = jnp.concatenate([form.to_form(body, q1, p_hat1), q1])
    return stability.transition_matrix(form, body, ref, element, dt, z1)


def transverse_exponent(T, h) -> complex:
    """The exponent with Im > 0 and the largest real part (the axial pair is at 0)."""
    e = np.asarray(stability.exponents(T, h))
    e = e[e.imag > 1e-6]
    return complex(e[np.argmax(e.real)])


def eigenvalue_table(form, quadrature: str, dts) -> dict:
    table = {}
    for nodes in NODES:
        step(f"{type(form).__name__}, {quadrature} quadrature, {nodes} nodes")
        element = Element(nodes, QUADRATURES[quadrature])
        rows = []
        for dt in dts:
            e = transverse_exponent(top_transition(vt.CRITICAL_SPIN, dt, form=form, element=element),
                                    element.length(dt))
            rows.append({"dt": dt, "re": e.real, "im": e.imag})
        table[str(nodes)] = rows
    return table


def boundary(form, element: Element, dts, iterations: int = 60) -> list[float]:
    """Least stable spin rate per dt, by bisection on [Omega_c / 2, 2 Omega_c] (vectorized in dt)."""
    radius = jax.jit(jax.vmap(lambda spin, dt: stability.spectral_radius(
        top_transition(spin, dt, form=form, element=element))))
    dts = jnp.asarray(dts)
    lo = jnp.full_like(dts, 0.5 * vt.CRITICAL_SPIN)
    hi = jnp.full_like(dts, 2.0 * vt.CRITICAL_SPIN)
    if not (np.all(radius(lo, dts) > 1 + RADIUS_TOL) and np.all(radius(hi, dts) <= 1 + RADIUS_TOL)):
        raise RuntimeError("the bracket [Omega_c / 2, 2 Omega_c] does not bound the boundary")
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        stable = radius(mid, dts) <= 1 + RADIUS_TOL
        lo, hi = jnp.where(stable, lo, mid), jnp.where(stable, mid, hi)
    return [float(b) for b in hi]


def reproduce(out: Path, quick: bool = False) -> dict:
    """Tables 1-2, the mixed form's table and the boundaries; writes JSON and PNG."""
    from mbjax_harness.plot.tfe import vertical_top_figure

    dts = DTS[::3] if quick else DTS
    primal, mixed = PrimalUnsymmetric(), Mixed()
    boundary_dts = [float(d) for d in np.linspace(0.02, 1.0, 6 if quick else 25)]
    data = {
        "scene": f"vertical top at its critical spin Omega_c = {vt.CRITICAL_SPIN:.6g} rad/s, "
                 "omega = sqrt(m g d / J_t) = 5/3; exponents ln(lambda) / h, h = (nodes - 1) dt",
        "exact": eigenvalue_table(primal, "exact", dts),
        "reduced": eigenvalue_table(primal, "reduced", dts),
        "mixed": eigenvalue_table(mixed, "exact", dts),
        "paper": {k: {n: [{"dt": dt, "re": re, "im": im} for dt, (re, im) in zip(DTS, rows)]
                      for n, rows in v.items()} for k, v in PAPER.items()},
        "stability_boundary": {
            "omega": vt.OMEGA,
            "dt": boundary_dts,
            "exact": boundary(primal, Element(2, ExactQuadrature()), boundary_dts),
            "reduced": boundary(primal, Element(2, ReducedQuadrature()), boundary_dts),
            "mixed": boundary(mixed, Element(2, ExactQuadrature()), boundary_dts),
            "exact_closed_form": [float(b) for b in vt.exact_boundaries(jnp.asarray(boundary_dts))[0]],
            "physical": vt.CRITICAL_SPIN,
        },
    }
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{NAME}.json").write_text(json.dumps(data, indent=1))
    vertical_top_figure(data).savefig(out / f"{NAME}.png", dpi=120)
    return data
