"""The figure of `mbjax reproduce integrators`."""

import numpy as np

from mbjax_harness.plot.style import COLORS, MARKERS, Figure, label


def integrators_figure(data: dict, energy_histories: dict, energy_dt: float) -> Figure:
    """(a) work-precision, (b) error against step with fitted orders, (c) heavy-top energy drift
    against step, (d) heavy-top energy history at one step."""
    fig = Figure(figsize=(12, 9), layout="constrained")
    (ax_wp, ax_order), (ax_drift, ax_hist) = fig.subplots(2, 2)
    names = list(data["expected_orders"])
    for name in names:
        rows = [r for r in data["results"] if r["integrator"] == name and np.isfinite(r["error"])]
        err = np.array([r["error"] for r in rows])
        kw = dict(color=COLORS[name], marker=MARKERS[name])
        ax_wp.loglog([r["seconds"] for r in rows], err, label=label(name), **kw)
        order = data["orders"][name]
        tag = f"{label(name)} (order {order:.2f})" if order is not None else label(name)
        ax_order.loglog([r["dt"] for r in rows], err, label=tag, **kw)
        top = [r for r in data["heavy_top"]["results"] if r["integrator"] == name]
        drift = np.array([r["energy_drift"] if r["stable"] else np.nan for r in top])
        ax_drift.loglog([r["dt"] for r in top], drift, label=label(name), **kw)
        ts, rel = energy_histories[name]
        ax_hist.semilogy(ts, np.maximum(np.abs(rel), 1e-17), color=COLORS[name], label=label(name))
    ax_wp.set(xlabel="run time [s]", ylabel="rotation error at 6 s [rad]",
              title="(a) torque-free body: work-precision")
    ax_order.set(xlabel="step dt [s]", ylabel="rotation error at 6 s [rad]",
                 title="(b) convergence (slopes fitted in the asymptotic range)")
    limit = data["heavy_top"]["rk4_stability_limit_dt"]
    ax_drift.axvline(limit, color=COLORS["rk4"], ls=":", label=f"RK4 unstable beyond {limit:.3g} s")
    ax_drift.set(xlabel="step dt [s]", ylabel="max |E - E0| / E0 over 10 s",
                 title="(c) heavy top: energy drift (unstable runs omitted)")
    ax_hist.set(xlabel="t [s]", ylabel="|E / E0 - 1|", ylim=(1e-17, 1e3),
                title=f"(d) heavy top: energy error history, dt = {energy_dt * 1e3:g} ms")
    for ax in (ax_wp, ax_order, ax_drift, ax_hist):
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    return fig
