"""`mbjax bench flexible`: work against precision on Anderson 1993's two flexible scenes. The
modal bodies against geometrically nonlinear ANCF beams (mbjax's own and exudyn's), one run.

Kane's spin-up beam (`mbjax.scenes.spin_up_beam`, 0-20 s; --quick 0-8 s), records with
"scene": "spin-up":
- mbjax's modal model: Craig-Bampton modes of a `N_ELEMENTS`-element beam (1, 4, 8 in-plane
  bending + 1 axial mode; the basis mesh sets the stiffening's accuracy, O(h^2): 10 elements
  leave 1.2e-3 m, 20 leave 4e-4 m), geometric stiffening, the hub angle prescribed, Anderson 1993's
  O(n + m^3) route. RK4 at the largest stable step (RK4's limit 2.8 / omega_max, omega_max the
  axial mode's 759 rad/s, rounded down to a whole number of steps per 0.1 s) and half of it;
  `ImplicitMidpoint(simplified=True)` (projected onto the prescribed angle) at steps far past the
  axial mode's period, `IMPLICIT_STEPS`; without geometric stiffening at RK4's largest step for 4
  bending modes (the spin passes the first bending frequency and the tip diverges: the error is
  reported, non-finite samples are counted, not fatal). Error = max |tip deflection - reference|
  over the span (the whole history), tip deflection along the rotating y axis, every 0.1 s.
- The reference: mbjax's ANCF beam (`spin_up_beam.reference`, RK4 at half its stable step), 8
  elements (converged: 16 elements move the tip by 2.6e-5 m), and a coarser one (half the
  elements), both timed ("kind": "ancf").
  Their RK4 loop is jitted inside each call, so every call compiles: run_s is the wall time of a
  call over twice the span less that of a call over the span (the compilations cancel; one
  sample), compile_s the rest of the call's wall time.
- exudyn (optional peer, same process): the same beam as `ObjectANCFCable2D` elements (as many as
  the reference), implicit generalized-alpha at `EXUDYN_STEPS`.

The slider-crank with a flexible rod (`mbjax.scenes.flexible_slider_crank`, 0-0.15 s; --quick one
revolution, 0.05 s), records with "scene": "slider-crank": the modal rod (2 and 3 elements, all
in-plane modes; --quick 2) with RK4 at its stable step and with the simplified implicit midpoint
at `CRANK_IMPLICIT_STEPS`; mbjax's ANCF rod (4 elements, the reference, and 2); exudyn's ANCF
cable rod (4 elements) at `EXUDYN_CRANK_STEPS`. Error = max |midpoint deflection - reference|
over the history [in].

Every record has "error" (the history's largest difference), "run_s" (median after warm-up,
`mbjax_harness.timing.measure`, for mbjax's modal runs and exudyn; compilation apart in "compile_s") and
"status". Records of kind "summary" give, per scene and engine, the fastest run whose error is
within the scene's tolerance (`TOLERANCE`: 1e-3 m, 0.01 in), or null. JSON lines + PNG (one
panel per scene).
"""

import platform
import time
from functools import partial
from pathlib import Path

import jax
import numpy as np

from mbjax_harness import peers
from mbjax_harness.timing import measure, write_jsonl
from mbjax.integrate import RK4, simulate

NAME = "flexible"
MODES, QUICK_MODES = (1, 4, 8), (1, 4)
N_ELEMENTS = 20                   # the spin-up basis mesh (the modal model has 5 coordinates)
EVERY = 0.1                       # sampling of the tip deflection [s]
RK4_LIMIT = 2.8                   # omega dt on RK4's stability boundary (imaginary axis: 2.83)
IMPLICIT_STEPS, QUICK_IMPLICIT_STEPS = (0.1, 0.05, 0.02), (0.05,)
EXUDYN_STEPS, QUICK_EXUDYN_STEPS = (2e-2, 1e-2, 5e-3, 2e-3), (1e-2, 5e-3)
CRANK_EVERY = 5e-4
CRANK_ELEMENTS, QUICK_CRANK_ELEMENTS = (2, 3), (2,)
CRANK_RK4_STEP = {2: 2e-5, 3: 1e-5}
CRANK_IMPLICIT_STEPS, QUICK_CRANK_IMPLICIT_STEPS = (1e-4, 5e-5), (1e-4,)
EXUDYN_CRANK_STEPS, QUICK_EXUDYN_CRANK_STEPS = (1e-4, 5e-5, 2e-5), (1e-4,)
TOLERANCE = {"spin-up": 1e-3, "slider-crank": 0.01}     # m, in
IMPLICIT_NAME = "implicit_midpoint (simplified Newton, 4 iterations)"


def largest_step(frequencies) -> float:
    """The largest step <= RK4_LIMIT / omega_max that divides EVERY."""
    return EVERY / int(np.ceil(EVERY * float(np.max(frequencies)) / RK4_LIMIT))


def implicit():
    from mbjax.integrate import ImplicitMidpoint
    return ImplicitMidpoint(simplified=True, newton_iterations=4)


def _error(values, reference) -> tuple[float, int]:
    """(max |values - reference| over the finite samples, number of non-finite samples)."""
    values = np.asarray(values)
    finite = np.isfinite(values)
    err = float(np.max(np.abs(values[finite] - np.asarray(reference)[finite]), initial=0.0))
    return err, int(np.sum(~finite))


def _timed(system, integrator, q0, v0, dt, t1, saveat, repeats):
    return measure(partial(simulate, system, integrator, q0, v0, dt=dt, t1=t1, saveat=saveat),
                   repeats=repeats)


def spin_up_modal(n_bending: int, stiffening: bool, dt: float, t1: float, ref, repeats: int,
                  common, integrator=None) -> dict:
    from mbjax.scenes import spin_up_beam

    system, q0, v0 = spin_up_beam.build(n_bending, 1, N_ELEMENTS, stiffening,
                                        projection=integrator is not None)
    saveat = np.round(np.arange(0.0, t1 + EVERY / 2, EVERY), 10)
    sol, timing = _timed(system, integrator or RK4(), q0, v0, dt, t1, saveat, repeats)
    tip, _ = spin_up_beam.tip(system, sol.qs)
    err, nonfinite = _error(tip, ref.tip_deflection)
    tip = np.asarray(tip)
    k = int(np.nanargmin(np.where(np.isfinite(tip), tip, np.nan))) if np.any(np.isfinite(tip)) else 0
    return {**common, "scene": "spin-up", "kind": "modal", "engine": "mbjax", "model": "modal",
            "integrator": "rk4" if integrator is None else IMPLICIT_NAME,
            "n_bending": n_bending, "n_axial": 1, "n_elements": N_ELEMENTS, "stiffening": stiffening,
            "dt": dt, "duration": t1, "compile_s": timing.compile_s, "run_s": timing.run_s,
            "error": err, "nonfinite_samples": nonfinite,
            "max_abs_tip": float(np.max(np.abs(tip[np.isfinite(tip)]), initial=0.0)),
            "peak": float(tip[k]), "t_peak": float(saveat[k]), "status": sol.messages()[0]}


def _timed_reference(call, ts):
    """(result, compile_s, run_s, wall_s) of a reference whose every call compiles (see the
    module docstring): run_s is the wall time of a call over twice the span less that of the call
    over the span (the compilations cancel), compile_s the rest of the call's wall time."""
    start = time.perf_counter()
    result = call(ts)
    jax.block_until_ready(result.solution.e)
    wall = time.perf_counter() - start
    start = time.perf_counter()
    jax.block_until_ready(call(np.concatenate([ts, ts[-1] + ts[1:]])).solution.e)
    run_s = max(time.perf_counter() - start - wall, 0.0)
    return result, max(wall - run_s, 0.0), run_s, wall


def spin_up_ancf(n_elements: int, ts, common) -> tuple[dict, object]:
    from mbjax.scenes import spin_up_beam

    ref, compile_s, run_s, wall = _timed_reference(
        lambda t: spin_up_beam.reference(n_elements, t), ts)
    tip = np.asarray(ref.tip_deflection)
    k = int(np.argmin(tip))
    return ({**common, "scene": "spin-up", "kind": "ancf", "engine": "mbjax", "model": "ANCF",
             "n_elements": n_elements, "dt": float(ref.solution.dt), "duration": float(ts[-1]),
             "compile_s": compile_s, "run_s": run_s, "wall_s": wall,
             "peak": float(tip[k]), "t_peak": float(ts[k]), "status": ref.solution.messages()[0]},
            ref)


def _exudyn(solve, reference, steps, repeats, base) -> list[dict]:
    if not peers.available("exudyn"):
        return [{**base, "status": "unavailable: exudyn is not installed"}]
    import exudyn

    records = []
    for dt in steps:
        try:
            values, timing = measure(partial(solve, dt), repeats=repeats)
        except Exception as exc:  # exudyn raises its own SolverError on a failed Newton step
            records.append({**base, "dt": dt, "status": f"failed: {type(exc).__name__}: {exc}"})
            continue
        err, nonfinite = _error(values, reference)
        records.append({**base, "dt": dt, "exudyn": exudyn.__version__,
                        "compile_s": timing.compile_s, "run_s": timing.run_s, "error": err,
                        "nonfinite_samples": nonfinite,
                        "status": "success" if nonfinite == 0 else "non-finite"})
    return records


def spin_up(common, quick: bool) -> list[dict]:
    from mbjax.scenes import spin_up_beam

    t1, n_ref = (8.0, 8) if quick else (spin_up_beam.DURATION, 8)
    repeats = 1 if quick else 3
    ts = np.round(np.arange(0.0, t1 + EVERY / 2, EVERY), 10)
    reference, ref = spin_up_ancf(n_ref, ts, common)
    coarse, coarse_ref = spin_up_ancf(n_ref // 2, ts, common)
    reference["error"] = 0.0
    reference["reference"] = True
    coarse["error"], _ = _error(coarse_ref.tip_deflection, ref.tip_deflection)
    records = [reference, coarse]

    structure = spin_up_beam.beam(N_ELEMENTS)
    for n_bending in QUICK_MODES if quick else MODES:
        dt = largest_step(spin_up_beam.modes(structure, n_bending, 1).frequencies)
        for step in (dt,) if quick else (dt, dt / 2):
            records.append(spin_up_modal(n_bending, True, step, t1, ref, repeats, common))
    for step in QUICK_IMPLICIT_STEPS if quick else IMPLICIT_STEPS:
        records.append(spin_up_modal(4, True, step, t1, ref, repeats, common, implicit()))
    dt = largest_step(spin_up_beam.modes(structure, 4, 1).frequencies)
    records.append(spin_up_modal(4, False, dt, t1, ref, repeats, common))

    base = {**common, "scene": "spin-up", "kind": "peer", "engine": "exudyn",
            "model": "ObjectANCFCable2D", "n_elements": n_ref, "duration": t1}
    records += _exudyn(lambda dt: peers.exudyn_spin_up_beam(n_ref, dt, ts),
                       ref.tip_deflection, QUICK_EXUDYN_STEPS if quick else EXUDYN_STEPS,
                       repeats, base)
    for r in records:
        r["reference_n_elements"] = n_ref
    return records


def slider_crank(common, quick: bool) -> list[dict]:
    from mbjax.scenes import flexible_slider_crank as scene

    t1 = 0.05 if quick else scene.DURATION
    repeats = 1 if quick else 3
    ts = np.round(np.arange(0.0, t1 + CRANK_EVERY / 2, CRANK_EVERY), 12)
    base = {**common, "scene": "slider-crank", "duration": t1}
    records, ref = [], None
    for n in (4, 2):
        result, compile_s, run_s, wall = _timed_reference(
            lambda t: scene.reference(n, t), ts)
        d = np.asarray(result.midpoint_deflection)
        ref = d if ref is None else ref
        records.append({**base, "kind": "ancf", "engine": "mbjax", "model": "ANCF",
                        "n_elements": n, "dt": float(result.solution.dt), "compile_s": compile_s,
                        "run_s": run_s, "wall_s": wall, "error": _error(d, ref)[0],
                        "reference": n == 4, "status": result.solution.messages()[0]})
    for n in QUICK_CRANK_ELEMENTS if quick else CRANK_ELEMENTS:
        system, q0, v0, midpoint = scene.build(n)
        runs = [(None, CRANK_RK4_STEP[n])] + [
            (implicit(), dt) for dt in (QUICK_CRANK_IMPLICIT_STEPS if quick else CRANK_IMPLICIT_STEPS)]
        for integrator, dt in runs:
            sol, timing = _timed(system, integrator or RK4(), q0, v0, dt, t1, ts, repeats)
            d = scene.midpoint_deflection(system, midpoint, sol.qs) / scene.INCH
            err, nonfinite = _error(d, ref)
            records.append({**base, "kind": "modal", "engine": "mbjax", "model": "modal",
                            "integrator": "rk4" if integrator is None else IMPLICIT_NAME,
                            "n_elements": n, "stiffening": True, "dt": dt,
                            "compile_s": timing.compile_s, "run_s": timing.run_s, "error": err,
                            "nonfinite_samples": nonfinite, "status": sol.messages()[0]})
    peer = {**base, "kind": "peer", "engine": "exudyn", "model": "ObjectANCFCable2D",
            "n_elements": 4}
    records += _exudyn(lambda dt: peers.exudyn_slider_crank(4, dt, ts), ref,
                       QUICK_EXUDYN_CRANK_STEPS if quick else EXUDYN_CRANK_STEPS, repeats, peer)
    for r in records:
        r["reference_n_elements"] = 4
    return records


def summaries(records: list[dict], common) -> list[dict]:
    """Per scene and engine, the fastest run within the scene's tolerance (exudyn, mbjax's modal
    bodies, mbjax's ANCF beams apart; the reference itself excluded)."""
    out = []
    for scene, tolerance in TOLERANCE.items():
        for kind in ("modal", "peer", "ancf"):
            rows = [r for r in records if r.get("scene") == scene and r["kind"] == kind
                    and "run_s" in r and not r.get("reference")]
            within = [r for r in rows if r.get("error") is not None and r["error"] <= tolerance
                      and r.get("status") == "success"]
            best = min(within, key=lambda r: r["run_s"]) if within else None
            if rows:
                out.append({**common, "scene": scene, "kind": "summary", "of": kind,
                            "engine": rows[0]["engine"], "tolerance": tolerance,
                            "fastest": None if best is None else {
                                k: best.get(k) for k in ("model", "integrator", "n_elements",
                                                         "n_bending", "dt", "run_s",
                                                         "compile_s", "error")}})
    return out


def _describe(r) -> str:
    if r["kind"] == "modal":
        modes = f"{r['n_bending']} bend+1 ax, " if "n_bending" in r else ""
        stiff = "" if r["stiffening"] else ", no stiffening"
        return f"modal {modes}{r['n_elements']} el, {r['integrator'].split(' ')[0]}{stiff}"
    return f"{r['model']} {r['n_elements']} el"


def run(out: Path, quick: bool = False) -> list[dict]:
    common = {"machine": platform.machine(), "jax": jax.__version__}
    records = spin_up(common, quick) + slider_crank(common, quick)
    records += summaries(records, common)

    out.mkdir(parents=True, exist_ok=True)
    write_jsonl(out / f"{NAME}.jsonl", records)
    from mbjax_harness.plot.bench import flexible_bench_figure
    flexible_bench_figure(records).savefig(out / f"{NAME}.png", dpi=120)
    for r in records:
        if r["kind"] == "summary":
            best = r["fastest"]
            what = ("none within the tolerance" if best is None else
                    f"{best['run_s']:.3f} s (dt {best['dt']:.3g}, error {best['error']:.3g})")
            print(f"{r['scene']:12s} fastest within {r['tolerance']:g}: {r['engine']:7s} "
                  f"{r['of']:6s} {what}")
            continue
        unit = "m" if r["scene"] == "spin-up" else "in"
        if "run_s" not in r:
            print(f"{r['scene']:12s} {r['engine']:7s} {_describe(r):42s} {r['status']}")
            continue
        print(f"{r['scene']:12s} {r['engine']:7s} {_describe(r):42s} dt={r['dt']:<9.3g} "
              f"{r['run_s']:8.3f} s (compile {r['compile_s']:5.1f} s)  error {r['error']:.3g} "
              f"{unit}  {r['status']}")
    return records
