"""The model-predictive control scene's figure (the tour's "mpc"): the arm's flange following its
circle under a receding-horizon controller, pushed and carrying a payload it does not know of."""

import numpy as np

from mbjax_harness.plot.style import Figure


def tracking_figure(ts, flange, target, error, solve_ms, period_ms: float, push: tuple,
                    title: str) -> Figure:
    """(a) the flange's path and the target's circle in the y-z plane; (b) the distance between
    them over time, the push shaded; (c) each tick's solve time against the control period.

    Args:
        ts: the ticks' times [s], shape (T + 1,).
        flange: the flange's positions at the ticks [m], shape (T + 1, 3).
        target: the target's, likewise.
        error: their distance [m], shape (T + 1,).
        solve_ms: each tick's solve [ms], shape (T,).
        period_ms: the control period [ms].
        push: (start, end) of the push [s].
        title: the figure's title.
    """
    fig = Figure(figsize=(14, 4.2), layout="constrained")
    ax_p, ax_e, ax_t = fig.subplots(1, 3)
    ax_p.plot(target[:, 1], target[:, 2], "k--", lw=1, label="target")
    ax_p.plot(flange[:, 1], flange[:, 2], color="#1f77b4", lw=1.5, label="flange")
    ax_p.set(xlabel="y [m]", ylabel="z [m]", title="(a) the flange's path", aspect="equal")
    ax_p.legend()
    ax_e.axvspan(*push, color="#d62728", alpha=0.15, label="push")
    ax_e.plot(ts, 1e3 * np.asarray(error), color="#1f77b4", label="tracking error")
    ax_e.set(xlabel="t [s]", ylabel="distance to the target [mm]", title="(b) tracking error")
    ax_e.legend()
    ax_t.plot(ts[:-1], solve_ms, ".", color="#1f77b4", ms=3, label="solve per tick")
    ax_t.axhline(period_ms, color="#d62728", ls="--", label="control period")
    ax_t.set(xlabel="t [s]", ylabel="[ms]", title="(c) each tick's solve", ylim=(0, None))
    ax_t.legend()
    fig.suptitle(title)
    return fig
