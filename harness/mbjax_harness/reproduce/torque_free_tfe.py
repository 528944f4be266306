"""`mbjax reproduce torque-free-tfe`: time elements on the torque-free body against its closed form.
As in Borri 1990 §8.1, Fig. 1 a-e.

The torque-free symmetric body (`mbjax.scenes.torque_free_body`: J_t / J_a = 1.875, 15 rad/s
about the symmetry axis and 10 rad/s about a transverse one, 6 s, about 100 rad of rotation)
marched with the primal form of eq 4.1 and the mixed form of eq 4.9 (the two the paper
discretizes, §5) on 2-, 3- and 4-node elements 0.015 s between nodes (Fig. 1 a-c) and 4-node
elements 0.030 and 0.045 s between nodes (Fig. 1 d-e); full ("exact") Gauss quadrature, each
element about a reference held at its initial configuration ("simply held constant", §2:
`ConstantReference()`). The error is the angle of R R_exact^T at every element boundary against
the closed form (eq 8.8).

JSON: {"cases": [{"form": "primal" | "mixed", "nodes", "spacing", "t", "error", "max_error",
"seconds", "iterations", "status"}, ...]}; "seconds" is the median run time of the whole 6 s
march after compilation.
"""

import json
from pathlib import Path

import jax
import numpy as np

from mbjax_harness.timing import measure
from mbjax.scenes import TOLERANCE
from mbjax.scenes import torque_free_body as tfb
from mbjax.tfe import (Body, ConstantReference, Element, Mixed, PrimalUnsymmetric, initial_state,
                       solve_tfe)

NAME = "torque-free-tfe"
PANELS = ((2, 0.015), (3, 0.015), (4, 0.015), (4, 0.030), (4, 0.045))
FORMS = {"primal": PrimalUnsymmetric(), "mixed": Mixed()}
REFERENCE = ConstantReference()


def scene():
    """(tfe.Body, initial State) of the §8.1 body."""
    body = Body.from_rigid(tfb.build()[0])
    return body, initial_state(body, np.eye(3), tfb.OMEGA0)


def run_case(form_name: str, nodes: int, spacing: float, repeats: int = 3,
             duration: float = tfb.DURATION) -> dict:
    body, state0 = scene()
    element = Element(nodes)
    n_elements = int(round(duration / element.length(spacing)))
    sol, timing = measure(lambda: solve_tfe(body, state0, dt=spacing, n_elements=n_elements,
                                            form=FORMS[form_name], element=element,
                                            reference=REFERENCE), repeats=repeats)
    # the accuracy status, from one more march (its estimate is not in the timing)
    checked = solve_tfe(body, state0, dt=spacing, n_elements=n_elements, form=FORMS[form_name],
                        element=element, reference=REFERENCE, **TOLERANCE)
    error = np.asarray(jax.jit(jax.vmap(tfb.rotation_error_matrix))(sol.R, sol.ts))
    return {"form": form_name, "nodes": nodes, "spacing": spacing,
            "t": np.asarray(sol.ts).tolist(), "error": error.tolist(),
            "max_error": float(error.max()), "seconds": timing.run_s,
            "iterations": int(np.max(sol.iterations)), "error_estimate": float(checked.error),
            "invariant_drift": float(checked.drift), "status": checked.messages()[0]}


def reproduce(out: Path, quick: bool = False) -> dict:
    """All Fig. 1 cases (quick: 2 s instead of 6 s); writes JSON and PNG."""
    from mbjax_harness.plot.tfe import torque_free_figure

    duration = 2.0 if quick else tfb.DURATION
    cases = [run_case(form, nodes, spacing, repeats=1 if quick else 3, duration=duration)
             for nodes, spacing in PANELS for form in FORMS]
    data = {"scene": f"torque-free body, Borri 1990 §8.1, {duration:g} s; primal = eq 4.1, "
                     "mixed = eq 4.9, exact quadrature, constant reference",
            "cases": cases}
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{NAME}.json").write_text(json.dumps(data, indent=1))
    torque_free_figure(data).savefig(out / f"{NAME}.png", dpi=110)
    return data
