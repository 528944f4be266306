"""The contact scene's figure (the tour's "contacts"): robots dropped on the floor by mbjax and by
MuJoCo from the same MJCF file."""

import numpy as np

from mbjax_harness.plot.style import Figure

COLORS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd")


def drop_figure(runs: dict, title: str) -> Figure:
    """(a) each robot's root height through the drop, mbjax solid, MuJoCo dashed; (b) their
    difference; (c) the run time per simulated second of each engine.

    Args:
        runs: per robot, {"ts", "mbjax", "mujoco" (heights, (T,), MuJoCo's None where it did not
            run), "mbjax_seconds", "mujoco_seconds" (per simulated second, MuJoCo's None)}.
        title: the figure's title.
    """
    fig = Figure(figsize=(14, 4.2), layout="constrained")
    ax_h, ax_d, ax_t = fig.subplots(1, 3)
    names = list(runs)
    for color, name in zip(COLORS, names):
        run = runs[name]
        ax_h.plot(run["ts"], run["mbjax"], color=color, lw=1.5, label=f"{name}, mbjax")
        if run["mujoco"] is not None:
            ax_h.plot(run["ts"], run["mujoco"], color=color, lw=1.5, ls=(0, (4, 2)), alpha=0.7,
                      label=f"{name}, MuJoCo")
            gap = np.maximum(np.abs(np.asarray(run["mbjax"]) - run["mujoco"]), 1e-17)
            ax_d.semilogy(run["ts"], gap, color=color, label=name)
    ax_h.set(xlabel="t [s]", ylabel="root height [m]", title="dropped with zero controls")
    ax_h.legend(fontsize=7)
    ax_d.axhline(1e-2, color="0.5", lw=1, ls=":", label="1 cm")
    ax_d.set(xlabel="t [s]", ylabel="|mbjax - MuJoCo| [m] (1e-17: equal)",
             title="root height: the difference")
    ax_d.legend(fontsize=7)
    y = np.arange(len(names))
    mbjax = [runs[n]["mbjax_seconds"] * 1e3 for n in names]
    peer = [(runs[n]["mujoco_seconds"] or 0.0) * 1e3 for n in names]
    ax_t.barh(y - 0.2, mbjax, 0.4, color="#1f77b4", label="mbjax (compiled, one robot)")
    ax_t.barh(y + 0.2, peer, 0.4, color="#7f7f7f", label="MuJoCo (mj_step from Python)")
    ax_t.set_yticks(y, names)
    ax_t.set(xlabel="run time per simulated second [ms]", title="speed")
    ax_t.legend(fontsize=7)
    for ax in (ax_h, ax_d, ax_t):
        ax.grid(alpha=0.3)
    fig.suptitle(title, fontsize=10)
    return fig
