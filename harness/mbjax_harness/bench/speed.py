"""`mbjax bench speed`: the cost users feel, on chains and real robots, against four peers.
One call, one trajectory, its gradient, a vmapped batch, the dynamics' derivatives and compile
time, against Pinocchio, jaxsim, adam and frax in one run.

Robots: the regular 7- and 30-link chains (`mbjax.model.chain`, written with `to_urdf`), and from
example-robot-data the Panda arm (7 dof, fixed base) and the Unitree G1 humanoid (floating base,
mbjax and Pinocchio only). Every library reads the same URDF; float64, CPU. Per robot and library:

- call: one jitted forward-dynamics call from Python (model passed as an argument, as a user
  writes `jax.jit(mbjax.forward_dynamics)(model, q, v, tau)`; call_closed_s with the model
  closed over), the median of many; its fixed cost is call - eval. Every JAX library runs with
  the CPU settings `import mbjax` makes (the `mbjax` module's docstring; mbjax/_src/runtime.py:
  synchronous dispatch, XLA's concurrency scheduler off), recorded in each line (xla_flag: the
  process's XLA_FLAGS; synchronous_dispatch: JAX's CPU async dispatch off);
- eval: one forward-dynamics evaluation inside a jitted rollout, a `lax.scan` of STEPS
  semi-implicit Euler steps (the same loop for every JAX library; mbjax also through
  `simulate(TreeSystem(model), RK4())`, per evaluation = run / (4 STEPS));
- vmap: per state of `jit(vmap(forward_dynamics))` at B = BATCH;
- grad: `jax.grad` of sum q(T)^2 over the rollout with respect to q0, divided by the rollout, and
  the temporary memory XLA allocates for it (grad_temp_bytes: what the reverse pass keeps); for
  the 7-link chain also that memory through `simulate`, plain and checkpointed, against the
  horizon (`grad_memory`);
- derivatives: `jax.jit(jax.jacfwd)` of the accelerations in (q, v, tau), q in its tangent space
  (q (+) e, e = 0), one call from Python (jac_s) and per state vmapped over JAC_BATCH states
  (jac_vmap_s, a horizon's knots as a trajectory optimizer linearizes them); Pinocchio:
  `computeABADerivatives`, the C++ time per call (jac_s, a loop minus an empty loop) and from
  Python (jac_python_s);
- compile: lowering and compiling the rollout.

Pinocchio: `aba` per call (the C++ estimate: Python loop time minus an empty loop's) and
`abaInParallel` per state at B = BATCH on one thread per core. `kernels` reads the compiled HLO of
`jit(forward_dynamics)`: the kernels XLA launches per call outside the tree passes and per body
step inside them. The summary record holds the speed targets met or missed.
"""

import os
import re
import time
from functools import partial
from pathlib import Path

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from mbjax_harness.bench.rigid import pinocchio_loop, relative_difference
from mbjax_harness.bench.throughput import pinocchio_parallel
from mbjax.integrate import RK4, simulate
from mbjax.model import chain, load_urdf, to_urdf
from mbjax.rigid import TreeSystem, forward_dynamics
from mbjax_harness.timing import timed, write_jsonl

NAME = "speed"
# the peers compared with where installed, left out of the records where not: the
# command's closing line names those missing (`mbjax_harness.cli._declared`)
PEERS = ("pinocchio",)
STEPS, QUICK_STEPS = 1000, 100
BATCH, QUICK_BATCH = 4096, 256
MEMORY_STEPS = (256, 1024, 4096)            # horizons of `grad_memory` (powers of 2: sqrt exact)
DT = 1e-3
JAC_BATCH = 64                  # states of the vmapped derivatives (a horizon's knots)
# targets
TARGET_EVAL_RATIO, TARGET_CALL_S, TARGET_GRAD_RATIO = 2.0, 10e-6, 3.0
TARGET_JAC_RATIO = 2.0          # issue 42: derivatives at Pinocchio's cost
# instructions that launch no kernel of their own
_FREE = {"parameter", "get-tuple-element", "tuple", "constant", "bitcast"}


def robots(quick: bool) -> list[tuple[str, str, bool]]:
    """(name, URDF text, floating base) of the robots measured."""
    out = [("chain7", to_urdf(chain(7)), False)]
    if quick:
        return out
    out.append(("chain30", to_urdf(chain(30)), False))
    try:
        from mbjax_harness.common import corpus_paths
        paths = {p.stem: p for p in corpus_paths()}
        out.append(("panda", paths["panda"].read_text(), False))
        out.append(("g1", paths["g1_29dof_rev_1_0"].read_text(), True))
    except Exception:             # example-robot-data missing: chains only
        pass
    return out


def kernel_counts(hlo: str) -> dict:
    """Kernels in a compiled HLO module: per call in the entry computation, and in every while
    loop's body that runs kernel by kernel (the tree passes: one iteration per body or depth
    level). A loop XLA compiled as one kernel (a call marked xla_cpu_small_call, see
    mbjax/_src/runtime.py) counts as one kernel where it is called; `one_kernel_loops` counts them."""
    blocks = dict(re.findall(r"\n(?:ENTRY )?%?([\w.\-]+) [^\n]*\{\n(.*?)\n\}", "\n" + hlo, re.S))
    entry = re.search(r"ENTRY %?([\w.\-]+)", hlo).group(1)

    def kernels(name):
        ops = re.findall(r"= [^=]*? ([a-z][a-z0-9\-]*)\(", blocks.get(name, ""))
        return sum(op not in _FREE for op in ops)

    # computations inside a one-kernel loop, and everything they call
    inside = set(re.findall(r"to_apply=%?([\w.\-]+), frontend_attributes=\{xla_cpu_small_call", hlo))
    hoisted, todo = len(inside), list(inside)
    while todo:
        for called in re.findall(r"(?:to_apply|body|condition|calls)=%?([\w.\-]+)",
                                 blocks.get(todo.pop(), "")):
            if called not in inside:
                inside.add(called)
                todo.append(called)
    bodies = [b for b in re.findall(r"body=%?([\w.\-]+)", hlo) if b not in inside]
    return {"entry": kernels(entry), "per_step": [kernels(b) for b in bodies],
            "one_kernel_loops": hoisted}


def _rollout(fd, steps: int, retract=None):
    """q(T) of `steps` semi-implicit Euler steps of v_dot = fd(q, v); q moves by retract(q, dt v)
    (q + dt v by default; a model's `retract` for a free joint's quaternion)."""
    retract = retract or (lambda q, dq: q + dq)

    def run(q0, v0):
        def step(state, _):
            q, v = state
            v = v + DT * fd(q, v)
            return (retract(q, DT * v), v), None
        return jax.lax.scan(step, (q0, v0), None, length=steps)[0][0]
    return run


def _measure_jax(fd, q, v, tau, Q, V, TAU, steps: int, repeats: int, budget: float,
                 retract=None) -> dict:
    """call, eval, vmap, grad, the derivatives and compile of one JAX library's fd(q, v, tau)."""
    record = {}
    _, t = timed(jax.jit(fd), q, v, tau, repeats=repeats * 20, budget_s=budget)
    record["call_s"] = t.run_s
    # d(v_dot)/d(q, v, tau) by jax.jacfwd, q moving in its tangent space (retract)
    retract = retract or (lambda q, dq: q + dq)

    def jacobians(q, v, tau):       # one (nv, 3 nv) array: a tuple of three outputs costs a
        # jitted call about 25 us more per output on this CPU (benchmarks/README.md)
        return jnp.concatenate(jax.jacfwd(lambda e, v, tau: fd(retract(q, e), v, tau),
                                          argnums=(0, 1, 2))(jnp.zeros_like(v), v, tau), 1)
    _, t = timed(jax.jit(jacobians), q, v, tau, repeats=repeats * 20, budget_s=budget)
    record["jac_s"] = t.run_s
    _, t = timed(jax.jit(jax.vmap(jacobians)), Q[:JAC_BATCH], V[:JAC_BATCH], TAU[:JAC_BATCH],
                 repeats=repeats, budget_s=budget)
    record["jac_vmap_s"] = t.run_s / JAC_BATCH
    batch = jax.jit(jax.vmap(fd))
    acc, t = timed(batch, Q, V, TAU, repeats=repeats, budget_s=budget)
    record["vmap_s"] = t.run_s / len(Q)
    record["acc"] = np.asarray(acc[:8])
    # the rollouts start at rest under zero torque (the robot falls under gravity), so that
    # every chain stays bounded over the horizon and the gradient is finite
    v, tau = jnp.zeros_like(v), jnp.zeros_like(tau)
    roll = jax.jit(_rollout(lambda q, v: fd(q, v, tau), steps, retract))
    start = time.perf_counter()
    roll.lower(q, v).compile()
    record["compile_s"] = time.perf_counter() - start
    _, t = timed(roll, q, v, repeats=repeats, budget_s=budget)
    record["eval_s"] = t.run_s / steps
    grad = jax.jit(jax.grad(lambda q0: jnp.sum(
        _rollout(lambda q, v: fd(q, v, tau), steps, retract)(q0, v) ** 2)))
    g, tg = timed(grad, q, repeats=repeats, budget_s=budget)
    record["grad_ratio"] = tg.run_s / t.run_s
    record["grad_temp_bytes"] = int(grad.lower(q).compile().memory_analysis().temp_size_in_bytes)
    record["grad_finite"] = bool(np.all(np.isfinite(g)))
    return record


def grad_memory(system, q, horizons=MEMORY_STEPS) -> dict:
    """XLA's temporary bytes for `jax.grad` of sum q(T)^2 through `simulate(system, RK4())`
    from rest, plain and with checkpoint=True, at each horizon T (compiled, not run), and the
    slope of log(bytes) against log(T): 1 for memory O(T), 0.5 for O(sqrt T)."""
    from mbjax_harness.bench.throughput import temp_bytes

    out = {}
    for checkpoint in (False, True):
        memory = []
        for steps in horizons:
            def loss(q0, steps=steps, checkpoint=checkpoint):
                return jnp.sum(simulate(system, RK4(), q0, jnp.zeros_like(q0), dt=DT,
                                        t1=steps * DT, saveat=np.array([steps * DT]),
                                        checkpoint=checkpoint).qs[-1] ** 2)
            memory.append(temp_bytes(jax.grad(loss), q))
        slope = float(np.polyfit(np.log(horizons), np.log(memory), 1)[0])
        out["checkpoint" if checkpoint else "plain"] = {"steps": list(horizons), "bytes": memory,
                                                        "slope": slope}
    return out


def _pinocchio(urdf: str, floating: bool, Q, V, TAU, repeats: int, budget: float) -> dict:
    import pinocchio as pin
    record = {}
    if not floating:
        loop = pinocchio_loop(urdf, Q[:64], V[:64], TAU[:64], repeats=repeats, budget_s=budget)
        record["call_s"] = loop["cpp_estimate_s"]
        record["acc"] = loop["acc"][:8]
        parallel = pinocchio_parallel(urdf, Q, V, TAU, repeats=repeats, budget_s=budget)
        record["vmap_s"] = parallel["per_state_s"]
        model = pin.buildModelFromXML(urdf)
        data = model.createData()
        qs, vs, taus = Q[:64], V[:64], TAU[:64]
    else:                         # random configurations on the free joint's manifold
        model = pin.buildModelFromXML(urdf, pin.JointModelFreeFlyer())
        data = model.createData()
        qs = [pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
              for _ in range(64)]
        vs = np.random.default_rng(0).standard_normal((64, model.nv))
        taus = np.zeros_like(vs)

    def loop(fn):
        return [fn(model, data, q, v, tau) for q, v, tau in zip(qs, vs, taus, strict=True)]
    _, t0 = timed(partial(loop, lambda *a: None), repeats=repeats, budget_s=budget)
    if floating:
        _, t = timed(partial(loop, pin.aba), repeats=repeats, budget_s=budget)
        record["call_s"] = (t.run_s - t0.run_s) / len(qs)
    # computeABADerivatives: d(v_dot)/d(q, v, tau) in the tangent space, the C++ time
    _, t = timed(partial(loop, pin.computeABADerivatives), repeats=repeats, budget_s=budget)
    record["jac_s"] = (t.run_s - t0.run_s) / len(qs)
    record["jac_python_s"] = t.run_s / len(qs)
    return record


def _peer(name: str, urdf: str):
    """(fd(q, v, tau) of a JAX peer for a fixed-base URDF (text), None) or (None, why not)."""
    import tempfile

    from mbjax_harness.bench import jax_peers
    path = Path(tempfile.mkdtemp()) / "robot.urdf"
    path.write_text(urdf)
    build = {"jaxsim": jax_peers.jaxsim_forward_dynamics,
             "adam": jax_peers.adam_forward_dynamics,
             "frax": jax_peers.frax_forward_dynamics}[name]
    try:
        return build(str(path), floating=False), None
    except Exception as error:    # a missing peer, or one that cannot read this URDF
        return None, f"{type(error).__name__}: {error}"


def run(out: Path, quick: bool = False) -> list[dict]:
    jax.config.update("jax_enable_x64", True)
    steps, batch = (QUICK_STEPS, QUICK_BATCH) if quick else (STEPS, BATCH)
    repeats, budget = (3, 2.0) if quick else (10, 10.0)
    common = {"suite": NAME, "jax": jax.__version__, "steps": steps, "batch": batch,
              "xla_flag": os.environ.get("XLA_FLAGS") or None,
              "synchronous_dispatch": not jax.config.read("jax_cpu_enable_async_dispatch")}
    records = []
    for name, urdf, floating in robots(quick):
        model = load_urdf(urdf, floating_base=floating, min_mass=1e-4 if floating else 0.0)
        # the peers' forward dynamics ignore the URDF's joint damping (the Panda's 0.003-0.3 N m s),
        # mbjax's applies it: all run without it, so that every library computes the same motion
        model = eqx.tree_at(lambda m: m.damping, model, jnp.zeros_like(model.damping))
        rng = np.random.default_rng(0)
        Q = jnp.asarray(rng.uniform(-1, 1, (batch, model.nq)))
        if floating:              # unit quaternions on the free joints
            Q = jax.vmap(model.normalize)(Q)
        V = jnp.asarray(rng.standard_normal((batch, model.nv)))
        TAU = jnp.asarray(rng.standard_normal((batch, model.nv)))
        q, v, tau = Q[0], V[0], TAU[0]
        base = {**common, "robot": name, "nv": model.nv, "floating": floating}

        mb = _measure_jax(partial(forward_dynamics, model), q, v, tau, Q, V, TAU, steps,
                          repeats, budget, retract=model.retract)
        _, t = timed(jax.jit(forward_dynamics), model, q, v, tau, repeats=repeats * 20,
                     budget_s=budget)
        mb["call_closed_s"] = mb["call_s"]                       # the model closed over
        mb["call_s"] = t.run_s                                   # the model an argument
        system = TreeSystem(model)                                # zero torque
        sim = jax.jit(lambda q, v: simulate(system, RK4(), q, v, dt=DT, t1=steps * DT,
                                            saveat=None).qs[-1])
        _, t = timed(sim, q, jnp.zeros_like(v), repeats=repeats, budget_s=budget)
        mb["eval_simulate_rk4_s"] = t.run_s / (4 * steps)
        if name == "chain7":
            mb["grad_memory"] = grad_memory(system, q)
        hlo = jax.jit(forward_dynamics).lower(model, q, v, tau).compile().as_text()
        mb["kernels"] = kernel_counts(hlo)
        acc = mb.pop("acc")
        records.append({**base, "library": "mbjax", **mb})

        if not floating:
            for peer in ("jaxsim", "adam", "frax"):
                fd, why = _peer(peer, urdf)
                if fd is None:
                    records.append({**base, "library": peer, "skipped": why[:300]})
                    continue
                rec = _measure_jax(fd, q, v, tau, Q, V, TAU, steps, repeats, budget)
                rec["rel_diff_mbjax"] = relative_difference(rec.pop("acc"), acc)
                records.append({**base, "library": peer, **rec})
        try:
            pin = _pinocchio(urdf, floating, np.asarray(Q), np.asarray(V), np.asarray(TAU),
                             repeats, budget)
        except ImportError:
            continue
        if "acc" in pin:
            pin["rel_diff_mbjax"] = relative_difference(pin.pop("acc"), acc)
        records.append({**base, "library": "pinocchio", **pin})
        write_jsonl(out / f"{NAME}.jsonl", records)          # what is done so far
    records.append(summarize(records, common))
    write_jsonl(out / f"{NAME}.jsonl", records)
    plot(records, out / f"{NAME}.png")
    return records


def summarize(records: list[dict], common: dict) -> dict:
    """The speed targets, each met or missed with its measured ratio."""
    rows = {(r["robot"], r["library"]): r for r in records
            if "library" in r and "skipped" not in r}
    targets = []

    def target(what, value, limit, unit=""):
        if value is not None:
            targets.append({"target": what, "value": value, "limit": limit,
                            "met": bool(value <= limit), "unit": unit})

    for robot in ("chain7", "chain30", "panda", "g1"):
        mb, pin = rows.get((robot, "mbjax")), rows.get((robot, "pinocchio"))
        if mb and pin:
            target(f"{robot}: eval in a rollout / Pinocchio aba", mb["eval_s"] / pin["call_s"],
                   TARGET_EVAL_RATIO)
        if mb and robot == "chain7":
            # the fixed cost of a call: what it costs beyond its evaluation inside a rollout
            target("chain7: one jitted call's fixed cost, model an argument",
                   mb["call_s"] - mb["eval_s"], TARGET_CALL_S, "s")
            target("chain7: one jitted call's fixed cost, model closed over",
                   mb["call_closed_s"] - mb["eval_s"], TARGET_CALL_S, "s")
            target("chain7: grad / rollout", mb["grad_ratio"], TARGET_GRAD_RATIO)
            if "grad_memory" in mb:      # O(sqrt T): log-log slope 0.5
                target("chain7: grad memory ~ T^slope, simulate(checkpoint=True)",
                       mb["grad_memory"]["checkpoint"]["slope"], 0.6)
            if pin and "vmap_s" in pin:
                target("chain7: vmap per state / abaInParallel", mb["vmap_s"] / pin["vmap_s"], 1.0)
        if mb and pin and "jac_s" in pin:
            target(f"{robot}: jax.jacfwd(forward_dynamics) call / computeABADerivatives",
                   mb["jac_s"] / pin["jac_s"], TARGET_JAC_RATIO)
            target(f"{robot}: jacfwd per state, vmapped / computeABADerivatives",
                   mb["jac_vmap_s"] / pin["jac_s"], TARGET_JAC_RATIO)
        for peer in ("jaxsim", "adam", "frax"):
            other = rows.get((robot, peer))
            if mb and other:
                for key in ("call_s", "eval_s", "vmap_s", "compile_s", "jac_s"):
                    target(f"{robot}: mbjax {key[:-2]} / {peer}", mb[key] / other[key], 1.0)
                target(f"{robot}: mbjax grad ratio / {peer}'s", mb["grad_ratio"]
                       / other["grad_ratio"], 1.0)
    return {**common, "kind": "summary", "targets": targets}


def plot(records: list[dict], path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [r for r in records if "library" in r and "skipped" not in r]
    robots_ = list(dict.fromkeys(r["robot"] for r in rows))
    libraries = list(dict.fromkeys(r["library"] for r in rows))
    keys = (("call_s", "one jitted call"), ("eval_s", "one evaluation in a rollout"),
            ("vmap_s", f"per state, batch of {records[0]['batch']}"))
    fig, axes = plt.subplots(1, len(keys), figsize=(13, 3.8))
    width = 0.8 / max(len(libraries), 1)
    for ax, (key, title) in zip(axes, keys, strict=True):
        for i, lib in enumerate(libraries):
            values = [next((r.get(key) for r in rows if r["robot"] == rb and r["library"] == lib),
                           None) for rb in robots_]
            xs = [j + i * width for j, val in enumerate(values) if val]
            ax.bar(xs, [val * 1e6 for val in values if val], width, label=lib)
        ax.set_xticks([j + 0.4 - width / 2 for j in range(len(robots_))], robots_)
        ax.set_yscale("log")
        ax.set_ylabel("us")
        ax.set_title(title)
    axes[0].legend()
    fig.suptitle("mbjax bench speed: forward dynamics, float64, CPU (lower is better)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def report(records: list[dict]) -> str:
    """The measurements and the targets as Markdown tables."""
    lines = ["| robot | nv | library | call [us] | eval in a rollout [us] | vmap per state [us] "
             "| derivatives: call [us] | derivatives: vmapped per state [us] "
             "| grad / rollout | grad memory [MB] | compile [s] | agrees with mbjax |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in records[:-1]:
        if "skipped" in r:
            continue

        def cell(key, scale, digits, r=r):
            return f"{r[key] * scale:.{digits}f}" if key in r else ""
        cells = [r["robot"], str(r["nv"]), r["library"], cell("call_s", 1e6, 2),
                 cell("eval_s", 1e6, 2), cell("vmap_s", 1e6, 2), cell("jac_s", 1e6, 1),
                 cell("jac_vmap_s", 1e6, 1), cell("grad_ratio", 1, 2),
                 cell("grad_temp_bytes", 1e-6, 1), cell("compile_s", 1, 2),
                 f"{r['rel_diff_mbjax']:.1e}" if "rel_diff_mbjax" in r else ""]
        lines.append("| " + " | ".join(cells) + " |")
    lines += ["", *_targets(records[-1])]
    return "\n".join(lines)


def _targets(summary: dict) -> list[str]:
    lines = ["| target | measured | limit | met |", "| --- | --- | --- | --- |"]
    for t in summary["targets"]:
        value = f"{t['value'] * 1e6:.1f} us" if t["unit"] == "s" else f"{t['value']:.2f}"
        limit = f"{t['limit'] * 1e6:.0f} us" if t["unit"] == "s" else f"{t['limit']:g}"
        lines.append(f"| {t['target']} | {value} | {limit} | {'yes' if t['met'] else 'no'} |")
    return lines
