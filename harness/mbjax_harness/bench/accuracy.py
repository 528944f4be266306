"""`mbjax bench accuracy`: what the default accuracy check catches, and what it costs.

Catches: the runs issue 43's probe found reporting `success` while far off (a stiff PD servo
just past RK4's stability limit, the same with semi-implicit Euler, dm_control's reacher at its
own step with a fast start, the heavy top at 50 ms, a 7-link chain at 40 ms, the vertical top's
primal time elements past their stability boundary), and the same systems at a step that
resolves them. Each run's final error against the same method at a 20 times finer step (the
time elements: against the mixed form's march at a quarter of the spacing), its status by
default and with rtol = 1e-3, and the default check's measure (`resolution`; the time
elements': the invariants' `drift`).

Cost: the 7-link chain's rollout (RK4, 200 steps of 10 ms, every state saved), `simulate` with
its status and default check against the bare loop (`lax.scan` of the same integrator's step,
no status): the first call (tracing and compiling) and a warm call, taking turns.
"""

import platform
import time
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from mbjax_harness.timing import in_turns, write_jsonl

NAME = "accuracy"
# the optional packages used where installed (dm_control: its reacher, one more case), left out
# of the records where not: the command's closing line names those missing
# (`mbjax_harness.cli._declared`)
PEERS = ("dm_control",)
RTOL = 1e-3


def _cases():
    """(name, system, integrator, q0, u0, dt, t1, the step that resolves it) for each case."""
    from mbjax.control import PD
    from mbjax.integrate import RK4, ImplicitMidpoint, SemiImplicitEuler
    from mbjax.model import chain, load_mjcf
    from mbjax.rigid import TreeSystem
    from mbjax.scenes import heavy_top as top

    link = chain(1)                         # a 0.3 m, 1 kg rod: I = m l^2 / 3 about its joint
    inertia = 0.3**2 / 3

    def stiff(omega_dt, dt=0.01):           # a PD servo of natural frequency omega_dt / dt
        return TreeSystem(link, control=PD(inertia * (omega_dt / dt) ** 2, 0.0, 0.0))

    cases = [("stiff PD, RK4 past its limit (omega dt = 2.9)", stiff(2.9), RK4(),
              jnp.array([0.01]), jnp.zeros(1), 0.01, 1.0, 0.002),
             ("stiff PD, semi-implicit Euler past its limit (omega dt = 2.2)", stiff(2.2),
              SemiImplicitEuler(), jnp.array([0.01]), jnp.zeros(1), 0.01, 1.0, 0.002)]
    try:
        from dm_control import suite
        path = Path(suite.__file__).parent / "reacher.xml"
        reacher = TreeSystem(load_mjcf(str(path)))
        cases.append(("dm_control reacher, RK4 at its 20 ms, fast start", reacher, RK4(),
                      jnp.array([0.5, 1.0]), jnp.array([20.0, -30.0]), 0.02, 5.0, 0.002))
    except ImportError:
        pass
    body, q0, u0 = top.build()
    cases += [("heavy top, implicit midpoint at 50 ms", body, ImplicitMidpoint(), q0, u0, 0.05,
               1.0, 0.01),
              ("heavy top, RK4 at 50 ms", body, RK4(), q0, u0, 0.05, 1.0, 0.01),
              ("7-link chain, RK4 at 40 ms (chaotic)", TreeSystem(chain(7)), RK4(),
               jnp.full(7, 1.0), jnp.zeros(7), 0.04, 10.0, 0.01)]
    return cases


def _caught(records: list[dict], quick: bool) -> None:
    from mbjax.integrate import RK4, simulate

    for name, system, integrator, q0, u0, dt, t1, fine_dt in _cases():
        if quick and "chain" in name:
            continue
        for step in (dt, fine_dt):
            run = simulate(system, integrator, q0, u0, dt=step, t1=t1, saveat=[t1])
            checked = simulate(system, integrator, q0, u0, dt=step, t1=t1, saveat=[t1],
                               rtol=RTOL)
            ref = simulate(system, RK4(), q0, u0, dt=step / 20, t1=t1, saveat=[t1])
            error = float(jnp.max(jnp.abs(run.qs[-1] - ref.qs[-1])))
            records.append({"suite": NAME, "kind": "case", "case": name, "dt": step,
                            "error": error if np.isfinite(error) else None,
                            "resolution": float(run.resolution), "status": run.messages()[0],
                            "ok": bool(run.ok), "status_rtol": checked.messages()[0],
                            "ok_rtol": bool(checked.ok)})
    _time_elements(records)


def _time_elements(records: list[dict]) -> None:
    """The vertical top at 1.01 Omega_c, 2-node elements of 0.5 s about the steady rotation
    over 20 s (tests/tfe/test_accuracy.py): the primal form's tilt grows, the mixed form's does
    not; the error is the final attitude's against the mixed form at 0.125 s."""
    from mbjax import lie
    from mbjax.scenes import vertical_top as vt
    from mbjax.tfe import Element, Mixed, PrimalUnsymmetric, initial_state, solve_tfe
    from mbjax_harness.common import DT, SPIN_RATIO, TILT0, steady_rotation  # top-long-run's

    body = vt.build()
    spin = SPIN_RATIO * vt.CRITICAL_SPIN
    state0 = initial_state(body, lie.exp(jnp.array([TILT0, 0.0, 0.0])),
                           jnp.array([0.0, 0.0, spin]))
    march = dict(element=Element(2), reference=steady_rotation(spin))
    ref = solve_tfe(body, state0, dt=DT / 4, n_elements=160, form=Mixed(), **march)
    for name, form in (("primal", PrimalUnsymmetric()), ("mixed", Mixed())):
        run = solve_tfe(body, state0, dt=DT, n_elements=40, form=form, **march)
        checked = solve_tfe(body, state0, dt=DT, n_elements=40, form=form, rtol=RTOL,
                            atol=RTOL, **march)
        error = float(jnp.linalg.norm(lie.log(run.R[-1] @ ref.R[-1].T)))
        records.append({"suite": NAME, "kind": "case", "dt": DT,
                        "case": f"vertical top, {name} time elements of 0.5 s",
                        "error": error, "resolution": None,
                        "drift": float(run.drift), "status": run.messages()[0],
                        "ok": bool(run.ok), "status_rtol": checked.messages()[0],
                        "ok_rtol": bool(checked.ok)})


def _cost(records: list[dict], quick: bool) -> None:
    """simulate against the bare loop on the 7-link chain (see the module docstring)."""
    from mbjax.integrate import RK4, simulate
    from mbjax.model import chain
    from mbjax.rigid import TreeSystem

    system, integrator = TreeSystem(chain(7)), RK4()
    q0, u0, dt, n = jnp.full(7, 0.3), jnp.zeros(7), 0.01, 200

    @jax.jit
    def bare(q0, u0):
        def step(state, k):
            q, u = state
            q1, u1, _ = integrator.step(system.hold(k * dt, q, u), k * dt, q, u, dt)
            return (q1, u1), (q1, u1)
        return jax.lax.scan(step, (q0, u0), jnp.arange(n))[1]

    runs = {"simulate": lambda: jax.block_until_ready(
                simulate(system, integrator, q0, u0, dt=dt, t1=n * dt).qs),
            "bare loop": lambda: jax.block_until_ready(bare(q0, u0))}
    first = {}
    for name, run in runs.items():          # first calls: tracing and compiling, one each
        jax.clear_caches()
        start = time.perf_counter()
        run()
        first[name] = time.perf_counter() - start
    warm = in_turns(runs, repeats=20 if quick else 200)
    for name in runs:
        records.append({"suite": NAME, "kind": "cost", "model": "chain7", "integrator": "rk4",
                        "steps": n, "variant": name, "first_call_s": first[name],
                        "warm_s": warm[name]})


def run(out: Path, quick: bool = False) -> list[dict]:
    records = []
    _caught(records, quick)
    _cost(records, quick)
    for r in records:
        r.update(machine=platform.machine(), jax=jax.__version__)
    out.mkdir(parents=True, exist_ok=True)
    write_jsonl(out / f"{NAME}.jsonl", records)
    from mbjax_harness.plot.bench import accuracy_bench_figure
    accuracy_bench_figure(records).savefig(out / f"{NAME}.png", dpi=120)
    for r in records:
        if r["kind"] == "case":
            error = "diverged" if r["error"] is None else f"{r['error']:.3g}"
            measure = (f"resolution {r['resolution']:.3g}" if r["resolution"] is not None
                       else f"drift {r['drift']:.3g}")
            print(f"{r['case']:62s} dt={r['dt']:<6g} error {error:>9s}  {measure}  default: "
                  f"{r['status'][:60]}  rtol: {'ok' if r['ok_rtol'] else 'failed'}")
        else:
            print(f"chain7 {r['variant']:9s} first call {r['first_call_s']:.3f} s, warm "
                  f"{r['warm_s'] * 1e3:.3f} ms")
    return records
