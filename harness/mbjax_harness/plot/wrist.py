"""Figures of the Carpal Wrist: integrator accuracy and stability, synthesized torques, sweeps."""

import numpy as np

from mbjax_harness.plot.style import COLORS, MARKERS, Figure, label


def _integrator_panels(ax_err, ax_stab, rows: list, critical: dict, seconds: dict | None = None):
    """(a) error against step (with run time per step in the legend), (b) the stability map with
    the critical steps predicted by the linearization."""
    names = list(dict.fromkeys(r["name"] for r in rows))
    for k, name in enumerate(names):
        mine = [r for r in rows if r["name"] == name]
        ok = [r for r in mine if r["error"] is not None]
        text = label(name) + (f" ({seconds[name] * 1e6:.0f} us/step)" if seconds else "")
        ax_err.loglog([r["dt"] for r in ok], [max(r["error"], 1e-16) for r in ok], marker=MARKERS[name],
                      color=COLORS[name], label=text)
        for r in mine:
            ax_stab.scatter(r["dt"], k, marker="o" if r["stable"] else "x", s=60,
                            color=COLORS[name] if r["stable"] else "k")
        crit = critical.get(name)
        if crit is not None:
            ax_stab.plot([crit, crit], [k - 0.35, k + 0.35], color=COLORS[name], lw=3)
    ax_err.set(xlabel="dt [s]", ylabel="max joint-angle error [rad]",
               title="torque-free, gravity-free motion: error after 0.4 s")
    ax_err.legend(fontsize=8)
    ax_stab.set_xscale("log")
    ax_stab.set_yticks(range(len(names)), [label(n) for n in names])
    ax_stab.set(xlabel="dt [s]", title="servoed wrist under gravity: o stable, x unstable;\n"
                "bars: critical dt of the linearization")


def integrator_figure(rows: list, critical: dict, seconds: dict) -> Figure:
    """The tour's Carpal Wrist figure: accuracy and stability of each integrator against dt."""
    fig = Figure(figsize=(13, 4.8), layout="constrained")
    _integrator_panels(*fig.subplots(1, 2), rows, critical, seconds)
    return fig


def carpal_wrist_figure(result: dict, curves: dict) -> Figure:
    """`mbjax reproduce carpal-wrist`: (a) error against step, (b) stability map with the
    predicted critical steps, (c) synthesized and baseline torques, (d) the descent."""
    fig = Figure(figsize=(13, 9.5), layout="constrained")
    ax = fig.subplots(2, 2)
    _integrator_panels(ax[0, 0], ax[0, 1], result["integrators"], result["critical_dt"])
    t = curves["t"]
    for i in range(3):
        ax[1, 0].plot(t, curves["tau_ff"][:, i], "--", color=f"C{i}", label=f"feed-forward, motor {i + 1}")
        ax[1, 0].plot(t, curves["tau_syn"][:, i], "-", color=f"C{i}", label=f"synthesized, motor {i + 1}")
    lim = result["torque_limit"]
    ax[1, 0].axhspan(lim, max(lim * 1.3, np.max(np.abs(curves["tau_ff"])) * 1.05), color="0.9")
    ax[1, 0].axhspan(-lim * 1.3 if np.min(curves["tau_ff"]) > -lim else np.min(curves["tau_ff"]) * 1.05,
                     -lim, color="0.9")
    ax[1, 0].set(xlabel="t [s]", ylabel="motor torque [N m]",
                 title=f"START -> GOAL in {result['duration']} s, |tau| <= {lim} N m (grey: beyond)")
    ax[1, 0].legend(fontsize=7, ncol=2)
    ax[1, 1].semilogy(result["trajectory"]["losses"])
    tr, bl = result["trajectory"], result["baseline"]
    ax[1, 1].set(xlabel="Adam iteration", ylabel="objective",
                 title=f"descent: pose error {bl['pose_error_clipped']:.2g} (clipped baseline) -> "
                       f"{tr['final_pose_error']:.2g};\neffort {bl['effort']:.3g} (baseline) vs "
                       f"{tr['effort']:.3g} N^2 m^2 s")
    return fig


def sweep_figure(peak: np.ndarray, x: np.ndarray, y: np.ndarray, xlabel: str, ylabel: str, title: str) -> Figure:
    """A map of peak motor torque over a 2-D slice of a parameter sweep."""
    fig = Figure(figsize=(6.5, 5), layout="constrained")
    ax = fig.subplots()
    im = ax.pcolormesh(x, y, peak.T, shading="auto", cmap="viridis")
    cs = ax.contour(x, y, peak.T, colors="w", linewidths=0.8)
    ax.clabel(cs, fontsize=7)
    fig.colorbar(im, ax=ax, label="peak |motor torque| [N m]")
    ax.set(xlabel=xlabel, ylabel=ylabel, title=title)
    return fig
