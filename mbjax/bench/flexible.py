"""`mbjax bench flexible`: Kane's spin-up beam, the modal flexible body against the nonlinear
ANCF beam and exudyn.

- Speed against accuracy of mbjax's modal model (`mbjax.scenes.spin_up_beam`: Craig-Bampton modes
  of a 10-element beam, 1, 2, 4, 8 in-plane bending modes + 1 axial mode, geometric stiffening,
  the hub angle prescribed, seed 002's O(n + m^3) route, RK4) at the largest stable step (RK4's
  limit 2.8 / omega_max, omega_max the axial mode's 759 rad/s, rounded down to a whole number of
  steps per 0.1 s) and half of it; without geometric stiffening at the largest step for 4 bending
  modes (the spin passes the first bending frequency and the tip diverges: the error is reported,
  non-finite samples are counted, not fatal). Error = max |tip deflection - reference| over the
  span, tip deflection along the rotating y axis, sampled every 0.1 s.
- The reference: mbjax's geometrically nonlinear ANCF beam (`spin_up_beam_reference`, RK4 at
  half its stable step), 8 elements over 0-20 s (--quick: 4 elements over 0-8 s), computed once
  per run. It and a coarser ANCF beam (half the elements) are timed as the "full nonlinear FE"
  points. Their RK4 loop is jitted inside each call, so every call compiles: compile_s is the wall
  time of a call over one 0.1 s interval, run_s the wall time of the whole call minus that (one
  sample, not a median).
- exudyn (optional peer, same process): the same beam as `ObjectANCFCable2D` elements (as many as
  the reference), the root's position fixed and its slope direction (free magnitude, as in the
  reference) prescribed through a `GenericJoint` with an offset user function, exudyn's implicit
  generalized-alpha solver (spectral radius 0.8, fixed steps), at several steps; run_s is the median
  wall time of building and solving (the offset is a Python user function, called from C++).

Modal run times: median after warm-up (`mbjax.timing.measure`), compile time apart.
JSON lines + PNG.
"""

import platform
import time
from functools import partial
from pathlib import Path

import jax
import numpy as np

from mbjax.bench import peers
from mbjax.timing import measure, write_jsonl
from mbjax.integrate import RK4, simulate

NAME = "flexible"
MODES = (1, 2, 4, 8)
EVERY = 0.1                       # sampling of the tip deflection [s]
RK4_LIMIT = 2.8                   # omega dt on RK4's stability boundary (imaginary axis: 2.83)
EXUDYN_STEPS = (1e-2, 5e-3, 2e-3)


def largest_step(frequencies) -> float:
    """The largest step <= RK4_LIMIT / omega_max that divides EVERY."""
    return EVERY / int(np.ceil(EVERY * float(np.max(frequencies)) / RK4_LIMIT))


def _error(tip, reference) -> tuple[float, int]:
    """(max |tip - reference| over the finite samples, number of non-finite samples)."""
    tip = np.asarray(tip)
    finite = np.isfinite(tip)
    err = float(np.max(np.abs(tip[finite] - np.asarray(reference)[finite]), initial=0.0))
    return err, int(np.sum(~finite))


def modal(n_bending: int, stiffening: bool, dt: float, t1: float, ref, repeats: int, common) -> dict:
    from mbjax.scenes import spin_up_beam

    system, q0, v0 = spin_up_beam.build(n_bending, 1, 10, stiffening)
    saveat = np.round(np.arange(0.0, t1 + EVERY / 2, EVERY), 10)
    sol, timing = measure(partial(simulate, system, RK4(), q0, v0, dt=dt, t1=t1, saveat=saveat),
                          repeats=repeats)
    tip, _ = spin_up_beam.tip(system, sol.qs)
    err, nonfinite = _error(tip, ref.tip_deflection)
    tip = np.asarray(tip)
    k = int(np.nanargmin(np.where(np.isfinite(tip), tip, np.nan))) if np.any(np.isfinite(tip)) else 0
    return {**common, "kind": "modal", "engine": "mbjax", "model": "modal",
            "n_bending": n_bending, "n_axial": 1, "n_elements": 10, "stiffening": stiffening,
            "dt": dt, "duration": t1, "compile_s": timing.compile_s, "run_s": timing.run_s,
            "error": err, "nonfinite_samples": nonfinite,
            "max_abs_tip": float(np.max(np.abs(tip[np.isfinite(tip)]), initial=0.0)),
            "peak": float(tip[k]), "t_peak": float(saveat[k]), "status": sol.messages()[0]}


def ancf(n_elements: int, ts, common) -> tuple[dict, object]:
    """One timed call of the ANCF reference (see the module docstring for the timing)."""
    from mbjax.flex.references import spin_up_beam_reference

    start = time.perf_counter()
    jax.block_until_ready(spin_up_beam_reference(n_elements, ts[:2]).tip_deflection)
    compile_s = time.perf_counter() - start
    start = time.perf_counter()
    ref = spin_up_beam_reference(n_elements, ts)
    jax.block_until_ready(ref.tip_deflection)
    wall = time.perf_counter() - start
    tip = np.asarray(ref.tip_deflection)
    k = int(np.argmin(tip))
    return ({**common, "kind": "ancf", "engine": "mbjax", "model": "ANCF",
             "n_elements": n_elements, "dt": float(ref.solution.dt), "duration": float(ts[-1]),
             "compile_s": compile_s, "run_s": max(wall - compile_s, 0.0), "wall_s": wall,
             "peak": float(tip[k]), "t_peak": float(ts[k]),
             "status": "success" if np.all(np.isfinite(tip)) else "non-finite"}, ref)


def exudyn_records(n_elements: int, ts, ref, steps, repeats: int, common) -> list[dict]:
    base = {**common, "kind": "peer", "engine": "exudyn", "model": "ObjectANCFCable2D",
            "n_elements": n_elements, "duration": float(ts[-1])}
    if not peers.available("exudyn"):
        return [{**base, "status": "unavailable: exudyn is not installed"}]
    import exudyn

    records = []
    for dt in steps:
        try:
            solve = partial(peers.exudyn_spin_up_beam, n_elements, dt, ts)
            tip, timing = measure(solve, repeats=repeats)
        except Exception as exc:  # exudyn raises its own SolverError on a failed Newton step
            records.append({**base, "dt": dt, "status": f"failed: {type(exc).__name__}: {exc}"})
            continue
        err, nonfinite = _error(tip, ref.tip_deflection)
        k = int(np.argmin(tip))
        records.append({**base, "dt": dt, "exudyn": exudyn.__version__,
                        "compile_s": timing.compile_s, "run_s": timing.run_s, "error": err,
                        "nonfinite_samples": nonfinite, "peak": float(tip[k]),
                        "t_peak": float(ts[k]), "status": "success"})
    return records


def run(out: Path, quick: bool = False) -> list[dict]:
    from mbjax.scenes import spin_up_beam

    common = {"machine": platform.machine(), "jax": jax.__version__}
    t1, n_ref = (8.0, 4) if quick else (spin_up_beam.DURATION, 8)
    modes = (1, 4) if quick else MODES
    repeats = 1 if quick else 3
    ts = np.round(np.arange(0.0, t1 + EVERY / 2, EVERY), 10)

    reference, ref = ancf(n_ref, ts, common)
    coarse, coarse_ref = ancf(n_ref // 2, ts, common)
    reference["error"] = 0.0
    reference["reference"] = True
    coarse["error"], _ = _error(coarse_ref.tip_deflection, ref.tip_deflection)
    records = [reference, coarse]

    structure = spin_up_beam.beam(10)
    for n_bending in modes:
        dt = largest_step(spin_up_beam.modes(structure, n_bending, 1).frequencies)
        for step in (dt,) if quick else (dt, dt / 2):
            records.append(modal(n_bending, True, step, t1, ref, repeats, common))
    n_bending = 4
    dt = largest_step(spin_up_beam.modes(structure, n_bending, 1).frequencies)
    records.append(modal(n_bending, False, dt, t1, ref, repeats, common))

    records += exudyn_records(n_ref, ts, ref, EXUDYN_STEPS[:2] if quick else EXUDYN_STEPS,
                              repeats, common)
    for r in records:
        r["reference_n_elements"] = n_ref

    out.mkdir(parents=True, exist_ok=True)
    write_jsonl(out / f"{NAME}.jsonl", records)
    from mbjax.plot.bench import flexible_bench_figure
    flexible_bench_figure(records).savefig(out / f"{NAME}.png", dpi=120)
    for r in records:
        what = (f"{r['n_bending']} bending + 1 axial, {'stiffened' if r['stiffening'] else 'no stiffening'}"
                if r["kind"] == "modal" else f"{r['model']} {r['n_elements']} el")
        if "run_s" not in r:
            print(f"{r['engine']:7s} {what:36s} {r['status']}")
            continue
        print(f"{r['engine']:7s} {what:36s} dt={r['dt']:<9.3g} {r['run_s']:8.3f} s "
              f"(compile {r['compile_s']:5.1f} s)  error {r['error']:.3g} m  "
              f"peak {r['peak']:.5f} m at {r['t_peak']:.1f} s  {r['status']}")
    return records
