"""`mbjax bench compile`: what compiling costs a user, against its targets. Its targets: a cold
quick tour in 60 s, warm in 15 s, a scene in 3 s.

- the tour: `mbjax tour --quick` in a fresh process with an empty persistent cache (cold), then
  again with the cache it filled (warm), and the process's wall time from start to exit; once as
  a user runs it (scenes side by side, one worker process per core: `mbjax_harness.parallel`), once
  with `--jobs 1` (one scene after another in one process, on a quiet machine), which also
  gives each scene's wall time alone and the programs XLA compiled or loaded for it (JAX's
  compile events);
- the first calls: in a fresh process with no cache, `mbjax.forward_dynamics` and
  `mbjax.mass_matrix` of the 7-link chain called outside `jax.jit`, as in a notebook: the first
  call (tracing and compiling) and the calls after it;
- the legged-robots guide's hand-written step (docs/legged-robots.md, its first three blocks as
  written, with the `robots` extra): its first `solve` with no cache, split into tracing and
  lowering and XLA's compile (JAX's compile events), against a target of 15 s (issue 61).

Every measurement runs in a subprocess of its own, so nothing is compiled before it starts.
"""

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from mbjax_harness.timing import write_jsonl

NAME = "compile"
# targets, seconds
TARGET_TOUR_COLD, TARGET_TOUR_WARM, TARGET_SCENE, TARGET_STEP = 60.0, 15.0, 3.0, 15.0
GUIDE = Path(__file__).resolve().parents[3] / "docs" / "legged-robots.md"

_TOUR = """
import json, sys
from jax import monitoring
from mbjax_harness import cli, tour

programs, current = {}, [None]
monitoring.register_event_duration_secs_listener(
    lambda event, duration, **kw: programs.__setitem__(current[0], programs.get(current[0], 0) + 1)
    if event == "/jax/core/compile/backend_compile_duration" else None)
for name, scene in list(tour.TOUR.items()):
    def counted(*args, _scene=scene, _name=name):
        current[0] = _name
        return _scene(*args)
    tour.TOUR[name] = counted
cli.main(["tour", "--quick", "--out", sys.argv[1], "--jobs", sys.argv[2]])
print(json.dumps(programs))
"""

_FIRST_CALLS = """
import json, time
import jax
jax.config.update("jax_enable_x64", True)
import numpy as np
import mbjax
from mbjax.model import chain

model = chain(7)
q, v, tau = (np.random.default_rng(k).uniform(-1, 1, 7) for k in range(3))
out = {}
for name, call in (("forward_dynamics", lambda: mbjax.forward_dynamics(model, q, v, tau)),
                   ("mass_matrix", lambda: mbjax.mass_matrix(model, q))):
    start = time.perf_counter()
    jax.block_until_ready(call())
    first = time.perf_counter() - start
    samples = []
    for _ in range(200):
        start = time.perf_counter()
        jax.block_until_ready(call())
        samples.append(time.perf_counter() - start)
    out[name] = {"first_s": first, "call_s": float(np.median(samples))}
print(json.dumps(out))
"""


_STEP = """
import json, re, sys, time
from jax import monitoring

blocks = re.findall(r"```python\\n(.*?)```", open(sys.argv[1]).read(), re.S)
exec("\\n".join(blocks[:3]))            # load ANYmal, stand it, write the step
events = {}
monitoring.register_event_duration_secs_listener(
    lambda event, duration, **kw: events.__setitem__(event, events.get(event, 0.0) + duration))
start = time.perf_counter()
result = solve(step, ILQR(), quasi_static(step))
result.cost.block_until_ready()
first = time.perf_counter() - start
start = time.perf_counter()
solve(step, ILQR(), quasi_static(step)).cost.block_until_ready()
again = time.perf_counter() - start
xla = events.get("/jax/core/compile/backend_compile_duration", 0.0)
trace = sum(v for k, v in events.items() if k in ("/jax/core/compile/jaxpr_trace_duration",
            "/jax/core/compile/jaxpr_to_mlir_module_duration"))
print(json.dumps({"first_s": first, "trace_lower_s": trace, "xla_s": xla, "again_s": again,
                  "iterations": int(result.iterations), "status": result.messages()[0],
                  "knots": step.horizon, "phases": step.n_phases}))
"""


def _python(script: str, *args: str, env: dict | None = None) -> tuple[dict, float]:
    """(the JSON the script prints last, the process's wall time)."""
    start = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", script, *args], capture_output=True, text=True,
                         check=True, env={**os.environ, **(env or {})})
    wall = time.perf_counter() - start
    return json.loads(out.stdout.strip().splitlines()[-1]), wall


def run(out: Path, quick: bool = False) -> list[dict]:
    from mbjax_harness.parallel import cores

    records = []
    for jobs in (1, cores()):
        with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as tour_out:
            env = {"JAX_COMPILATION_CACHE_DIR": cache, "MBJAX_NO_CACHE": "0"}
            for run_kind in ("cold", "warm"):
                programs, wall = _python(_TOUR, tour_out, str(jobs), env=env)
                summary = json.loads((Path(tour_out) / "summary.json").read_text())
                # programs are counted in this process: with workers, in none
                scenes = {name: {"wall_s": scene["wall_seconds"],
                                 "programs": programs.get(name) if jobs == 1 else None}
                          for name, scene in summary["scenes"].items()}
                records.append({"suite": NAME, "kind": "tour", "cache": run_kind, "jobs": jobs,
                                "wall_s": wall, "scenes": scenes})
    first, _ = _python(_FIRST_CALLS, env={"MBJAX_NO_CACHE": "1"})
    records.append({"suite": NAME, "kind": "first_calls", "model": "chain7", **first})
    try:
        step, _ = _python(_STEP, str(GUIDE), env={"MBJAX_NO_CACHE": "1"})
        records.append({"suite": NAME, "kind": "guide_step", **step})
    except (subprocess.CalledProcessError, FileNotFoundError) as error:   # no robots extra
        print(f"the legged guide's step skipped: {getattr(error, 'stderr', error)}"[-400:])
    records.append(summarize(records))
    write_jsonl(out / f"{NAME}.jsonl", records)
    plot(records, out / f"{NAME}.png")
    return records


def _tours(records: list[dict], one_at_a_time: bool) -> dict:
    """{"cold": record, "warm": record} of the tours run one scene at a time or with a worker
    per core."""
    return {r["cache"]: r for r in records if r.get("kind") == "tour"
            and (r["jobs"] == 1) == one_at_a_time}


def summarize(records: list[dict]) -> dict:
    """The compile-time targets, each met or missed: the tours as a user runs them, each
    scene alone (one at a time, from a cold cache)."""
    tours, alone = _tours(records, False), _tours(records, True)
    targets = [{"target": "tour --quick, cold cache", "value": tours["cold"]["wall_s"],
                "limit": TARGET_TOUR_COLD},
               {"target": "tour --quick, warm cache", "value": tours["warm"]["wall_s"],
                "limit": TARGET_TOUR_WARM}]
    targets += [{"target": f"scene {name}, cold cache", "value": scene["wall_s"],
                 "limit": TARGET_SCENE} for name, scene in alone["cold"]["scenes"].items()]
    targets += [{"target": "the legged guide's hand-written step, first solve (no cache)",
                 "value": r["first_s"], "limit": TARGET_STEP}
                for r in records if r.get("kind") == "guide_step"]
    for t in targets:
        t["met"] = bool(t["value"] <= t["limit"])
    return {"suite": NAME, "kind": "summary", "targets": targets}


def plot(records: list[dict], path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    tours, alone = _tours(records, False), _tours(records, True)
    names = list(alone["cold"]["scenes"])
    fig, ax = plt.subplots(figsize=(11, 4))
    width = 0.4
    for i, (kind, hatch) in enumerate((("cold", None), ("warm", "//"))):
        scenes = alone[kind]["scenes"]
        bars = ax.bar([j + i * width for j in range(len(names))],
                      [scenes[n]["wall_s"] for n in names], width, hatch=hatch,
                      label=f"{kind} cache (tour: {alone[kind]['wall_s']:.0f} s one scene at a "
                            f"time, {tours[kind]['wall_s']:.0f} s with a worker per core)")
        for bar, name in zip(bars, names, strict=True):
            ax.annotate(str(scenes[name]["programs"]), (bar.get_x() + bar.get_width() / 2,
                                                        bar.get_height()),
                        ha="center", va="bottom", fontsize=7)
    ax.axhline(TARGET_SCENE, color="k", lw=0.8, ls="--", label=f"target {TARGET_SCENE:g} s")
    ax.set_xticks([j + width / 2 for j in range(len(names))], names, rotation=20, ha="right")
    ax.set_ylabel("scene wall time [s]")
    ax.set_title("mbjax tour --quick --jobs 1, each scene from a cold and a warm compilation "
                 "cache (numbers: programs compiled or loaded)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def report(records: list[dict]) -> str:
    """The tours and the targets as Markdown tables."""
    tours, alone = _tours(records, False), _tours(records, True)
    jobs = tours["cold"]["jobs"]
    lines = ["| scene (`--jobs 1`) | cold [s] | programs | warm [s] | programs |",
             "| --- | --- | --- | --- | --- |"]
    for name, cold in alone["cold"]["scenes"].items():
        warm = alone["warm"]["scenes"][name]
        lines.append(f"| {name} | {cold['wall_s']:.1f} | {cold['programs']} | "
                     f"{warm['wall_s']:.1f} | {warm['programs']} |")
    lines.append(f"| the whole process, one scene at a time | {alone['cold']['wall_s']:.1f} | | "
                 f"{alone['warm']['wall_s']:.1f} | |")
    lines.append(f"| the whole process, {jobs} workers (the default) | "
                 f"{tours['cold']['wall_s']:.1f} | | {tours['warm']['wall_s']:.1f} | |")
    first = next(r for r in records if r.get("kind") == "first_calls")
    lines += ["", "| called outside jit (7-link chain) | first call [ms] | later calls [us] |",
              "| --- | --- | --- |"]
    lines += [f"| {name} | {first[name]['first_s'] * 1e3:.0f} | {first[name]['call_s'] * 1e6:.1f} |"
              for name in ("forward_dynamics", "mass_matrix")]
    for r in (r for r in records if r.get("kind") == "guide_step"):
        lines += ["", "| the legged guide's step | first solve [s] | trace and lower [s] | XLA [s] "
                  "| second solve [s] | iterations | status |", "| --- | --- | --- | --- | --- | --- | --- |",
                  f"| {r['knots']} knots, {r['phases']} phases | {r['first_s']:.1f} | "
                  f"{r['trace_lower_s']:.1f} | {r['xla_s']:.1f} | {r['again_s']:.2f} | "
                  f"{r['iterations']} | {r['status']} |"]
    lines += ["", "| target | measured [s] | limit [s] | met |", "| --- | --- | --- | --- |"]
    lines += [f"| {t['target']} | {t['value']:.1f} | {t['limit']:g} | "
              f"{'yes' if t['met'] else 'no'} |" for t in records[-1]["targets"]]
    return "\n".join(lines)
