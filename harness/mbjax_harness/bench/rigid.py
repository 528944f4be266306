"""`mbjax bench rigid`: forward dynamics of rigid chains, mbjax against Pinocchio and MuJoCo.

One run measures, for regular n-link revolute chains (`mbjax.model.chain(n)`, float64, CPU):

1. One state per call: `jit(forward_dynamics)` with method "recursive" (Anderson 1993's O(n)
   recursion) and "dense" (Jerkovsky 1978's transformation operator + Cholesky, O(n^3)), the model
   passed as an argument; run time, compile time as the first call minus a typical call and,
   for the targets, as the time to lower and compile ahead of time (`lower_compile_time`).
   Extra sizes between 2 and 70 resolve the crossover where the recursion overtakes the dense
   form (the `CROSSOVER_NV` that method="auto" uses) and give the compile time at n = 10.
2. Batches: `jit(vmap(forward_dynamics))` over B states (B = 64 and 1024 at the extra sizes
   of 1. too, for the batched crossover); dense only where its (n, n, 6, 6)
   operator blocks fit in memory (B n^2 <= DENSE_MAX_BN2; skipped configurations are recorded
   with the reason).
3. Peers on the same chain (`mbjax.model.to_urdf`, identical q ordering): Pinocchio's
   `pin.aba` and MuJoCo's `mj_forward` (the whole pipeline: CRB mass matrix, its factorization,
   bias forces), each called once per state from a Python loop. The same loop with the call
   replaced by a no-op (Pinocchio) or with only the state copies (MuJoCo) gives the loop overhead,
   and the difference an estimate of the time in C/C++ (it still includes the binding's argument
   conversion, about 1 us). Pinocchio is skipped where `createData` would not fit in memory (its
   Data allocates O(nv^3): 0.07 GB at nv = 100, 0.5 GB at 200).
4. Inside a loop: the time per evaluation when many run in one jitted `fori_loop` (`looped_fn`),
   every size of 1., where the per-call overhead of 1. is gone; the crossover there is the one a
   simulation or an optimisation with method="auto" meets, and sets `CROSSOVER_NV`.
5. The gradient of a rollout: loss = |q(T)|^2 after 1000 RK4 steps of the 7-link chain,
   `jax.grad` with respect to (q0, v0) against the forward rollout.

Every forward-dynamics record carries the largest difference of its accelerations from
Pinocchio's (MuJoCo's where Pinocchio is skipped), relative to the largest acceleration.
JSON lines + PNG; the last record (kind "summary") holds the crossovers (per call, in a loop, at
every batch size, and the one for method="auto"), the fitted slope of log t against log n (looped,
where the overhead does not hide it) and the targets met or missed.
"""

import os
import platform
import time
from functools import partial
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from mbjax_harness import peers
from mbjax_harness.common import STRATEGY, loop_length, looped_fn, states
from mbjax_harness.timing import timed, write_jsonl
from mbjax.integrate import RK4, simulate
from mbjax.model import chain, to_urdf
from mbjax.rigid import TreeSystem, forward_dynamics

NAME = "rigid"
# the peers compared with where installed, left out of the records where not: the
# command's closing line names those missing (`mbjax_harness.cli._declared`)
PEERS = ("pinocchio", "mujoco")
METHODS = ("recursive", "dense")
NS = (1, 7, 30, 100, 300, 1000)
QUICK_NS = (1, 7, 30, 100)
BATCHES = (1, 64, 1024, 4096)
QUICK_BATCHES = (1, 64)
# Extra single-state sizes: the recursive/dense crossover and the compile time at n = 10.
CROSSOVER_NS = (2, 3, 4, 5, 6, 8, 10, 12, 15, 20, 25, 40, 50, 70)
QUICK_CROSSOVER_NS = (10,)
# The dense form keeps (n, n, 6, 6) blocks (A, its rate, ...): about 0.9 kB n^2 of temporaries
# per state (XLA's memory analysis: 78 MB at n = 300, 0.86 GB at n = 1000); batches stay < 2 GB.
DENSE_MAX_BN2 = 2_200_000
# Pinocchio's Data allocates O(nv^3) (measured 70 nv^3 bytes): 1.9 GB at nv = 300.
PINOCCHIO_MAX_NV = 330
PEER_STATES = 64            # states per Python loop for the peers
GRAD_N, GRAD_DT, GRAD_STEPS = 7, 1e-3, 1000
# The dense form in a loop stops at n = 300 (one evaluation at n = 1000 takes seconds).
LOOPED_DENSE_MAX_N = 300
# Batch sizes also measured at the crossover sizes, so the batched crossover is resolved.
CROSSOVER_BATCHES = (64, 1024)
# method="auto" tolerates the recursion being up to this factor slower in a loop (see summarize).
AUTO_TOLERANCE = 1.5


def single_fn(method: str):
    """One state per call, the model an argument (its parameters are leaves)."""
    return jax.jit(partial(forward_dynamics, method=STRATEGY[method]))


def lower_compile_time(method: str, *args) -> float:
    """Seconds to trace, lower and compile `single_fn(method)` ahead of time (a fresh jit, so
    nothing is cached): the compile time alone, without the first call's other costs."""
    start = time.perf_counter()
    single_fn(method).lower(*args).compile()
    return time.perf_counter() - start


def batched_fn(method: str):
    return jax.jit(jax.vmap(partial(forward_dynamics, method=STRATEGY[method]), in_axes=(None, 0, 0, 0)))


def pinocchio_available(n: int) -> bool:
    return peers.available("pinocchio") and n <= PINOCCHIO_MAX_NV


def _noop(*args):
    return None


def pinocchio_loop(urdf: str, Q, V, T, repeats: int, budget_s: float) -> dict:
    """pin.aba once per state from Python: per-state time, loop overhead and their difference,
    and the accelerations of the states (for the cross-checks)."""
    import pinocchio as pin

    model = pin.buildModelFromXML(urdf)
    data = model.createData()

    def loop(fn):
        return [fn(model, data, q, v, t) for q, v, t in zip(Q, V, T, strict=True)]

    acc, timing = timed(partial(loop, pin.aba), repeats=repeats, budget_s=budget_s)
    _, overhead = timed(partial(loop, _noop), repeats=repeats, budget_s=budget_s)
    per_state, loop_s = timing.run_s / len(Q), overhead.run_s / len(Q)
    return {"per_state_s": per_state, "loop_overhead_s": loop_s,
            "cpp_estimate_s": per_state - loop_s, "runs": timing.runs, "acc": np.array(acc)}


def mujoco_loop(urdf: str, Q, V, T, repeats: int, budget_s: float) -> dict:
    """mj_forward once per state from Python (state copied into MjData first): per-state time,
    the time of the copies alone, their difference, and the accelerations."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(urdf)
    data = mujoco.MjData(model)

    def loop(forward: bool):
        out = []
        for q, v, t in zip(Q, V, T, strict=True):
            data.qpos[:] = q
            data.qvel[:] = v
            data.qfrc_applied[:] = t
            if forward:
                mujoco.mj_forward(model, data)
                out.append(data.qacc.copy())
        return out

    acc, timing = timed(partial(loop, True), repeats=repeats, budget_s=budget_s)
    _, overhead = timed(partial(loop, False), repeats=repeats, budget_s=budget_s)
    per_state, loop_s = timing.run_s / len(Q), overhead.run_s / len(Q)
    return {"per_state_s": per_state, "loop_overhead_s": loop_s,
            "cpp_estimate_s": per_state - loop_s, "runs": timing.runs, "acc": np.array(acc)}


def relative_difference(a, ref) -> float:
    """max |a - ref| / max |ref|."""
    a, ref = np.asarray(a), np.asarray(ref)
    return float(np.max(np.abs(a - ref)) / max(np.max(np.abs(ref)), 1e-300))



def _looped_records(ns, repeats: int, budget_s: float, common: dict) -> list[dict]:
    """Time per evaluation inside a jitted loop (`looped_fn`), both methods, every size."""
    records = []
    for n in ns:
        model = chain(n)
        q, v, tau = (jnp.asarray(x[0]) for x in states(n, 1))
        for method in METHODS:
            if method == "dense" and n > LOOPED_DENSE_MAX_N:
                continue
            k = loop_length(n)
            _, timing = timed(looped_fn(method, k), model, q, v, tau, repeats=repeats,
                              budget_s=budget_s)
            records.append({**common, "kind": "looped", "engine": "mbjax", "method": method,
                            "n": n, "evaluations": k, "compile_s": timing.compile_s,
                            "run_s": timing.run_s, "per_eval_s": timing.run_s / k,
                            "runs": timing.runs})
    return records


def _gradient_records(methods, repeats: int, common: dict) -> list[dict]:
    """jax.grad of |q(T)|^2 after GRAD_STEPS RK4 steps against the forward rollout."""
    model = chain(GRAD_N)
    q0 = jnp.asarray(np.linspace(0.3, 1.0, GRAD_N))
    v0 = jnp.zeros(GRAD_N)
    T = GRAD_DT * GRAD_STEPS
    records = []
    for method in methods:
        system = TreeSystem(model, method=STRATEGY[method])

        def loss(q0, v0, system=system):
            sol = simulate(system, RK4(), q0, v0, dt=GRAD_DT, t1=T, saveat=[T])
            return jnp.sum(sol.qs[-1] ** 2)

        _, fwd = timed(jax.jit(loss), q0, v0, repeats=repeats, budget_s=5.0)
        grads, grad = timed(jax.jit(jax.grad(loss, argnums=(0, 1))), q0, v0, repeats=repeats,
                            budget_s=10.0)
        finite = bool(all(np.all(np.isfinite(g)) for g in grads))
        records.append({**common, "kind": "gradient", "engine": "mbjax", "method": method,
                        "n": GRAD_N, "integrator": "rk4", "dt": GRAD_DT, "steps": GRAD_STEPS,
                        "loss": "sum(q(T)^2), grad wrt (q0, v0)",
                        "forward_compile_s": fwd.compile_s, "forward_s": fwd.run_s,
                        "grad_compile_s": grad.compile_s, "grad_s": grad.run_s,
                        "grad_over_forward": grad.run_s / fwd.run_s,
                        "per_step_forward_s": fwd.run_s / GRAD_STEPS, "finite": finite})
    return records


def fit_slope(ns, ts) -> float | None:
    """Slope of log t against log n (None with fewer than two points)."""
    if len(ns) < 2:
        return None
    return float(np.polyfit(np.log(ns), np.log(ts), 1)[0])


def crossover(rows: list[dict], key: str = "run_s", group: str | None = None,
              tolerance: float = 1.0) -> int | None:
    """The smallest measured n from which on the recursion takes less than `tolerance` times the
    dense form's time at every measured size (and, with `group`, for every value of that field,
    e.g. every batch size measured with both methods); None if it never does."""
    by_n = {}
    for r in rows:
        by_n.setdefault((r["n"], r.get(group)), {})[r["method"]] = r[key]
    wins = {}
    for (n, _), t in by_n.items():
        if set(t) >= set(METHODS):
            wins[n] = wins.get(n, True) and t["recursive"] < tolerance * t["dense"]
    ns = sorted(wins)
    faster = [wins[n] for n in ns]
    for i, n in enumerate(ns):
        if all(faster[i:]):
            return n
    return None


def summarize(records: list[dict], ns, common: dict) -> dict:
    """Crossovers, scaling fits and the speed targets. Scaling is judged on the looped times
    (per evaluation, no dispatch overhead); compile time on the single-call jit."""
    single = [r for r in records if r["kind"] == "forward" and r["engine"] == "mbjax"
              and r["batch"] == 0 and "run_s" in r]
    looped = [r for r in records if r["kind"] == "looped"]
    run = {(r["method"], r["n"]): r["run_s"] for r in single}
    per_eval = {(r["method"], r["n"]): r["per_eval_s"] for r in looped}
    comp = {(r["method"], r["n"]): r.get("lower_compile_s", r["compile_s"]) for r in single}
    rec_ns = [n for n in ns if ("recursive", n) in per_eval]
    n_max = max(n for _, n in comp)
    # t = a + b n, fitted in relative terms (weights 1/t) over the sizes from 7 on
    fit_ns = np.array([n for n in rec_ns if n >= 7], dtype=float)
    fit_t = np.array([per_eval[("recursive", n)] for n in fit_ns])
    b, a = np.polyfit(fit_ns, fit_t, 1, w=1 / fit_t) if len(fit_ns) >= 2 else (None, None)
    big = [n for n in rec_ns if n >= 100]
    slope_big = fit_slope(big, [per_eval[("recursive", n)] for n in big])
    # n = 10's compile time, as the median over its neighbours 5 <= n <= 20 (one first call per
    # size is a single, noisy sample)
    base = {m: float(np.median([t for (mm, n), t in comp.items() if mm == m and 5 <= n <= 20]))
            for m in METHODS if any(mm == m and 5 <= n <= 20 for mm, n in comp)}
    compile_ratio = {m: comp[(m, n_max)] / base[m] for m in base if (m, n_max) in comp}

    def speedup(table):
        return (table[("dense", 300)] / table[("recursive", 300)]
                if ("dense", 300) in table and ("recursive", 300) in table else None)

    grads = {r["method"]: r["grad_over_forward"] for r in records if r["kind"] == "gradient"}
    batched = [r for r in records if r["kind"] == "forward" and r["engine"] == "mbjax"
               and r["batch"] > 1 and "run_s" in r]
    crossover_batched = crossover(batched, group="batch")
    # method="auto" serves simulations and optimisations (loops) and vmapped sweeps (batches):
    # the recursion from the first size from which it is never more than AUTO_TOLERANCE times
    # slower in a loop (where small sizes are within noise of each other) and faster at every
    # batch size (where the dense form vmaps badly).
    loose = crossover(looped, "per_eval_s", tolerance=AUTO_TOLERANCE)
    summary = {
        **common, "kind": "summary",
        "crossover_nv": crossover(single),
        "crossover_nv_looped": crossover(looped, "per_eval_s"),
        "crossover_nv_batched": crossover_batched,
        "crossover_nv_auto": (None if loose is None or crossover_batched is None
                              else max(loose, crossover_batched)),
        "recursive_slope": fit_slope([n for n in rec_ns if n >= 30],
                                     [per_eval[("recursive", n)] for n in rec_ns if n >= 30]),
        "recursive_slope_n_ge_100": slope_big,
        "recursive_fixed_s": None if a is None else float(a),
        "recursive_per_body_s": None if b is None else float(b),
        "compile_n_max": n_max,
        "compile_s_n10": base,
        "compile_ratio_nmax_over_n10": compile_ratio,
        "compile_s_nmax": {m: comp.get((m, n_max)) for m in METHODS},
        "dense_over_recursive_n300": speedup(run),
        "dense_over_recursive_n300_looped": speedup(per_eval),
        "grad_over_forward": grads,
    }
    speedup_300 = summary["dense_over_recursive_n300_looped"]
    summary["targets"] = {
        "compile_n1000_within_1.5x_of_n10": (compile_ratio.get("recursive", 99) <= 1.5
                                             if n_max == 1000 else None),
        "compile_n1000_under_3s": (comp[("recursive", 1000)] < 3.0
                                   if ("recursive", 1000) in comp else None),
        "recursive_linear": None if slope_big is None else slope_big <= 1.15,
        "recursive_5x_faster_than_dense_n300": None if speedup_300 is None else speedup_300 >= 5,
    }
    return summary


def run(out: Path, quick: bool = False) -> list[dict]:
    from mbjax_harness.progress import progress

    ns = QUICK_NS if quick else NS
    batches = QUICK_BATCHES if quick else BATCHES
    single_ns = sorted(set(ns) | set(QUICK_CROSSOVER_NS if quick else CROSSOVER_NS))
    repeats = 5 if quick else 30
    budget = 0.5 if quick else 3.0
    common = {"suite": NAME, "scene": "chain(n): regular revolute chain, float64",
              "machine": platform.machine(), "cpus": os.cpu_count(), "jax": jax.__version__,
              "xla_flags": os.environ.get("XLA_FLAGS", ""), "quick": quick}
    records: list[dict] = []
    fns = {m: single_fn(m) for m in METHODS}
    batched = {m: batched_fn(m) for m in METHODS}
    # A throwaway compile (its own jit, so no size is cached), so that the first size does not
    # pay for JAX's own start-up.
    jax.block_until_ready(single_fn("recursive")(chain(2), *(jnp.zeros(2),) * 3))

    for n in progress(single_ns, len(single_ns), "bench rigid: one state per call"):
        model = chain(n)
        urdf = to_urdf(model)
        Q, V, T = states(n, PEER_STATES if n in ns else 1)
        ref, ref_engine = None, None
        if n in ns and pinocchio_available(n):
            pin_res = pinocchio_loop(urdf, Q, V, T, repeats, budget)
            ref, ref_engine = pin_res.pop("acc")[0], "pinocchio"
            records.append({**common, "kind": "forward", "engine": "pinocchio", "method": "aba",
                            "n": n, "batch": len(Q), "mode": "python loop", **pin_res})
        elif n in ns and peers.available("pinocchio"):
            records.append({**common, "kind": "forward", "engine": "pinocchio", "method": "aba",
                            "n": n, "skipped": f"pinocchio Data allocates O(nv^3) memory "
                                               f"(about {70 * n**3 / 1e9:.0f} GB at nv = {n})"})
        if n in ns and peers.available("mujoco"):
            mj = mujoco_loop(urdf, Q, V, T, repeats, budget)
            acc = mj.pop("acc")
            if ref is None:
                ref, ref_engine = acc[0], "mujoco"
            else:
                mj |= {"rel_diff": relative_difference(acc[0], ref), "ref_engine": ref_engine}
            records.append({**common, "kind": "forward", "engine": "mujoco", "method": "mj_forward",
                            "n": n, "batch": len(Q), "mode": "python loop", **mj})
        for method in METHODS:
            q, v, tau = (jnp.asarray(x[0]) for x in (Q, V, T))
            acc, timing = timed(fns[method], model, q, v, tau, repeats=repeats, budget_s=budget)
            record = {**common, "kind": "forward", "engine": "mbjax", "method": method, "n": n,
                      "batch": 0, "mode": "single", "compile_s": timing.compile_s,
                      "lower_compile_s": lower_compile_time(method, model, q, v, tau),
                      "run_s": timing.run_s, "per_state_s": timing.run_s, "runs": timing.runs}
            if ref is not None:
                record |= {"rel_diff": relative_difference(acc, ref), "ref_engine": ref_engine}
            records.append(record)

    configs = [(n, b, m) for n in ns for b in batches for m in METHODS]
    if not quick:
        configs += [(n, b, m) for n in CROSSOVER_NS for b in CROSSOVER_BATCHES for m in METHODS]
    for n, batch, method in progress(configs, len(configs), "bench rigid: batches"):
        base = {**common, "kind": "forward", "engine": "mbjax", "method": method, "n": n,
                "batch": batch, "mode": "batched"}
        if method == "dense" and batch * n * n > DENSE_MAX_BN2:
            records.append({**base, "skipped": f"B n^2 = {batch * n * n:.3g} > {DENSE_MAX_BN2:.3g}: "
                                               "the dense operator blocks would need "
                                               f"~{0.9 * batch * n * n / 1e6:.0f} GB"})
            continue
        model = chain(n)
        q, v, tau = (jnp.asarray(x) for x in states(n, batch))
        _, timing = timed(batched[method], model, q, v, tau, repeats=max(3, repeats // 3),
                          budget_s=4 * budget)
        records.append({**base, "compile_s": timing.compile_s, "run_s": timing.run_s,
                        "per_state_s": timing.run_s / batch, "runs": timing.runs})

    start = time.perf_counter()
    records += _looped_records(single_ns, repeats=3 if quick else 10, budget_s=budget,
                               common=common)
    records += _gradient_records(("recursive",) if quick else METHODS, repeats=3 if quick else 5,
                                 common=common)
    print(f"loops and the gradient of a rollout: {time.perf_counter() - start:.1f} s")
    records.append(summarize(records, single_ns, common))

    out.mkdir(parents=True, exist_ok=True)
    write_jsonl(out / f"{NAME}.jsonl", records)
    from mbjax_harness.plot.trees import rigid_bench_figure
    rigid_bench_figure(records).savefig(out / f"{NAME}.png", dpi=120)
    print(report(records))
    return records


def _us(seconds) -> str:
    return "-" if seconds is None else f"{seconds * 1e6:.4g}"


def report(records: list[dict]) -> str:
    """The tables printed at the end of a run (and pasted into benchmarks/README.md)."""
    fwd = [r for r in records if r["kind"] == "forward"]

    def get(engine, method, n, batch=0, key="per_state_s"):
        for r in fwd:
            if (r["engine"], r["method"], r["n"]) == (engine, method, n) and (
                    engine != "mbjax" or r["batch"] == batch):
                return r.get(key)
        return None

    ns = sorted({r["n"] for r in fwd if r["engine"] != "mbjax"}) or sorted({r["n"] for r in fwd})
    header = ("| n | recursive | dense | dense/recursive | pin.aba | pin C++ est. | mj_forward | "
              "mj C est. | compile recursive [s] | compile dense [s] |")
    lines = ["one state per call [us]: mbjax jit(forward_dynamics); peers from a Python loop "
             + "(C estimate = loop minus its overhead)", header, "|---" * 10 + "|"]
    for n in ns:
        rec, den = get("mbjax", "recursive", n), get("mbjax", "dense", n)
        ratio = f"{den / rec:.3g}" if rec and den else "-"
        cr, cd = (get("mbjax", m, n, key="lower_compile_s") or get("mbjax", m, n, key="compile_s")
                  for m in METHODS)
        lines.append(f"| {n} | {_us(rec)} | {_us(den)} | {ratio} | {_us(get('pinocchio', 'aba', n))} | "
                     f"{_us(get('pinocchio', 'aba', n, key='cpp_estimate_s'))} | "
                     f"{_us(get('mujoco', 'mj_forward', n))} | "
                     f"{_us(get('mujoco', 'mj_forward', n, key='cpp_estimate_s'))} | "
                     f"{'-' if cr is None else f'{cr:.2f}'} | {'-' if cd is None else f'{cd:.2f}'} |")
    batches = sorted({r["batch"] for r in fwd if r["engine"] == "mbjax" and r["batch"]})
    lines += ["", "batched jit(vmap(forward_dynamics)), time per state [us] (recursive / dense)",
              "| n | " + " | ".join(f"B = {b}" for b in batches) + " |", "|---" * (len(batches) + 1) + "|"]
    for n in sorted({r["n"] for r in fwd if r["engine"] == "mbjax" and r["batch"]}):
        cells = [f"{_us(get('mbjax', 'recursive', n, b))} / {_us(get('mbjax', 'dense', n, b))}"
                 for b in batches]
        lines.append(f"| {n} | " + " | ".join(cells) + " |")
    looped = [r for r in records if r["kind"] == "looped"]
    if looped:
        per = {(r["method"], r["n"]): r["per_eval_s"] for r in looped}
        lines += ["", "one evaluation inside a jitted loop [us] (no per-call dispatch)",
                  "| n | recursive | dense | dense/recursive |", "|---|---|---|---|"]
        for n in sorted({r["n"] for r in looped}):
            rec, den = per.get(("recursive", n)), per.get(("dense", n))
            ratio = f"{den / rec:.3g}" if rec and den else "-"
            lines.append(f"| {n} | {_us(rec)} | {_us(den)} | {ratio} |")
    lines.append("")
    for r in records:
        if r["kind"] == "gradient":
            lines.append(f"grad of a {r['steps']}-step RK4 rollout, {r['n']}-link chain, {r['method']}: "
                         f"forward {r['forward_s'] * 1e3:.1f} ms, grad {r['grad_s'] * 1e3:.1f} ms, "
                         f"ratio {r['grad_over_forward']:.2f} (compile {r['forward_compile_s']:.2f} s / "
                         f"{r['grad_compile_s']:.2f} s)")
        if r["kind"] == "summary":
            lines.append(f"crossover (recursive faster from n =): {r['crossover_nv']} one state per call, "
                         f"{r['crossover_nv_looped']} inside a loop, {r['crossover_nv_batched']} at every batch "
                         f"size; for method='auto': {r['crossover_nv_auto']}; recursive slope (looped) "
                         f"(n >= 30) {r['recursive_slope']}, (n >= 100) {r['recursive_slope_n_ge_100']}; "
                         f"t = {_us(r['recursive_fixed_s'])} us + {_us(r['recursive_per_body_s'])} us n")
            lines.append(f"compile n_max/n10: {r['compile_ratio_nmax_over_n10']}; dense/recursive at "
                         f"n = 300: {r['dense_over_recursive_n300']} per call, "
                         f"{r['dense_over_recursive_n300_looped']} looped")
            lines.append(f"targets: {r['targets']}")
    return "\n".join(lines)
