"""`mbjax reproduce flexible-slider-crank`: a slider-crank's flexible rod against an ANCF rod.
Its midpoint deflection against a nonlinear ANCF rod over three crank turns (Anderson 1993 §3.1,
Figs. 4-5).

The slider-crank with a flexible connecting rod (`mbjax.scenes.flexible_slider_crank`: 6 in rigid
crank at 125.6 rad/s, 12 in steel rod of 0.25 in diameter, massless slider), the rod modelled by
1, 2 and 3 beam elements with all their in-plane modes and geometric stiffening, solved by Anderson
1993's O(n + m^3) route with projection, RK4; the rod's midpoint deflection from the chord PQ in
inches, positive away from O at t = 0, over three crank revolutions (0.15 s).

The slider's constraint load stiffens the rod as a child's reaction would (Anderson 1993 eq 33, through
the grid point's second-order displacement, `grid_point` in mbjax/_src/flex/kinematics.py): without it the
3-element rod departed from the reference after the first revolution (0.087 in over 0.15 s against
a 0.145 in amplitude); with it the whole history stays within `HISTORY_TOLERANCE`.

The reference is an independent model: the geometrically nonlinear ANCF rod of
`mbjax.scenes.flexible_slider_crank.reference` (absolute nodal coordinates, exact strains), 4
elements, at the same save times.

RK4 steps: the 3-element model's highest mode needs dt <= 1e-5 s; 1 and 2 elements are stable at
2e-5 s. Full run: 1, 2, 3 elements at `DT` over 0.15 s. Quick run: 1 and 2 elements at
`QUICK_DT` over one revolution (0.05 s), ANCF with 2 elements.

JSON: {"t", "midpoint_deflection_in" (the contract: the finest model's, 3 elements in the full
run, 2 in the quick one), "n_elements" (that model's element count), "by_elements": {"1": [...],
"2": [...], "3": [...]}, "reference": {"t", "midpoint_deflection_in", "n_elements", "seconds"},
"peaks": {"1": peak |deflection|, ...}, "reference_peak", "peak_relative_errors": {"1", ...},
"max_abs_differences": {"1", ...} (against the reference over the whole run), "history_tolerance_in"
(`HISTORY_TOLERANCE`, 0.01 in), "history_status": {"1", ...} ("success", or "inaccurate: ..."
where the history departs by more), "dt": {"1", ...},
"seconds": {"1", ...} (wall time of each run, compilation included), "duration", "status":
{"1", ...}}. Non-finite values are written as null.
"""

import json
import math
import time
from pathlib import Path

import numpy as np

from mbjax_harness.progress import step
from mbjax_harness.reproduce.spin_up_beam import history_status
from mbjax.scenes import flexible_slider_crank as scene

NAME = "flexible-slider-crank"
ELEMENTS, QUICK_ELEMENTS = (1, 2, 3), (1, 2)
DT, QUICK_DT = 1e-5, 2e-5
EVERY = 5e-4
HISTORY_TOLERANCE = 0.01                  # in: the largest |deflection - reference| over the run
REFERENCE_ELEMENTS, QUICK_REFERENCE_ELEMENTS = 4, 2
QUICK_DURATION = 0.05                      # one crank revolution, 2 pi / 125.6 s


def finite(value):
    value = float(value)
    return value if math.isfinite(value) else None


def finite_list(values) -> list:
    return [float(v) if math.isfinite(v) else None for v in np.asarray(values, float).ravel()]


def reproduce(out: Path, quick: bool = False) -> dict:
    """The midpoint deflection for each element count against the ANCF rod; JSON and PNG."""
    from mbjax_harness.plot.flex import slider_crank_figure

    duration = QUICK_DURATION if quick else scene.DURATION
    dt = QUICK_DT if quick else DT
    elements = QUICK_ELEMENTS if quick else ELEMENTS
    runs = {}
    for n in elements:
        step(f"{n} elements")
        start = time.perf_counter()
        ts, d, sol = scene.run(n_elements=n, dt=dt, t1=duration, every=EVERY)
        d = np.asarray(d)
        runs[str(n)] = (np.asarray(ts), d, time.perf_counter() - start, sol.messages()[0])
    ts = runs[str(elements[0])][0]
    n_ref = QUICK_REFERENCE_ELEMENTS if quick else REFERENCE_ELEMENTS
    start = time.perf_counter()
    ref = scene.reference(n_elements=n_ref, ts=ts)
    ref_seconds = time.perf_counter() - start
    ref_d = np.asarray(ref.midpoint_deflection)
    ref_peak = float(np.max(np.abs(ref_d)))
    finest = str(max(elements))
    peaks = {n: finite(np.max(np.abs(d))) for n, (_, d, _, _) in runs.items()}
    data = {
        "t": ts.tolist(),
        "midpoint_deflection_in": finite_list(runs[finest][1]),
        "n_elements": int(finest),
        "by_elements": {n: finite_list(d) for n, (_, d, _, _) in runs.items()},
        "reference": {"t": np.asarray(ref.ts).tolist(), "midpoint_deflection_in": finite_list(ref_d),
                      "n_elements": n_ref,
                      "model": "geometrically nonlinear ANCF beam "
                               "(mbjax.scenes.flexible_slider_crank.reference)",
                      "seconds": ref_seconds},
        "peaks": peaks,
        "reference_peak": ref_peak,
        "peak_relative_errors": {n: None if p is None else abs(p - ref_peak) / ref_peak
                                 for n, p in peaks.items()},
        "max_abs_differences": {n: finite(np.max(np.abs(d - ref_d))) for n, (_, d, _, _) in runs.items()},
        "history_tolerance_in": HISTORY_TOLERANCE,
        "history_status": {n: history_status(float(np.max(np.abs(d - ref_d))), HISTORY_TOLERANCE, "in")
                           for n, (_, d, _, _) in runs.items()},
        "dt": {n: dt for n in runs},
        "seconds": {n: r[2] for n, r in runs.items()},
        "duration": duration,
        "status": {n: r[3] for n, r in runs.items()},
    }
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{NAME}.json").write_text(json.dumps(data, indent=1, allow_nan=False))
    slider_crank_figure(data).savefig(out / f"{NAME}.png", dpi=120)
    return data
