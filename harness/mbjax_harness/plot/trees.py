"""Figures of rigid-body trees: `mbjax bench rigid`, `mbjax reproduce tree-scaling` and the
tour's rigid chain."""

import numpy as np

from mbjax_harness.plot.style import COLORS, MARKERS, Figure, label

# One colour per formulation or peer, in every tree figure.
TREE_COLORS = {"recursive": "#1f77b4", "dense": "#d62728", "pinocchio": "#2ca02c",
               "mujoco": COLORS["mujoco"]}


def _guide(ax, ns, anchor_n, anchor_t, slope: int, **kw) -> None:
    """A dotted line t ~ n^slope through (anchor_n, anchor_t)."""
    ns = np.asarray(ns, dtype=float)
    ax.loglog(ns, anchor_t * (ns / anchor_n) ** slope, ls=":", lw=1, **kw)


def rigid_bench_figure(records: list[dict]) -> Figure:
    """(a) time per state against n, one state per call, mbjax and peers; (b) batched time per
    state against n for each B; (c) compile time against n; (d) the crossover at small n, one
    state per call and per evaluation inside a jitted loop."""
    fig = Figure(figsize=(13, 10), layout="constrained")
    (ax_single, ax_batch), (ax_compile, ax_cross) = fig.subplots(2, 2)
    fwd = [r for r in records if r["kind"] == "forward" and "per_state_s" in r]
    single = [r for r in fwd if r["engine"] == "mbjax" and r["batch"] == 0]
    peer_ns = sorted({r["n"] for r in fwd if r["engine"] != "mbjax"})
    main_ns = peer_ns or sorted({r["n"] for r in single})

    def series(rows, key="per_state_s", ns=None):
        rows = sorted((r for r in rows if ns is None or r["n"] in ns), key=lambda r: r["n"])
        return [r["n"] for r in rows], [r[key] for r in rows]

    for method in ("recursive", "dense"):
        rows = [r for r in single if r["method"] == method]
        ax_single.loglog(*series(rows, ns=main_ns), marker="o", color=TREE_COLORS[method],
                         label=f"mbjax {method} (jit, 1 state)")
        looped = [r for r in records if r["kind"] == "looped" and r["method"] == method]
        ax_single.loglog(*series(looped, key="per_eval_s", ns=main_ns), marker="^", ls="--",
                         mfc="none", color=TREE_COLORS[method],
                         label=f"mbjax {method}, per evaluation in a jitted loop")
        ax_compile.semilogx(*series(rows, key="compile_s"), marker="o", color=TREE_COLORS[method],
                            label=f"mbjax {method}: first call minus a typical call")
        if all("lower_compile_s" in r for r in rows):
            ax_compile.semilogx(*series(rows, key="lower_compile_s"), marker="s", ls="--",
                                mfc="none", color=TREE_COLORS[method],
                                label=f"mbjax {method}: lower + compile ahead of time")
        ax_cross.loglog(*series([r for r in rows if r["n"] <= 100]), marker="o",
                        color=TREE_COLORS[method], label=f"mbjax {method}")
    for engine, method in (("pinocchio", "aba"), ("mujoco", "mj_forward")):
        rows = [r for r in fwd if r["engine"] == engine]
        if rows:
            ax_single.loglog(*series(rows), marker="s", color=TREE_COLORS[engine],
                             label=f"{engine} {method} (Python loop)")
            ax_single.loglog(*series(rows, key="cpp_estimate_s"), marker="s", ls="--",
                             mfc="none", color=TREE_COLORS[engine],
                             label=f"{engine} {method}, loop overhead removed")
    for method, slope, color in (("recursive", 1, "k"), ("dense", 3, "grey")):
        last = max((r for r in records if r["kind"] == "looped" and r["method"] == method
                    and r["n"] in main_ns), key=lambda r: r["n"], default=None)
        if last is not None:
            ns = [n for n in main_ns if n >= 10] or main_ns
            _guide(ax_single, ns, last["n"], last["per_eval_s"], slope, color=color,
                   label=f"slope {slope}")
    ax_single.set(xlabel="links n", ylabel="time per state [s]",
                  title="(a) forward dynamics, one state: per call and in a loop",
                  ylim=(0.3 * min(r[key] for r in records for key in
                                  ("per_state_s", "cpp_estimate_s", "per_eval_s")
                                  if r.get(key, 0) > 0 and r["n"] in main_ns), None))

    batched = [r for r in fwd if r["engine"] == "mbjax" and r["batch"] > 0]
    batches = sorted({r["batch"] for r in batched})
    shades = np.linspace(0.35, 1.0, max(len(batches), 1))
    for batch, shade in zip(batches, shades, strict=True):
        for method, ls in (("recursive", "-"), ("dense", "--")):
            rows = [r for r in batched if r["method"] == method and r["batch"] == batch]
            if rows:
                ax_batch.loglog(*series(rows), marker="o", ls=ls, alpha=shade,
                                color=TREE_COLORS[method], label=f"{method}, B = {batch}")
    ax_batch.set(xlabel="links n", ylabel="time per state [s]",
                 title="(b) jit(vmap(...)) over B states (dense only where it fits)")
    ax_compile.set(xlabel="links n", ylabel="compile time [s]", ylim=(0, None),
                   title="(c) compile time against n")

    for method in ("recursive", "dense"):
        rows = [r for r in records if r["kind"] == "looped" and r["method"] == method and r["n"] <= 100]
        if rows:
            ax_cross.loglog(*series(rows, key="per_eval_s"), marker="^", ls="--", mfc="none",
                            color=TREE_COLORS[method], label=f"mbjax {method}, per evaluation in a loop")
    summary = next((r for r in records if r["kind"] == "summary"), None)
    for key, ls, text in (("crossover_nv", ":", "recursive faster from n = {} (per call)"),
                          ("crossover_nv_looped", "-.", "recursive faster from n = {} (in a loop)"),
                          ("crossover_nv_auto", "--", "method='auto' switches at n = {}")):
        if summary and summary.get(key) is not None:
            ax_cross.axvline(summary[key], color="k", ls=ls, lw=1, label=text.format(summary[key]))
    grads = [r for r in records if r["kind"] == "gradient"]
    note = "\n".join(f"grad / forward, {r['steps']}-step RK4 rollout, {r['n']} links, {r['method']}: "
                     f"{r['grad_over_forward']:.2f}" for r in grads)
    if note:
        ax_cross.text(0.02, 0.02, note, transform=ax_cross.transAxes, va="bottom", fontsize=7)
    ax_cross.set(xlabel="links n", ylabel="time per call [s]",
                 title="(d) the crossover: one call, and inside a jitted loop")
    for ax in (ax_single, ax_batch, ax_compile, ax_cross):
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, loc="best")
    return fig


def tree_scaling_figure(data: dict) -> Figure:
    """CPU time of one forward-dynamics evaluation against n, log-log, with slope-1 and slope-3
    guides (Anderson 1993 Fig. 8)."""
    fig = Figure(figsize=(7, 5.5), layout="constrained")
    ax = fig.subplots()
    ns = np.asarray(data["n"], dtype=float)
    series = (("recursive_s", "recursive", "mbjax recursive, O(n) (Anderson 1993)"),
              ("dense_s", "dense", "mbjax dense, O(n^3) (Jerkovsky 1978 + Cholesky)"),
              ("pinocchio_aba_s", "pinocchio", "Pinocchio aba (from Python)"))
    for key, color, text in series:
        if key in data:
            ax.loglog(ns, data[key], marker="o", color=TREE_COLORS[color], label=text)
    _guide(ax, ns, ns[-1], data["recursive_s"][-1], 1, color="k", label="slope 1")
    _guide(ax, ns, ns[-1], data["dense_s"][-1], 3, color="grey", label="slope 3")
    ax.set(xlabel="degrees of freedom n (n-link revolute chain)",
           ylabel="CPU time of one evaluation [s]",
           title="forward dynamics against n (cf. Anderson 1993 Fig. 8)",
           ylim=(0.3 * min(min(data[k]) for k, _, _ in series if k in data), None))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def rigid_chain_figure(snapshots, runs: dict, title: str) -> Figure:
    """(a) the chain at a few times (side view, x-z), (b) error at the end against run time,
    (c) largest relative energy error against run time; one line per integrator, one point per
    step size. `snapshots` is [(t, points (n + 1, 3))]; `runs[name]` a list of dicts with
    "dt", "seconds", "error" and "energy_error"."""
    fig = Figure(figsize=(15, 4.8), layout="constrained")
    ax_chain, ax_err, ax_energy = fig.subplots(1, 3)
    shades = np.linspace(0.25, 1.0, len(snapshots))
    for (t, points), shade in zip(snapshots, shades, strict=True):
        ax_chain.plot(points[:, 0], points[:, 2], marker="o", ms=3, color="k", alpha=shade,
                      label=f"t = {t:g} s")
    ax_chain.set(xlabel="x [m]", ylabel="z [m]", aspect="equal", title="reference motion (side view)")
    for name, rows in runs.items():
        kw = {"color": COLORS[name], "marker": MARKERS[name], "label": label(name)}
        seconds = [r["seconds"] for r in rows]
        ax_err.loglog(seconds, [max(r["error"], 1e-16) for r in rows], **kw)
        ax_energy.loglog(seconds, [max(r["energy_error"], 1e-17) for r in rows], **kw)
        for r in rows:
            ax_err.annotate(f"{r['dt'] * 1e3:g} ms", (r["seconds"], max(r["error"], 1e-16)),
                            fontsize=6, xytext=(3, 3), textcoords="offset points")
    ax_err.set(xlabel="run time [s]", ylabel="max |q - q_ref| at the end [rad]",
               title="speed against accuracy (labels: step)")
    ax_energy.set(xlabel="run time [s]", ylabel="max |E / E0 - 1|", title="energy error")
    for ax in (ax_chain, ax_err, ax_energy):
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(title)
    return fig
