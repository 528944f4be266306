"""`mbjax bench tfe`: time finite elements against the step-by-step integrators on two scenes.
Speed against accuracy.

- the torque-free body of Borri 1990 §8.1 (6 s), error against the closed form (eq 8.8);
- the Simo-Wong heavy top (10 s, spinning at 50 rad/s), error against an adaptive Dopri8
  reference (rtol 1e-12).

Time elements: the primal form of eq 4.1 and the mixed form of eq 4.9 on 2-, 3- and 4-node
elements (exact quadrature, `solve_tfe`'s per-element constant-velocity reference) of lengths
ELEMENT_LENGTHS. Integrators: RK4, implicit midpoint and the Lie-group RKMK4 through `simulate`,
steps STEPS. Each record: run time (median after warm-up), compile time, the rotation error and
the relative energy error at the end, Newton's largest iteration count and the solution status.
JSON lines + PNG (error against run time, one panel per scene).
"""

import platform
from functools import partial
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from mbjax import lie
from mbjax_harness.timing import measure, write_jsonl
from mbjax.integrate import INTEGRATORS, simulate, solve_reference
from mbjax.scenes import heavy_top, torque_free_body
from mbjax.tfe import Body, Element, Mixed, PrimalUnsymmetric, initial_state, solve_tfe

NAME = "tfe"
FORMS = {"primal": PrimalUnsymmetric(), "mixed": Mixed()}
NODES = (2, 3, 4)
ELEMENT_LENGTHS = (0.1, 0.05, 0.025, 0.0125)   # s; each divides both scenes' durations
INTEGRATOR_NAMES = ("rk4", "implicit_midpoint", "rkmk4")
STEPS = (0.01, 0.005, 0.0025, 0.00125, 0.000625)


def scenes() -> dict:
    """name -> (RigidBody, q0, u0, duration, exact final rotation)."""
    out = {}
    body, q0, u0 = torque_free_body.build()
    out["torque-free body"] = (body, q0, u0, torque_free_body.DURATION,
                               torque_free_body.exact_rotation(torque_free_body.DURATION))
    body, q0, u0 = heavy_top.build()
    ref = solve_reference(body, q0, u0, jnp.array([0.0, heavy_top.DURATION]), rtol=1e-12, atol=1e-12)
    out["heavy top"] = (body, q0, u0, heavy_top.DURATION, body.rotation_matrix(ref.qs[-1]))
    return out


def angle(R, R_exact) -> float:
    """Rotation error in rad (NaN for a run that blew up)."""
    R = np.asarray(R)
    if not np.all(np.isfinite(R)):
        return float("nan")
    return float(np.linalg.norm(lie.log(jnp.asarray(R) @ R_exact.T)))


def run(out: Path, quick: bool = False) -> list[dict]:
    repeats = 3 if quick else 7
    lengths = ELEMENT_LENGTHS[1:3] if quick else ELEMENT_LENGTHS
    nodes_set = (2, 4) if quick else NODES
    steps = STEPS[1:4:2] if quick else STEPS
    common = {"machine": platform.machine(), "jax": jax.__version__}
    records = []
    for scene, (rigid, q0, u0, T, R_exact) in scenes().items():
        E0 = float(rigid.energy(q0, u0))
        body = Body.from_rigid(rigid)
        R0 = rigid.rotation_matrix(q0)
        state0 = initial_state(body, R0, u0)
        for form_name, form in FORMS.items():
            for nodes in nodes_set:
                element = Element(nodes)
                for length in lengths:
                    dt = length / (nodes - 1)
                    n = int(round(T / length))
                    sol, timing = measure(partial(solve_tfe, body, state0, dt=dt, n_elements=n,
                                                  form=form, element=element), repeats=repeats)
                    E = float(sol.energy(body)[-1])
                    records.append({**common, "scene": scene, "method": f"tfe {form_name} {nodes}-node",
                                    "family": "tfe", "form": form_name, "nodes": nodes,
                                    "element_length": length, "dt": dt, "duration": T,
                                    "compile_s": timing.compile_s, "run_s": timing.run_s,
                                    "error": angle(sol.R[-1], R_exact),
                                    "energy_error": abs(E / E0 - 1.0),
                                    "newton_iterations": int(np.max(sol.iterations)),
                                    "status": sol.messages()[0]})
        for name in INTEGRATOR_NAMES:
            for dt in steps:
                sol, timing = measure(partial(simulate, rigid, INTEGRATORS[name](), q0, u0, dt=dt,
                                              t1=T, saveat=[T]), repeats=repeats)
                q, u = sol.qs[-1], sol.vs[-1]
                finite = bool(jnp.all(jnp.isfinite(q)) & jnp.all(jnp.isfinite(u)))
                q = rigid.project(q) if finite else q
                records.append({**common, "scene": scene, "method": name, "family": "integrator",
                                "dt": dt, "duration": T, "compile_s": timing.compile_s,
                                "run_s": timing.run_s,
                                "error": angle(rigid.rotation_matrix(q), R_exact) if finite else float("nan"),
                                "energy_error": abs(float(rigid.energy(q, u)) / E0 - 1.0) if finite
                                else float("nan"), "status": sol.messages()[0]})

    out.mkdir(parents=True, exist_ok=True)
    write_jsonl(out / f"{NAME}.jsonl", records)
    from mbjax_harness.plot.bench import tfe_bench_figure
    tfe_bench_figure(records).savefig(out / f"{NAME}.png", dpi=120)
    for r in records:
        print(f"{r['scene']:17s} {r['method']:22s} dt={r['dt']:<9.4g} {r['run_s'] * 1e3:9.2f} ms "
              f"(compile {r['compile_s']:5.1f} s)  error {r['error']:.3g} rad  energy "
              f"{r['energy_error']:.3g}  {r['status']}")
    return records
