"""`mbjax reproduce spin-up-beam`: Kane's spin-up beam, stiffened or not, against an ANCF beam.
The modal tip with and without geometric stiffening against a nonlinear ANCF beam (Anderson 1993
§3.2, eq 109).

The hub-clamped cantilever (L = 10 m, `mbjax.scenes.spin_up_beam`) spun up in its own plane, omega
rising from 0 to 6 rad/s over 15 s and held; omega passes the first bending frequency (3.8 rad/s)
at t = 8.5 s. The modal model (20 beam elements, the lowest `N_BENDING` in-plane bending modes and
one axial mode, Craig-Bampton, clamped at the hub) is solved by Anderson 1993's O(n + m^3) route with
RK4 (`DT`), with geometric stiffening (eqs 32-33) and without it. Without stiffening
K - omega^2 M_yy softens and turns indefinite, and the tip runs away (about 70 m at 10 s and
1e20 m at 20 s); with stiffening the tip lags by at most 0.57 m and settles once omega is steady.

The reference is an independent model: the geometrically nonlinear ANCF beam of
`mbjax.scenes.spin_up_beam.reference` (absolute nodal coordinates, exact strains, no
modal truncation), `REFERENCE_ELEMENTS` elements, at the same save times.

The whole history is held to `HISTORY_TOLERANCE` (1e-3 m against a 0.57 m peak): the modes' beam
mesh sets the geometric stiffness's accuracy (element-constant axial forces, O(h^2)), and 10
elements left 1.2e-3 m, 20 leave 4.4e-4 m (8 ANCF elements are converged: 16 move the tip by
2.6e-5 m).

Full run: 20 s, 4 bending modes, ANCF with 8 elements, and a study of the peak against the number
of bending modes (1, 2, 4: each a compilation of its own). Quick run: 10 s (the peak at 7 s and
the runaway past the crossing), no study.

JSON (lengths in metres, transverse deflection in the rotating frame, negative when the tip lags):
{"t", "tip_deflection", "tip_deflection_no_stiffening", "axial_tip_displacement" (the contract;
the tip's displacement along the rotating beam axis, stiffened run: the axial mode's stretch minus
the foreshortening (1/2) int (w')^2 dx of the bending shape), and "axial_stretch" (the axial mode
alone), "omega" (rad/s at t), "reference": {"t", "tip_deflection", "tip_axial", "n_elements",
"seconds"}, "peak" (the most negative stiffened deflection), "peak_time", "reference_peak",
"peak_relative_error", "max_abs_difference" (stiffened against the reference over the run),
"history_tolerance" (m), "history_status" ("success", or "inaccurate: ..." where
max_abs_difference exceeds the tolerance),
"final_deflection", "no_stiffening_max_abs" (null where not finite), "modes": {"n_bending",
"n_axial", "n_elements"}, "dt", "duration", "seconds" (modal run after compilation),
"compile_seconds", "status", "status_no_stiffening", "mode_study": [{"n_bending", "peak",
"peak_relative_error", "seconds"}] (full run)}. Non-finite values are written as null.
"""

import json
import math
import time
from functools import partial
from pathlib import Path

import numpy as np

from mbjax_harness.timing import measure
from mbjax.flex import geometric_stiffness
from mbjax.scenes import spin_up_beam as scene

NAME = "spin-up-beam"
DT = 2e-3                      # RK4 step of the modal model
EVERY = 0.1                    # save interval
N_BENDING, QUICK_N_BENDING = 4, 4
N_ELEMENTS = 20                # beam elements behind the modes (the stiffening's accuracy, O(h^2))
REFERENCE_ELEMENTS, QUICK_REFERENCE_ELEMENTS = 8, 8
HISTORY_TOLERANCE = 1e-3       # m: the largest |tip deflection - reference| over the run
QUICK_DURATION = 10.0
MODE_STUDY = (1, 2, 4)


def finite_list(values) -> list:
    """Floats for JSON, null where not finite (the unstiffened run overflows)."""
    return [float(v) if math.isfinite(v) else None for v in np.asarray(values, float).ravel()]


def finite(value):
    value = float(value)
    return value if math.isfinite(value) else None


def history_status(difference: float, tolerance: float, unit: str) -> str:
    """"success" where the history's largest difference from the reference is within the
    tolerance, else "inaccurate: ..." saying by how much."""
    if math.isfinite(difference) and difference <= tolerance:
        return "success"
    return (f"inaccurate: the history departs from the reference by {difference:.3g} {unit}, "
            f"over the tolerance {tolerance:g} {unit}")


def modal_run(n_bending: int, duration: float, stiffening: bool = True, repeats: int = 1):
    """((ts, transverse, axial, solution) as numpy / Solution, Timing or None): `repeats` > 0
    times the run after compiling."""
    go = partial(scene.run, n_bending=n_bending, n_elements=N_ELEMENTS, stiffening=stiffening,
                 dt=DT, t1=duration, every=EVERY)
    (ts, tip, axial, sol), timing = measure(go, repeats=repeats) if repeats else (go(), None)
    return (np.asarray(ts), np.asarray(tip), np.asarray(axial), sol), timing


def foreshortening(n_bending: int, qs) -> np.ndarray:
    """The tip's axial pull-in from bending, (1/2) int_0^L (v'^2 + w'^2) dx, along a trajectory
    (q = (hub angle, modal coordinates)): the quadratic form of the unit-force geometric stiffness
    (the same integral that geometric stiffening uses) in the modal coordinates [m]."""
    structure = scene.beam(N_ELEMENTS)
    shapes = np.asarray(scene.modes(structure, n_bending).shapes)
    unit = np.asarray(geometric_stiffness(structure, np.ones(N_ELEMENTS), torsion=False))
    qf = np.asarray(qs)[:, 1:]
    return 0.5 * np.einsum("ti,ij,tj->t", qf, shapes.T @ unit @ shapes, qf)


def reproduce(out: Path, quick: bool = False) -> dict:
    """Modal model with and without stiffening against the ANCF beam; writes JSON and PNG."""
    from mbjax_harness.plot.flex import spin_up_figure

    duration = QUICK_DURATION if quick else scene.DURATION
    n_bending = QUICK_N_BENDING if quick else N_BENDING
    n_ref = QUICK_REFERENCE_ELEMENTS if quick else REFERENCE_ELEMENTS
    (ts, tip, stretch, sol), timing = modal_run(n_bending, duration)
    axial = stretch - foreshortening(n_bending, sol.qs)
    # same shapes, so the same compiled rollout: stiffening is data in the flexible body
    (_, tip_free, _, sol_free), _ = modal_run(n_bending, duration, stiffening=False,
                                             repeats=0)
    start = time.perf_counter()
    ref = scene.reference(n_elements=n_ref, ts=ts)
    ref_tip = np.asarray(ref.tip_deflection)
    ref_seconds = time.perf_counter() - start

    k, k_ref = int(np.argmin(tip)), int(np.argmin(ref_tip))
    peak, ref_peak = float(tip[k]), float(ref_tip[k_ref])
    with np.errstate(over="ignore", invalid="ignore"):
        free_abs = np.abs(tip_free)
    data = {
        "t": ts.tolist(),
        "tip_deflection": finite_list(tip),
        "tip_deflection_no_stiffening": finite_list(tip_free),
        "axial_tip_displacement": finite_list(axial),
        "axial_stretch": finite_list(stretch),
        "omega": np.asarray(scene.omega(ts)).tolist(),
        "reference": {"t": np.asarray(ref.ts).tolist(), "tip_deflection": finite_list(ref_tip),
                      "tip_axial": finite_list(ref.tip_axial), "n_elements": n_ref,
                      "model": "geometrically nonlinear ANCF beam (mbjax.scenes.spin_up_beam.reference)",
                      "seconds": ref_seconds},
        "peak": peak, "peak_time": float(ts[k]),
        "reference_peak": ref_peak, "reference_peak_time": float(ts[k_ref]),
        "peak_relative_error": abs(peak - ref_peak) / abs(ref_peak),
        "max_abs_difference": float(np.max(np.abs(tip - ref_tip))),
        "history_tolerance": HISTORY_TOLERANCE,
        "history_status": history_status(float(np.max(np.abs(tip - ref_tip))), HISTORY_TOLERANCE, "m"),
        "final_deflection": float(tip[-1]),
        "no_stiffening_max_abs": finite(np.nanmax(free_abs)) if np.any(np.isfinite(free_abs)) else None,
        "modes": {"n_bending": n_bending, "n_axial": 1, "n_elements": N_ELEMENTS},
        "dt": DT, "duration": duration,
        "seconds": timing.run_s, "compile_seconds": timing.compile_s,
        "status": sol.messages()[0], "status_no_stiffening": sol_free.messages()[0],
    }
    if not quick:
        study = []
        for nb in MODE_STUDY:
            if nb == n_bending:
                row_peak, seconds = peak, timing.run_s
            else:
                (_, tip_nb, _, _), timing_nb = modal_run(nb, duration)
                row_peak, seconds = float(np.min(tip_nb)), timing_nb.run_s
            study.append({"n_bending": nb, "peak": row_peak,
                          "peak_relative_error": abs(row_peak - ref_peak) / abs(ref_peak),
                          "seconds": seconds})
        data["mode_study"] = study
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{NAME}.json").write_text(json.dumps(data, indent=1, allow_nan=False))
    spin_up_figure(data).savefig(out / f"{NAME}.png", dpi=120)
    return data
