"""`mbjax bench wrist`: the Carpal Wrist's dynamics, rollouts and parameter sweeps.

- Work-precision: RK4 on the torque-free tool (scene `carpal_wrist.free_motion`, 0.4 s) at the steps
  STEPS, error against RK4 at 0.1 ms; run time and compile time separately.
- Routes: forward dynamics by the autodiff Lagrangian (eq 6.21) and inverse dynamics by the
  Lagrangian and by Newton-Euler, one call and a vmapped batch of BATCH states (time per state);
  the largest difference of the two inverse-dynamics routes.
- Sweep: peak motor torque along the minimum-jerk START -> GOAL path for VARIANTS wrist variants,
  one jitted vmap, and the same sharded over all local devices (`jax.sharding`) when there are
  several (run with XLA_FLAGS=--xla_force_host_platform_device_count=2 to split a CPU in two, or on
  a GPU host).

No peer engine is measured: Pinocchio, MuJoCo and exudyn have no Carpal Wrist, and modelling its
three closed loops there is a different (constrained, numerically closed) problem from the
chapter's closed-form coordinates. JSON lines + PNG.
"""

import platform
from functools import partial
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from mbjax_harness.timing import measure, write_jsonl
from mbjax.integrate import RK4, simulate
from mbjax.scenes import carpal_wrist as cw
from mbjax.trajopt import sweep as sweep_variants
from mbjax.wrist import ToolPath, grid, peak_torque

NAME = "wrist"
STEPS = (0.04, 0.02, 0.01, 5e-3, 2e-3)
QUICK_STEPS = (0.02, 5e-3)
BATCH = 1000


def work_precision(steps, repeats, common) -> list[dict]:
    system, q0, u0 = cw.free_motion()
    T = cw.FREE_DURATION
    ref = simulate(system, RK4(), q0, u0, dt=1e-4, t1=T, saveat=[T]).qs[-1]
    records = []
    for dt in steps:
        sol, timing = measure(partial(simulate, system, RK4(), q0, u0, dt=dt, t1=T, saveat=[T]),
                              repeats=repeats)
        records.append({**common, "kind": "work-precision", "integrator": "rk4", "dt": dt, "duration": T,
                        "compile_s": timing.compile_s, "run_s": timing.run_s,
                        "error": float(jnp.max(jnp.abs(sol.qs[-1] - ref))), "status": sol.messages()[0]})
    return records


def routes(repeats, common) -> list[dict]:
    w = cw.wrist()
    rng = np.random.default_rng(0)
    q = jnp.asarray(np.asarray(cw.home(w)) + rng.uniform(-0.3, 0.3, (BATCH, 3)))
    qd, qdd = jnp.asarray(rng.normal(0, 2, (BATCH, 3))), jnp.asarray(rng.normal(0, 20, (BATCH, 3)))
    fns = {"forward dynamics (Lagrange)": lambda a, b, c: w.forward_dynamics(a, b, c),
           "inverse dynamics (Lagrange)": lambda a, b, c: w.inverse_dynamics(a, b, c),
           "inverse dynamics (Newton-Euler)": lambda a, b, c: w.newton_euler_torques(a, b, c)}
    records = []
    for name, fn in fns.items():
        one, t1 = measure(jax.jit(fn), q[0], qd[0], qdd[0], repeats=10 * repeats)
        many, tb = measure(jax.jit(jax.vmap(fn)), q, qd, qdd, repeats=repeats)
        records.append({**common, "kind": "route", "route": name, "compile_s": t1.compile_s,
                        "run_s": t1.run_s, "batch": BATCH, "batch_run_s": tb.run_s,
                        "batch_us_per_state": tb.run_s / BATCH * 1e6})
    routes_gap = jax.jit(jax.vmap(lambda *x: w.inverse_dynamics(*x) - w.newton_euler_torques(*x)))
    diff = jnp.max(jnp.abs(routes_gap(q, qd, qdd)))
    for r in records:
        r["lagrange_newton_euler_max_diff"] = float(diff)
    return records


def sweep(variants_per_axis: int, repeats, common) -> list[dict]:
    w = cw.wrist()
    path = ToolPath(cw.START, cw.GOAL, cw.DURATION)
    k = variants_per_axis
    wrists, shape = grid(w, tool_mass=np.linspace(0.5, 3.0, k),
                         tool_com=[(0.01, -0.005, z) for z in np.linspace(0.0, 0.15, k)],
                         link_length=np.linspace(0.09, 0.12, k))
    variants = int(np.prod(shape))
    fn = partial(peak_torque, path=path)
    records = []
    peaks = {}
    layouts = {"vmap, 1 device": None}
    if len(jax.devices()) > 1:
        layouts[f"sharded, {len(jax.devices())} devices"] = jax.devices()
    for name, devices in layouts.items():
        out, timing = measure(partial(sweep_variants, fn, wrists, devices=devices), repeats=repeats)
        peaks[name] = np.asarray(out)
        records.append({**common, "kind": "sweep", "layout": name, "variants": variants,
                        "compile_s": timing.compile_s, "run_s": timing.run_s,
                        "us_per_variant": timing.run_s / variants * 1e6,
                        "peak_torque_max": float(np.max(out)), "peak_torque_min": float(np.min(out))})
    first = next(iter(peaks.values()))
    for r, p in zip(records, peaks.values()):
        r["max_diff_from_vmap"] = float(np.max(np.abs(p - first)))
    return records


def run(out: Path, quick: bool = False) -> list[dict]:
    common = {"machine": platform.machine(), "jax": jax.__version__, "device": jax.devices()[0].platform}
    repeats = 1 if quick else 3
    records = (work_precision(QUICK_STEPS if quick else STEPS, repeats, common) + routes(repeats, common)
               + sweep(5 if quick else 10, repeats, common))
    out.mkdir(parents=True, exist_ok=True)
    write_jsonl(out / f"{NAME}.jsonl", records)
    from mbjax_harness.plot.bench import wrist_bench_figure
    wrist_bench_figure(records).savefig(out / f"{NAME}.png", dpi=120)
    for r in records:
        if r["kind"] == "work-precision":
            print(f"rk4 dt={r['dt']:<6g} {r['run_s'] * 1e3:8.2f} ms (compile {r['compile_s']:4.1f} s) "
                  f"error {r['error']:.3g} rad  {r['status']}")
        elif r["kind"] == "route":
            print(f"{r['route']:32s} {r['run_s'] * 1e6:8.1f} us/call, {r['batch_us_per_state']:6.2f} us/state "
                  f"in a batch of {r['batch']} (compile {r['compile_s']:4.1f} s)")
        else:
            print(f"sweep {r['layout']:22s} {r['variants']} variants {r['run_s']:.3f} s "
                  f"({r['us_per_variant']:.0f} us/variant, compile {r['compile_s']:.1f} s)")
    return records
