"""`mbjax bench trajopt`: trajectory optimisation: mbjax's iLQR against Crocoddyl's FDDP.
On identical problems, one at a time and 64 at once.

Problems: `arm-reach`, the shipped 7-dof arm's flange moved 0.4 m, and `acrobot-swingup`, the
double pendulum driven at its elbow to upright (`mbjax.scenes`); and Crocoddyl's own
contact-free examples (`mbjax_harness.crocoddyl.examples`): `kinova-reach`, `double-pendulum`,
`quadrotor` (a free base driven by four thrusters through an actuation matrix) and
`quadrotor-bounded` (thrusts in [0.1, 5] N, Crocoddyl's BoxDDP); and its legged gaits through
contact (`mbjax_harness.crocoddyl.gaits`): `anymal-walk` (its quadrupedal walk, 108 knots of
contact phases and impulses) and `talos-step` (a step of each foot of Talos's legs), whose
records also hold mbjax's solution (`xs` in Pinocchio's state layout, `us` in Crocoddyl's
control order, empty at an impulse). Each is built twice, as an
`mbjax.trajopt.Problem` and as a Crocoddyl shooting problem (Pinocchio models of the same URDF,
the same residuals and weights, the same horizon and step), both with semi-implicit Euler steps
(Crocoddyl's `IntegratedActionModelEuler`), both from the same first guess and its rollout. The
run checks that the two are one problem: Crocoddyl's step from each state of the guess's mbjax
rollout lands on mbjax's next state (`one_step_agreement`, largest difference in Crocoddyl's
layout) and the guess costs the same (`cost_agreement`, relative); and it prices each engine's
solution in the other (`cost_in_other_engine`: the rollout of its controls).

mbjax's iLQR runs with Crocoddyl's globalization (`ILQR(**CROCODDYL_SCHEDULE)`: the same
step lengths, acceptance test and regularization schedule), so the two differ in their
derivatives and their code, not in their strategy.

Timing. Each solver runs until its own convergence test passes (mbjax: a relative decrease below
1e-8; Crocoddyl: its stopping criterion, 1e-9 on the expected improvement) or 200 iterations, from
the rolled-out guess. `seconds` is the median wall time of that solve (mbjax after compiling,
`compile_s` apart); `seconds_to_tolerance` is the wall time of a solve stopped after the
iterations the solver needed to come within 1e-6 (relative) of the better of the two final costs
(`TOLERANCE`, found from each solver's cost history; None where the solver stops short of it), so
a solver is not charged for a tail that its convergence test, not the problem, asks for: the
fastest of `TIMED_RUNS` solves of each engine, the two taking turns (this machine's slow spells,
+-25 % over seconds, otherwise decided ratios near 1). Single problems
run single-threaded against single-threaded: Crocoddyl's problem with `nthreads = 1` (with its
default, a thread per core, it ran on both cores, its CPU time twice its wall time, although this
build warns that `nthreads` has no effect), mbjax's one jitted solve (XLA ran it no faster with a
second core). The batches run on the same two
cores: Crocoddyl's loop with its default threads, mbjax's batch split over a device per core.

Many targets: `N_TARGETS` flange targets 0.4 m from the start in a 30-degree cone about the
single problem's direction (seeded), solved by mbjax as one `jax.vmap`ped solve (every problem
iterates until the slowest is done), by mbjax one jitted solve at a time, and by Crocoddyl in a
Python loop (its targets changed in place). JSON lines + PNG; the last record (kind "summary")
holds the targets: the better problem's `seconds_to_tolerance` within 2x Crocoddyl's, and
the 64 targets ahead of Crocoddyl's loop.
"""

import platform
import time
from functools import partial
from pathlib import Path

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from mbjax_harness import peers
from mbjax_harness.crocoddyl.examples import EXAMPLES, Example
from mbjax_harness.crocoddyl.gaits import GAITS
from mbjax_harness.crocoddyl.solver import CrocoddylSolver, _controls, agreement
from mbjax_harness.crocoddyl.terms import crocoddyl_reach, crocoddyl_swingup, crocoddyl_working
from mbjax.integrate import SemiImplicitEuler
from mbjax_harness.timing import in_turns, measure, write_jsonl
from mbjax.trajopt import CROCODDYL_SCHEDULE, ILQR, solve

NAME = "trajopt"
TOLERANCE = 1e-6
ITERATIONS = 200
TIMED_RUNS = 15        # each engine's solves to the tolerance, in turns
N_TARGETS, QUICK_TARGETS = 64, 8
N_VARIANTS = 256               # the acrobot sweep (issue 42: batches that pay)
CONE = np.radians(30.0)


def targets(n: int, seed: int = 0) -> np.ndarray:
    """n offsets [m] of length 0.4 in a cone of half-angle CONE about +y (`scenes.arm.REACH`)."""
    rng = np.random.default_rng(seed)
    cos = rng.uniform(np.cos(CONE), 1.0, n)
    phi = rng.uniform(0.0, 2 * np.pi, n)
    sin = np.sqrt(1.0 - cos**2)
    return 0.4 * np.stack([sin * np.cos(phi), cos, sin * np.sin(phi)], 1)


def arm_reach():
    """(mbjax problem, first guess, final error of a final q, Crocoddyl builder)."""
    from mbjax.data import ARM7
    from mbjax.rigid import inverse_dynamics
    from mbjax.scenes import arm

    problem = arm.reach_problem(integrator=SemiImplicitEuler())
    model = problem.system.model
    target = arm.reach_target(model)
    zero = jnp.zeros(model.nv)

    def crocoddyl(target=target):
        return crocoddyl_reach(str(ARM7), problem.q0, target,
                                     inverse_dynamics(model, problem.q0, zero, zero), arm.FLANGE,
                                     problem.dt, problem.horizon)

    return (problem, arm.hold(problem),
            lambda q: float(jnp.linalg.norm(arm.flange(model, q) - target)), crocoddyl)


def _identity(xs):
    return np.asarray(xs)


def arm_example() -> Example:
    problem, us0, final_error, build = arm_reach()
    return Example(problem, np.asarray(us0), lambda: build()[0], "SolverFDDP", _identity,
                   final_error)


def acrobot_example() -> Example:
    from mbjax.model import to_urdf
    from mbjax.scenes import acrobot

    problem = acrobot.swingup_problem(integrator=SemiImplicitEuler())
    model = problem.system.model
    goal = jnp.array([0.0, 0.0, 2 * acrobot.LENGTH])

    def crocoddyl():
        return crocoddyl_swingup(to_urdf(model), problem.q0, goal, acrobot.LENGTH,
                                       problem.dt, problem.horizon)

    return Example(problem, np.zeros((problem.horizon, problem.nu)), crocoddyl, "SolverFDDP",
                   _identity, lambda q: float(jnp.linalg.norm(acrobot.tip(model, q) - goal)))


PROBLEMS = {"arm-reach": arm_example, "acrobot-swingup": acrobot_example, **EXAMPLES, **GAITS}
GAIT_TIMED_RUNS = 3     # a gait's solve takes seconds: fewer turns


def _to_tolerance(costs, best: float) -> int | None:
    """The first iteration whose cost is within TOLERANCE of best (None if none is)."""
    costs = np.asarray(costs)
    within = np.flatnonzero(costs <= best + TOLERANCE * abs(best))
    return int(within[0]) if len(within) else None


def single(name: str, repeats: int, common: dict) -> list[dict]:
    """Both engines on one problem: cost histories, times to convergence and to TOLERANCE, and
    each engine's solution priced by the other."""
    example = PROBLEMS[name]()
    problem, us0 = example.problem, jnp.asarray(example.us0)
    states0 = None if example.states0 is None else jnp.asarray(example.states0)
    final_error = example.final_error or (lambda q: None)
    ilqr = ILQR(iterations=ITERATIONS, **CROCODDYL_SCHEDULE)
    result, timing = measure(solve, problem, ilqr, us0, states0, repeats=repeats)
    iterations = int(result.iterations)
    costs = np.asarray(result.costs)[:iterations + 1]
    mbjax = {**common, "kind": "single", "problem": name, "engine": "mbjax", "solver": "ILQR",
             "iterations": iterations, "seconds": timing.run_s, "compile_s": timing.compile_s,
             "cost": float(result.cost), "final_error": final_error(result.qs[-1]),
             "status": result.messages()[0], "history": costs.tolist()}
    records = [mbjax]
    why = crocoddyl_working()
    if why is not None:
        records.append({**common, "kind": "single", "problem": name, "engine": "crocoddyl",
                        "skipped": why})
        best = mbjax["cost"]
    else:
        croc_problem = example.crocoddyl()
        to_croc, from_croc = _controls(example, croc_problem)
        croc = CrocoddylSolver(croc_problem, to_croc(example.us0), example.solver,
                               xs0=None if states0 is None else example.to_crocoddyl(states0))
        checks = agreement(example, croc_problem)
        history = croc.history(ITERATIONS)
        converged = croc.solve(ITERATIONS)
        us_croc = from_croc(croc.solver.us)
        q_end = problem.split(problem.rollout(jnp.asarray(us_croc))[-1])[0]
        us_mbjax = to_croc(result.us)
        mbjax["cost_in_other_engine"] = croc_problem.calc(croc_problem.rollout(us_mbjax),
                                                          us_mbjax)
        if name in GAITS:      # the solution, in Pinocchio's state layout and Crocoddyl's controls
            mbjax["xs"] = example.to_crocoddyl(result.xs).tolist()
            mbjax["us"] = [u.tolist() for u in us_mbjax]
        records.append({
            **common, "kind": "single", "problem": name, "engine": "crocoddyl",
            "solver": example.solver, "iterations": int(croc.solver.iter),
            "seconds": croc.timed(ITERATIONS, repeats), "cost": float(croc.solver.cost),
            "final_error": final_error(q_end),
            "status": "success" if converged else "not converged", "history": history,
            "cost_in_other_engine": float(problem.objective(jnp.asarray(us_croc))), **checks})
        best = min(mbjax["cost"], records[-1]["cost"])
        records[-1]["iterations_to_tolerance"] = _to_tolerance(history, best)
    k = _to_tolerance(costs, best)
    mbjax["iterations_to_tolerance"] = k
    # the solves stopped at the tolerance, timed in turns
    runs = {}
    if k is not None:
        stopped = ILQR(iterations=max(k, 1), **CROCODDYL_SCHEDULE)
        runs["mbjax"] = lambda: jax.block_until_ready(solve(problem, stopped, us0, states0).us)
    if why is None and records[-1]["iterations_to_tolerance"] is not None:
        runs["crocoddyl"] = partial(croc.solve, max(records[-1]["iterations_to_tolerance"], 1))
    seconds = in_turns(runs, GAIT_TIMED_RUNS if name in GAITS else TIMED_RUNS)
    for r in records:
        if "skipped" not in r:
            r["seconds_to_tolerance"] = seconds.get(r["engine"])
    for r in records:
        r["best_cost"] = best
        r["relative_to_best"] = (r["cost"] - best) / abs(best) if "cost" in r else None
    return records


def _batch_record(base: dict, engine: str, how: str, seconds: float, iterations,
                  converged, **extra) -> dict:
    """One way of solving a batch of problems: its wall time, iterations and convergence."""
    return {**base, "engine": engine, "how": how, "seconds": seconds,
            "mean_iterations": float(np.mean(iterations)),
            "max_iterations": int(np.max(iterations)), "converged": int(np.sum(converged)),
            **extra}


def _looped(solve_one, inputs) -> tuple[float, list[int], list[bool]]:
    """(seconds, iterations, converged) of a Python loop of one jitted `solve_one(x)` over
    inputs, after a compiling call."""
    one = jax.jit(solve_one)
    jax.block_until_ready(one(jnp.asarray(inputs[0])))
    start = time.perf_counter()
    results = [jax.block_until_ready(one(jnp.asarray(x))) for x in inputs]
    return (time.perf_counter() - start, [int(r.iterations) for r in results],
            [int(r.status) == 0 for r in results])


def many(n: int, repeats: int, common: dict, loop: bool = True) -> list[dict]:
    """The arm's reach to n targets: mbjax vmapped, mbjax one by one (unless not `loop`: on a
    GPU each solve is thousands of small kernels), Crocoddyl in a loop."""
    from mbjax.scenes import arm

    problem, us0, _, build = arm_reach()
    model = problem.system.model
    offsets = targets(n)

    solver = ILQR(iterations=ITERATIONS, **CROCODDYL_SCHEDULE)

    def one(offset):
        return solve(arm.reach_problem(offset, arm=model, integrator=SemiImplicitEuler()),
                     solver, us0)

    summary = partial(_batch_record, {**common, "kind": "many", "problem": "arm-reach",
                                      "targets": n})
    problems = eqx.filter_vmap(lambda o: arm.reach_problem(o, arm=model,
                                                           integrator=SemiImplicitEuler()))(
        jnp.asarray(offsets))
    guesses = jnp.broadcast_to(jnp.asarray(us0), (n, *np.shape(us0)))
    results, timing = measure(solve, problems, solver, guesses, repeats=repeats)
    records = [summary("mbjax", f"one batched solve (a working set per device, "
                       f"{len(jax.devices())} devices)", timing.run_s,
                       np.asarray(results.iterations), np.asarray(results.status) == 0,
                       compile_s=timing.compile_s, devices=len(jax.devices()))]
    batched = jax.jit(jax.vmap(one))
    results, timing = measure(batched, jnp.asarray(offsets), repeats=repeats)
    records.append(summary("mbjax", "one vmapped solve", timing.run_s,
                           np.asarray(results.iterations), np.asarray(results.status) == 0,
                           compile_s=timing.compile_s))
    if loop:
        records.append(summary("mbjax", "a loop of jitted solves", *_looped(one, offsets)))
    why = crocoddyl_working()
    if why is not None:
        records.append({**common, "kind": "many", "problem": "arm-reach", "engine": "crocoddyl",
                        "skipped": why})
        return records
    croc_problem, set_target = build()
    croc = CrocoddylSolver(croc_problem, us0, threads=None)
    start_flange = np.asarray(arm.flange(model, problem.q0))
    iterations, converged = [], []
    start = time.perf_counter()
    for offset in offsets:
        set_target(start_flange + offset)
        converged.append(croc.solve(ITERATIONS))
        iterations.append(croc.solver.iter)
    records.append(summary("crocoddyl", "a Python loop", time.perf_counter() - start, iterations,
                           converged))
    return records


def sweep_acrobot(n: int, common: dict) -> list[dict]:
    """The acrobot's swing-up for n variants, both links' masses scaled by factors in
    [0.8, 1.2]: mbjax's batched solve (a working set per device), a loop of one jitted solve,
    Crocoddyl's FDDP in a loop (its problems built beforehand, not timed)."""
    from mbjax.model import to_urdf
    from mbjax.scenes import acrobot

    base = acrobot.model()
    scales = np.linspace(0.8, 1.2, n)
    solver = ILQR(iterations=ITERATIONS, **CROCODDYL_SCHEDULE)

    def variant(scale):
        model = eqx.tree_at(lambda m: m.mass, base, base.mass * scale)
        return acrobot.swingup_problem(model, integrator=SemiImplicitEuler())

    summary = partial(_batch_record, {**common, "kind": "sweep", "problem": "acrobot-swingup",
                                      "variants": n})

    problems = eqx.filter_vmap(variant)(jnp.asarray(scales))
    horizon = problems.horizon
    guesses = jnp.zeros((n, horizon, 1))
    results, timing = measure(solve, problems, solver, guesses, repeats=1)
    records = [summary("mbjax", f"one batched solve ({len(jax.devices())} devices)",
                       timing.run_s, np.asarray(results.iterations),
                       np.asarray(results.status) == 0, compile_s=timing.compile_s)]
    records.append(summary("mbjax", "a loop of jitted solves", *_looped(
        lambda scale: solve(variant(scale), solver, jnp.zeros((horizon, 1))), scales)))
    why = crocoddyl_working()
    if why is not None:
        return records + [{**common, "kind": "sweep", "problem": "acrobot-swingup",
                           "engine": "crocoddyl", "skipped": why}]
    goal = jnp.array([0.0, 0.0, 2 * acrobot.LENGTH])
    built = []
    for scale in scales:
        model = eqx.tree_at(lambda m: m.mass, base, base.mass * scale)
        problem = variant(scale)
        built.append(CrocoddylSolver(crocoddyl_swingup(
            to_urdf(model), problem.q0, goal, acrobot.LENGTH, problem.dt, horizon),
            np.zeros((horizon, 1)), threads=None))
    start = time.perf_counter()
    converged = [croc.solve(ITERATIONS) for croc in built]
    records.append(summary("crocoddyl", "a Python loop", time.perf_counter() - start,
                           [croc.solver.iter for croc in built], converged))
    return records


def summarize(records: list[dict], common: dict) -> dict:
    """The targets, met or missed, from the records."""
    out = {**common, "kind": "summary"}
    singles = {(r["problem"], r["engine"]): r for r in records
               if r["kind"] == "single" and "skipped" not in r}
    # where one engine never came within TOLERANCE of the other's optimum, the other wins (0 or
    # inf); where neither did (both stopped short of the better optimum), no ratio
    def ratio(ours, theirs):
        if ours is None:
            return None if theirs is None else float("inf")
        return 0.0 if theirs is None else ours / theirs

    ratios = {p: ratio(singles[p, "mbjax"]["seconds_to_tolerance"],
                       singles[p, "crocoddyl"]["seconds_to_tolerance"])
              for p in PROBLEMS if (p, "crocoddyl") in singles}
    ratios = {p: r for p, r in ratios.items() if r is not None}
    out["single_ratio"] = ratios
    out["single_met"] = max(ratios.values()) <= 1.0 if ratios else None      # issue 42: <= 1x
    many_ = {(r["engine"], r.get("how")): r for r in records
             if r["kind"] == "many" and "skipped" not in r}
    croc = [r for (engine, _), r in many_.items() if engine == "crocoddyl"]
    if croc:
        best = min(r["seconds"] for (engine, _), r in many_.items() if engine == "mbjax")
        out["many_ratio"] = best / croc[0]["seconds"]
        out["many_met"] = out["many_ratio"] < 1.0
    else:
        out["many_ratio"] = out["many_met"] = None
    sweeps = {(r["engine"], r.get("how")): r for r in records
              if r["kind"] == "sweep" and "skipped" not in r}
    croc = [r for (engine, _), r in sweeps.items() if engine == "crocoddyl"]
    batch = [r for (engine, how), r in sweeps.items() if engine == "mbjax" and "batched" in how]
    loop_ = [r for (engine, how), r in sweeps.items() if engine == "mbjax" and "loop" in how]
    out["sweep_ratio"] = batch[0]["seconds"] / croc[0]["seconds"] if croc and batch else None
    out["sweep_batch_over_loop"] = (batch[0]["seconds"] / loop_[0]["seconds"]
                                    if batch and loop_ else None)
    return out


def table(records: list[dict]) -> str:
    """The single problems as a Markdown table: problem | engine | iterations | wall time to
    1e-6 | cost | status, with the agreement checks."""
    lines = ["| problem | engine | iterations (to 1e-6) | wall time to 1e-6 [ms] | cost | "
             "status | one step, guess cost agree |", "|---|---|---|---|---|---|---|"]
    for r in records:
        if r["kind"] != "single" or "skipped" in r:
            continue
        checks = (f"{r['one_step_agreement']:.1e}, {r['cost_agreement']:.1e}"
                  if "one_step_agreement" in r else "")
        to = r["seconds_to_tolerance"]
        lines.append(f"| {r['problem']} | {r['engine']} {r['solver']} | {r['iterations']} "
                     f"({r['iterations_to_tolerance'] if to is not None else '-'}) | "
                     f"{f'{to * 1e3:.1f}' if to is not None else 'not within 1e-6'} | "
                     f"{r['cost']:.10g} | {r['status']} | {checks} |")
    return "\n".join(lines)


def run(out: Path, quick: bool = False) -> list[dict]:
    common = {"machine": platform.machine(), "jax": jax.__version__,
              "device": jax.devices()[0].device_kind, "backend": jax.default_backend()}
    if peers.available("crocoddyl"):
        import crocoddyl
        import pinocchio

        common.update(crocoddyl=crocoddyl.__version__, pinocchio=pinocchio.__version__)
    repeats = 1 if quick else 3
    records = []
    for name in PROBLEMS:
        records += single(name, repeats, common)
    records += many(QUICK_TARGETS if quick else N_TARGETS, 1, common)
    records += sweep_acrobot(QUICK_TARGETS if quick else N_VARIANTS, common)
    records.append(summarize(records, common))

    out.mkdir(parents=True, exist_ok=True)
    write_jsonl(out / f"{NAME}.jsonl", records)
    from mbjax_harness.plot.bench import trajopt_bench_figure
    trajopt_bench_figure(records).savefig(out / f"{NAME}.png", dpi=120)
    for r in records:
        if "skipped" in r:
            print(f"{r['kind']:6s} {r['problem']:18s} {r['engine']:9s} skipped: {r['skipped']}")
        elif r["kind"] == "sweep":
            print(f"sweep  {r['variants']} acrobots {r['engine']:9s} {r['how']:24s} "
                  f"{r['seconds']:7.2f} s, iterations mean {r['mean_iterations']:.0f} max "
                  f"{r['max_iterations']}, converged {r['converged']}/{r['variants']}")
        elif r["kind"] == "many":
            print(f"many   {r['targets']} targets {r['engine']:9s} {r['how']:24s} "
                  f"{r['seconds']:7.2f} s, iterations mean {r['mean_iterations']:.0f} max "
                  f"{r['max_iterations']}, converged {r['converged']}/{r['targets']}")
        elif r["kind"] == "summary":
            print(f"targets: every problem within 1x Crocoddyl: {r['single_met']} "
                  f"({r['single_ratio']}); many targets ahead: {r['many_met']} "
                  f"(ratio {r['many_ratio']}); acrobot sweep batched / Crocoddyl "
                  f"{r['sweep_ratio']}, / mbjax loop {r['sweep_batch_over_loop']}")
    print(table(records))
    print(f"wrote {out / (NAME + '.jsonl')} and {out / (NAME + '.png')}")
    return records
