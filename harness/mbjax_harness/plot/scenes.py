"""Figures of the tour's scenes."""

import numpy as np

from mbjax_harness.plot.style import COLORS, Figure, label, note_in


def error_history_figure(histories: dict, title: str) -> Figure:
    """Error against time, one line per integrator."""
    fig = Figure(figsize=(8, 5), layout="constrained")
    ax = fig.subplots()
    for name, (ts, err) in histories.items():
        ax.semilogy(ts, np.maximum(err, 1e-17), color=COLORS[name], label=label(name))
    ax.set(xlabel="t [s]", ylabel="error [rad]", title=title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def heavy_top_figure(runs: dict, title: str) -> Figure:
    """Left: the tip of the symmetry axis seen from above, for the runs that keep the energy to
    1e-3 (diverging runs would hide the nutation). Right: |E/E0 - 1| against time, every run."""
    fig = Figure(figsize=(12, 5), layout="constrained")
    ax_path, ax_energy = fig.subplots(1, 2)
    for name, (ts, axis, rel) in runs.items():
        if np.all(np.abs(rel) < 1e-3):
            ax_path.plot(axis[:, 0], axis[:, 1], color=COLORS[name], lw=0.8, label=label(name))
        ax_energy.semilogy(ts, np.maximum(np.abs(rel), 1e-17), color=COLORS[name],
                           label=label(name))
    ax_path.set(xlabel="x", ylabel="y", title="tip of the symmetry axis (top view; runs with |dE/E| < 1e-3)",
                aspect="equal")
    ax_energy.set(xlabel="t [s]", ylabel="|E / E0 - 1|", ylim=(1e-17, 1e3), title="energy error")
    for ax in (ax_path, ax_energy):
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(title)
    return fig


def controls_figure(ts, dq, displacement, checks: dict, title: str) -> Figure:
    """(a) joint angles of the pushed arm about its pose; (b) the flange's displacement from the
    unpushed run; (c) jax.grad against central differences."""
    fig = Figure(figsize=(14, 4.2), layout="constrained")
    ax_q, ax_f, ax_g = fig.subplots(1, 3, width_ratios=(1, 1, 0.8))
    for j in range(dq.shape[1]):
        ax_q.plot(ts, dq[:, j], lw=1, label=f"joint {j + 1}")
    ax_q.set(xlabel="t [s]", ylabel="q - q_ref [rad]", title="pushed at the flange for 0.1 s")
    ax_q.legend(fontsize=7, ncol=2)
    for i, axis in enumerate("xyz"):
        ax_f.plot(ts, displacement[:, i] * 1e3, label=axis)
    ax_f.axvspan(0.0, 0.1, color="0.9")
    ax_f.set(xlabel="t [s]", ylabel="flange displacement [mm]", title="caught by the servo")
    ax_f.legend(fontsize=8)
    names = list(checks)
    y = np.arange(len(names))
    grads = [abs(checks[n][0]) for n in names]
    fds = [abs(checks[n][1]) for n in names]
    ax_g.barh(y - 0.18, grads, height=0.35, label="jax.grad")
    ax_g.barh(y + 0.18, fds, height=0.35, label="central differences")
    ax_g.set(yticks=y, yticklabels=names, xscale="log", xlabel="|derivative|",
             title="gradient of the reach loss",      # bars from a decade below the smallest
             xlim=(0.1 * min(grads + fds), 2 * max(grads + fds)))
    ax_g.legend(fontsize=8)
    for ax in (ax_q, ax_f, ax_g):
        ax.grid(alpha=0.3)
    fig.suptitle(title, fontsize=10)
    return fig


def models_figure(ts, qs, lower, upper, flange, peers: dict, title: str) -> Figure:
    """(a) the falling arm's joint angles against their limits; (b) the flange's path, by name;
    (c) forward dynamics against the peers: `peers` is {peer: {"status", "max_relative_difference"}}
    (`mbjax_harness.tour._model_peers`), a bar for each peer compared, where a peer was not, what
    to install (`mbjax_harness.peers.note`) in its place, or across the panel when none was."""
    from mbjax_harness.peers import TITLES, note

    fig = Figure(figsize=(14, 4.2), layout="constrained")
    ax_q, ax_f, ax_p = fig.subplots(1, 3, width_ratios=(1.2, 1, 0.6))
    for j in range(qs.shape[1]):
        line, = ax_q.plot(ts, qs[:, j], lw=1, label=f"joint {j + 1}")
        for bound in (lower[j], upper[j]):
            ax_q.axhline(bound, color=line.get_color(), lw=0.6, ls=":")
    ax_q.set(xlabel="t [s]", ylabel="q [rad]", title="(a) unpowered fall, limits dotted")
    ax_q.legend(fontsize=7, ncol=2)
    ax_f.plot(flange[:, 0], flange[:, 2], "-", lw=1.5)
    ax_f.plot(flange[0, 0], flange[0, 2], "o", label="start")
    ax_f.set(xlabel="x [m]", ylabel="z [m]", title='(b) frame_pose(model, q, "flange")',
             aspect="equal")
    ax_f.legend(fontsize=7)
    names = list(peers)
    ax_p.set_yscale("log")
    ax_p.set(ylim=(1e-17, 1e-6), ylabel="max relative difference",
             title="(c) forward dynamics vs peers")
    compared = [n for n in names if peers[n]["status"] == "compared"]
    if compared:
        slots = range(len(names))
        ax_p.bar([k for k in slots if names[k] in compared],
                 [max(peers[n]["max_relative_difference"], 1e-17) for n in names if n in compared],
                 color="C0")
        ax_p.set_xticks(slots, [TITLES.get(n, n) for n in names])
        ax_p.set_xlim(-0.6, len(names) - 0.4)
        for k, n in enumerate(names):
            if n not in compared:
                ax_p.text(k, 1e-12, note(n, peers[n]["status"]).replace(": ", ":\n", 1),
                          ha="center", va="center", fontsize=7, rotation=90, color="0.3")
    else:
        note_in(ax_p, "\n".join(note(n, peers[n]["status"]) for n in names)
                or "no peer to compare with")
    for ax in (ax_q, ax_f, ax_p):
        ax.grid(alpha=0.3)
    fig.suptitle(f"ARM7 from URDF: {title}")
    return fig
