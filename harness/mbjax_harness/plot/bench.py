"""Figures of the benchmark suites."""

import numpy as np
from matplotlib.ticker import NullFormatter

from mbjax_harness.plot.style import COLORS, MARKERS, Figure


def integrators_bench_figure(records: list[dict]) -> Figure:
    """Left: error at 10 s against run time, mbjax (coloured) and MuJoCo (grey) integrators.
    Right: steps per second against batch size."""
    fig = Figure(figsize=(12, 5), layout="constrained")
    ax_wp, ax_batch = fig.subplots(1, 2)
    single = [r for r in records if r["batch"] == 1]
    for engine, integrator in dict.fromkeys((r["engine"], r["integrator"]) for r in single):
        rows = [r for r in single if r["engine"] == engine and r["integrator"] == integrator]
        err = np.array([r["error"] for r in rows])
        ok = np.isfinite(err) & (err < 10)
        if engine == "mbjax":
            kw = dict(color=COLORS[integrator], marker=MARKERS[integrator], label=f"mbjax {integrator}")
        else:
            kw = dict(color=COLORS["mujoco"], marker="x", ls="--", label=f"MuJoCo {integrator}")
        ax_wp.loglog(np.array([r["run_s"] for r in rows])[ok], err[ok], **kw)
    ax_wp.set(xlabel="run time for 10 s [s]", ylabel="rotation error at 10 s [rad]",
              title="heavy top: speed against accuracy (diverged runs omitted)")
    batched = [r for r in records if r["batch"] > 1 or r["integrator"] in ("rkmk4", "RK4")]
    for engine, color in (("mbjax", COLORS["rkmk4"]), ("mujoco", COLORS["mujoco"])):
        rows = sorted((r for r in batched if r["engine"] == engine and r["dt"] == 2e-3),
                      key=lambda r: r["batch"])
        if rows:
            ax_batch.loglog([r["batch"] for r in rows], [r["steps_per_s"] for r in rows],
                            marker="o", color=color, label=f"{engine} {rows[0]['integrator']}")
    ax_batch.set(xlabel="batch size", ylabel="body-steps per second",
                 title="batched rollouts, dt = 2 ms (CPU)")
    for ax in (ax_wp, ax_batch):
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    return fig


TFE_COLORS = {"2": "#8c564b", "3": "#e377c2", "4": "#17becf"}
TFE_STYLES = {"primal": "-", "mixed": "--"}


def tfe_bench_figure(records: list[dict]) -> Figure:
    """Rotation error at the end against run time, one panel per scene: time elements (primal
    solid, mixed dashed, one colour per node count) and the step-by-step integrators."""
    scenes = list(dict.fromkeys(r["scene"] for r in records))
    fig = Figure(figsize=(6.5 * len(scenes), 5), layout="constrained")
    for ax, scene in zip(np.atleast_1d(fig.subplots(1, len(scenes))), scenes):
        rows = [r for r in records if r["scene"] == scene]
        for method in dict.fromkeys(r["method"] for r in rows):
            line = [r for r in rows if r["method"] == method]
            err = np.array([r["error"] for r in line])
            ok = np.isfinite(err) & (err < 3.0)
            first = line[0]
            if first["family"] == "tfe":
                kw = dict(color=TFE_COLORS[str(first["nodes"])], ls=TFE_STYLES[first["form"]],
                          marker="o" if first["form"] == "primal" else "s", mfc="none")
            else:
                kw = dict(color=COLORS[method], marker=MARKERS[method], ls=":")
            ax.loglog(np.array([r["run_s"] for r in line])[ok], err[ok], label=method, **kw)
        ax.set(xlabel=f"run time for {rows[0]['duration']:g} s [s]",
               ylabel="rotation error at the end [rad]",
               title=f"{scene}: speed against accuracy (failed runs omitted)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, ncol=2)
    return fig


def loops_bench_figure(records: list[dict]) -> Figure:
    """`mbjax bench loops`: (a) error against run time per route on the 12-dof closed chain;
    (b) run time of 1 s of simulation against n, O(n + m^3) against the dense route."""
    fig = Figure(figsize=(12, 4.6), layout="constrained")
    ax_w, ax_s = fig.subplots(1, 2)
    wp = [r for r in records if r["kind"] == "work-precision"]
    for route in dict.fromkeys(r["route"] for r in wp):
        rows = [r for r in wp if r["route"] == route]
        ax_w.loglog([r["run_s"] for r in rows], [r["error"] for r in rows], "o-", label=route)
    ax_w.set(xlabel="run time [s]", ylabel="max joint-angle error [rad]",
             title="(a) closed chain, 12 dof, 1 s, RK4")
    sc = [r for r in records if r["kind"] == "scaling"]
    for route in dict.fromkeys(r["route"] for r in sc):
        rows = [r for r in sc if r["route"] == route]
        ax_s.loglog([r["n"] for r in rows], [r["run_s_per_simulated_s"] for r in rows], "o-",
                    label=route)
    ax_s.set(xlabel="n (tree degrees of freedom)", ylabel="run time per simulated second [s]",
             title="(b) scaling (Anderson 1993 Fig. 8)")
    for ax in (ax_w, ax_s):
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    return fig


CEILING = 3.0   # m: errors above are drawn here (marked ^) with their value


def flexible_bench_figure(records: list[dict]) -> Figure:
    """`mbjax bench flexible`: the history's largest error against run time, (a) Kane's spin-up
    beam (tip deflection [m]), (b) the flexible slider-crank (midpoint deflection [in]). Modal
    models: one line per bending-mode or element count with RK4 (circles), the simplified implicit
    midpoint (diamonds), open markers without geometric stiffening; squares mbjax's ANCF beams (the
    reference a vertical line: its error is zero by definition); crosses exudyn's ANCF cable. The
    dashed horizontal line is the scene's tolerance; each point is labelled with its step (and its
    status where it is not success)."""
    fig = Figure(figsize=(13, 5.2), layout="constrained")
    axes = fig.subplots(1, 2)
    palette = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b")

    def pos(v):
        return v is not None and np.isfinite(v) and v > 0

    def label_steps(ax, rows, color):
        for r in rows:
            status = "" if r.get("status", "success") == "success" else f" ({r['status']})"
            ax.annotate(f"{r['dt']:.2g}{status}", (r["run_s"], r["error"]),
                        textcoords="offset points", xytext=(4, 3), fontsize=6, color=color)

    for ax, (scene, unit, what, tolerance) in zip(axes, (
            ("spin-up", "m", "tip deflection", 1e-3),
            ("slider-crank", "in", "midpoint deflection", 0.01))):
        rows = [r for r in records if r.get("scene", "spin-up") == scene]
        if not rows:
            ax.set_visible(False)
            continue
        modal = [r for r in rows if r["kind"] == "modal"]
        key = "n_bending" if scene == "spin-up" else "n_elements"
        colors = dict(zip(sorted({r[key] for r in modal}), palette))
        for value, color in colors.items():
            for integrator, marker in (("rk4", "o-"), ("implicit", "D-")):
                line = sorted((r for r in modal if r[key] == value and r["stiffening"]
                               and r.get("integrator", "rk4").startswith(integrator)
                               and pos(r["error"])), key=lambda r: r["run_s"])
                if line:
                    name = (f"{value} bending + 1 axial" if scene == "spin-up" else f"{value} el")
                    ax.loglog([r["run_s"] for r in line], [r["error"] for r in line], marker,
                              color=color, ms=5,
                              label=f"modal, {name}, {'RK4' if integrator == 'rk4' else 'implicit midpoint'}")
                    label_steps(ax, line, color)
            for r in (r for r in modal if r[key] == value and not r["stiffening"]):
                if pos(r["error"]):   # diverged runs (errors up to 1e20 m) drawn at the ceiling
                    ax.loglog(r["run_s"], min(r["error"], CEILING), "^" if r["error"] > CEILING else "o",
                              mfc="none", ms=10, color=color,
                              label=f"modal, {value} bending + 1 axial, no stiffening")
                    ax.annotate(f"{r['error']:.2g} {unit}", (r["run_s"], min(r["error"], CEILING)),
                                textcoords="offset points", xytext=(8, -4), fontsize=7, color=color)
        for r in (r for r in rows if r["kind"] == "ancf"):
            if r.get("reference") and r["run_s"] > 0:
                ax.axvline(r["run_s"], color="k", ls=":",
                           label=f"ANCF {r['n_elements']} el (reference), {r['run_s']:.3g} s")
            elif pos(r.get("error")):
                ax.loglog(r["run_s"], r["error"], "ks", label=f"ANCF {r['n_elements']} el (mbjax)")
        peer = sorted((r for r in rows if r["kind"] == "peer" and pos(r.get("error"))),
                      key=lambda r: r["run_s"])
        if peer:
            ax.loglog([r["run_s"] for r in peer], [r["error"] for r in peer], "x--", color="0.35",
                      ms=8, label=f"exudyn ANCF cable {peer[0]['n_elements']} el, generalized-alpha")
            label_steps(ax, peer, "0.35")
        ax.axhline(tolerance, color="0.6", ls="--", lw=0.8, label=f"tolerance {tolerance:g} {unit}")
        duration = rows[0]["duration"]
        ax.set(xlabel=f"run time for {duration:g} s, compilation apart [s]",
               ylabel=f"max |{what} - reference| over the history [{unit}]",
               title=f"{scene}, 0-{duration:g} s: speed against accuracy")
        if scene == "spin-up":
            ax.set_ylim(top=2 * CEILING)
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6.5)
    fig.suptitle("run times are medians of a few calls on a shared machine: differences under "
                 "about 20 % are noise", fontsize=8, color="0.4")
    return fig


def wrist_bench_figure(records: list[dict]) -> Figure:
    """`mbjax bench wrist`: (a) RK4 error against run time, (b) time per call and per batched
    state of each dynamics route, (c) sweep time per variant of each layout."""
    fig = Figure(figsize=(14, 4.6), layout="constrained")
    ax_wp, ax_routes, ax_sweep = fig.subplots(1, 3)
    wp = [r for r in records if r["kind"] == "work-precision"]
    ax_wp.loglog([r["run_s"] for r in wp], [max(r["error"], 1e-16) for r in wp], "o-",
                 color=COLORS["rk4"], label="RK4")
    for r in wp:
        ax_wp.annotate(f"{r['dt'] * 1e3:g} ms", (r["run_s"], max(r["error"], 1e-16)), fontsize=7)
    ax_wp.set(xlabel="run time [s]", ylabel="max joint-angle error [rad]",
              title=f"torque-free tool, {wp[0]['duration']} s")
    ax_wp.legend()
    routes = [r for r in records if r["kind"] == "route"]
    y = np.arange(len(routes))
    ax_routes.barh(y - 0.2, [r["run_s"] * 1e6 for r in routes], 0.4, label="one call")
    ax_routes.barh(y + 0.2, [r["batch_us_per_state"] for r in routes], 0.4,
                   label=f"per state, batch of {routes[0]['batch']}")
    ax_routes.set_yticks(y, [r["route"] for r in routes], fontsize=8)
    ax_routes.set_xscale("log")
    ax_routes.set(xlabel="us", title="dynamics routes (jit, CPU)")
    ax_routes.legend(fontsize=8)
    sw = [r for r in records if r["kind"] == "sweep"]
    ax_sweep.bar([r["layout"] for r in sw], [r["us_per_variant"] for r in sw])
    ax_sweep.set(ylabel="us per variant", title=f"peak-torque sweep, {sw[0]['variants']} variants")
    return fig


def throughput_figure(records: list[dict]) -> Figure:
    """`mbjax bench throughput`: forward dynamics per state against batch size (every engine, every
    chain size), rollout steps per second against batch size, the rollout gradient's memory
    against the number of steps, and float32's accuracy."""
    fig = Figure(figsize=(13, 9), layout="constrained")
    (ax_fd, ax_roll), (ax_mem, ax_acc) = fig.subplots(2, 2)
    forward = [r for r in records if r["kind"] == "forward"]
    ns = sorted({r["n"] for r in forward})
    styles = {7: "-", 30: "--", 100: ":"}
    series = (("mbjax", "batch_aba", "float64", COLORS.get("rk4", "C0"), "mbjax batch_aba"),
              ("mbjax", "vmap sharded", "float64", "C5", "mbjax jit(vmap), one device per core"),
              ("mbjax", "batch_aba", "float32", "C2", "mbjax batch_aba float32"),
              ("mbjax", "vmap", "float64", "C1", "mbjax jit(vmap(forward_dynamics))"),
              ("pinocchio", "abaInParallel", "float64", "C3", "Pinocchio abaInParallel"))
    for n in ns:
        ls = styles.get(n, "-.")
        for engine, method, dtype, color, label in series:
            rows = sorted((r for r in forward if r["n"] == n and r["engine"] == engine
                           and r["method"] == method and r["dtype"] == dtype), key=lambda r: r["batch"])
            if rows:
                ax_fd.loglog([r["batch"] for r in rows], [r["per_state_s"] * 1e6 for r in rows],
                             ls=ls, color=color, marker="o", ms=3,
                             label=f"{label}" if n == ns[0] else None)
        pin = [r for r in forward if r["n"] == n and r["engine"] == "pinocchio" and r["method"] == "aba"]
        if pin:
            ax_fd.axhline(pin[0]["per_state_s"] * 1e6, color=COLORS.get("mujoco", "grey"), ls=ls,
                          lw=1, label="Pinocchio aba per call from Python" if n == ns[0] else None)
        ax_fd.annotate(f"n = {n}", (1, min(r["per_state_s"] for r in forward if r["n"] == n) * 1e6),
                       fontsize=8)
    ax_fd.set(xlabel="batch size B", ylabel="time per state [us]",
              title="forward dynamics of n-link chains (solid 7, dashed 30, dotted 100)")
    ax_fd.legend(fontsize=7)

    rollout = [r for r in records if r["kind"] == "rollout"]
    for engine, color, label in (("mbjax", COLORS.get("rk4", "C0"), "mbjax simulate, lax.map over chunks"),
                                 ("mujoco", COLORS.get("mujoco", "grey"), "mujoco.rollout"),
                                 ("mjx", "C4", "MJX jit(vmap)")):
        for n in sorted({r["n"] for r in rollout}):
            rows = sorted((r for r in rollout if r["engine"] == engine and r["n"] == n),
                          key=lambda r: r["batch"])
            if rows:
                ax_roll.loglog([r["batch"] for r in rows], [r["steps_per_s"] for r in rows],
                               ls=styles.get(n, "-."), color=color, marker="o" if len(rows) > 1 else "*",
                               ms=4 if len(rows) > 1 else 12, label=label if n == 7 else None)
    ax_roll.set(xlabel="batch size B", ylabel="RK4 steps per second (B x steps / run time)",
                title="rollouts, dt = 1 ms (solid 7, dashed 30, dotted 100 links)")
    ax_roll.legend(fontsize=7)

    for r in (r for r in records if r["kind"] == "gradient"):
        label = ("jax.jacfwd" if r.get("mode") == "jacfwd" else
                 "jax.grad, checkpoint=True" if r["checkpoint"] else "jax.grad, plain")
        ax_mem.loglog(r["memory_steps"], np.array(r["grad_temp_bytes"]) / 1e6, marker="o",
                      label=f"{label} (slope {r['memory_slope']:.2f}; "
                            f"{r['grad_over_forward']:.1f}x forward time)")
        if r.get("mode") == "grad" and not r["checkpoint"]:
            ax_mem.loglog(r["memory_steps"], np.array(r["forward_temp_bytes"]) / 1e6, marker="s",
                          color="grey", label="forward rollout")
    ax_mem.set(xlabel="rollout steps T", ylabel="XLA temporary memory [MB]",
               title="gradient of sum q(T)^2 through an RK4 rollout (7 links)")
    ax_mem.legend(fontsize=7)

    for dtype, key, color in (("float32", "rel_diff_float64", "C2"),
                              ("float64", "rel_diff_pinocchio", COLORS.get("rk4", "C0"))):
        rows = [r for r in forward if r["engine"] == "mbjax" and r["method"] == "batch_aba"
                and r["dtype"] == dtype and key in r]
        by_n = {n: max(r[key] for r in rows if r["n"] == n) for n in sorted({r["n"] for r in rows})}
        if by_n:
            ax_acc.semilogy(list(by_n), list(by_n.values()), marker="o", color=color,
                            label=f"batch_aba {dtype}: " + ("against float64" if dtype == "float32"
                                                            else "against Pinocchio"))
    ax_acc.set(xlabel="links n", ylabel="max |a - a_ref| / max |a_ref|",
               title="accuracy of the accelerations")
    ax_acc.legend(fontsize=7)
    return fig


def trajopt_bench_figure(records: list[dict]) -> Figure:
    """`mbjax bench trajopt`: per problem, each engine's cost above the better optimum against
    the iteration's share of its solve time; then the many-targets and the sweep's times."""
    singles = [r for r in records if r["kind"] == "single" and "skipped" not in r]
    problems = list(dict.fromkeys(r["problem"] for r in singles))
    ncols = min(len(problems) + 2, 4)
    nrows = -(-(len(problems) + 2) // ncols)
    fig = Figure(figsize=(5.2 * ncols, 4.2 * nrows), layout="constrained")
    axes = fig.subplots(nrows, ncols, squeeze=False).ravel()
    for ax in axes[len(problems) + 2:]:
        ax.set_axis_off()
    style = {"mbjax": ("#1f77b4", "o"), "crocoddyl": ("#d62728", "s")}
    for ax, problem in zip(axes, problems, strict=False):
        for r in (r for r in singles if r["problem"] == problem):
            costs = np.asarray(r["history"])
            gap = np.maximum((costs - r["best_cost"]) / abs(r["best_cost"]), 1e-12)
            t = np.arange(len(costs)) * r["seconds"] / max(len(costs) - 1, 1)
            color, marker = style.get(r["engine"], ("k", "x"))
            ax.loglog(np.maximum(t, 1e-4), gap, color=color, marker=marker, ms=3,
                      markevery=max(len(costs) // 12, 1),
                      label=f"{r['engine']} {r['solver']}: {r['iterations']} it, "
                            f"{r['seconds'] * 1e3:.0f} ms; "
                            + (f"to 1e-6 {r['seconds_to_tolerance'] * 1e3:.0f} ms"
                               if r["seconds_to_tolerance"] is not None
                               else "stops short of 1e-6"))
        ax.axhline(1e-6, color="0.5", lw=0.8, ls="--")
        ax.set(xlabel="time [s] (each iteration its share of the solve)",
               ylabel="(cost - best) / best", title=problem)
        ax.legend(fontsize=7)
    ax = axes[len(problems)]
    many = [r for r in records if r["kind"] == "many" and "skipped" not in r]
    labels = [f"{r['engine']}\n{r['how']}" for r in many]
    ax.bar(range(len(many)), [r["seconds"] for r in many],
           color=[style.get(r["engine"], ("k", "x"))[0] for r in many])
    ax.set_xticks(range(len(many)), labels, fontsize=7)
    for i, r in enumerate(many):
        ax.annotate(f"{r['seconds']:.2f} s\n{r['converged']}/{r['targets']} converged",
                    (i, r["seconds"]), ha="center", va="bottom", fontsize=7)
    if many:
        ax.set_ylim(0, 1.2 * max(r["seconds"] for r in many))
    ax.set(ylabel="wall time [s]", title=f"arm-reach, {many[0]['targets'] if many else 0} targets")
    ax = axes[len(problems) + 1]
    sweep = [r for r in records if r["kind"] == "sweep" and "skipped" not in r]
    ax.bar(range(len(sweep)), [r["seconds"] for r in sweep],
           color=[style.get(r["engine"], ("k", "x"))[0] for r in sweep])
    ax.set_xticks(range(len(sweep)), [f"{r['engine']}\n{r['how']}" for r in sweep], fontsize=7)
    for i, r in enumerate(sweep):
        ax.annotate(f"{r['seconds']:.2f} s\n{r['converged']}/{r['variants']} converged",
                    (i, r["seconds"]), ha="center", va="bottom", fontsize=7)
    if sweep:
        ax.set_ylim(0, 1.2 * max(r["seconds"] for r in sweep))
    ax.set(ylabel="wall time [s]",
           title=f"acrobot swing-up, {sweep[0]['variants'] if sweep else 0} mass variants")
    return fig


def accuracy_bench_figure(records: list[dict]) -> Figure:
    """Left: each case's final error against the default check's resolution, at the step that
    fails (filled: flagged by default) and at the step that resolves it. Right: the 7-link
    chain's rollout, simulate (status and default check) against the bare loop."""
    fig = Figure(figsize=(12, 5), layout="constrained")
    ax_cases, ax_cost = fig.subplots(1, 2, width_ratios=(2, 1))
    cases = [r for r in records if r["kind"] == "case" and r["resolution"] is not None]
    for k, name in enumerate(dict.fromkeys(r["case"] for r in cases)):
        color = f"C{k % 10}"
        for r in (r for r in cases if r["case"] == name):
            error = r["error"] if r["error"] is not None else 1e3
            ax_cases.loglog(max(r["resolution"], 1e-3), max(error, 1e-12),
                            marker="o" if r["ok"] else "s", ms=8, color=color,
                            mfc="none" if r["ok"] else color,
                            label=name if r["dt"] == max(c["dt"] for c in cases
                                                         if c["case"] == name) else None)
    ax_cases.axvline(1.0, color="k", lw=0.8, ls="--")
    ax_cases.set(xlabel="resolution: step x the motion's rate (default check, limit 1)",
                 ylabel="final error (1e3: diverged)",
                 title="default check: filled = flagged INACCURATE, hollow = success")
    ax_cases.legend(fontsize=7)
    cost = [r for r in records if r["kind"] == "cost"]
    names = [r["variant"] for r in cost]
    x = np.arange(len(names))
    ax_cost.bar(x - 0.2, [r["first_call_s"] for r in cost], 0.4, label="first call [s]")
    ax_cost.bar(x + 0.2, [r["warm_s"] * 1e3 for r in cost], 0.4, label="warm call [ms]")
    ax_cost.set_xticks(x, names)
    ax_cost.set(title="7-link chain, RK4, 200 steps")
    for ax in (ax_cases, ax_cost):
        ax.grid(True, which="both", alpha=0.3)
    ax_cost.legend(fontsize=8)
    return fig
