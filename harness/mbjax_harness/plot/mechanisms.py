"""Figures of closed mechanisms from the literature: `mbjax reproduce andrews-squeezer`."""

import numpy as np

from mbjax_harness.plot.style import COLORS, MARKERS, Figure

ANGLES = ("beta", "Theta", "gamma", "Phi", "delta", "Omega", "epsilon")


def _wrapped(angle: np.ndarray) -> np.ndarray:
    """The angle mod 2 pi in [-pi, pi), NaN at the wraps so that lines do not jump across."""
    wrapped = (angle + np.pi) % (2 * np.pi) - np.pi
    jumps = np.abs(np.diff(wrapped)) > np.pi
    return np.where(np.concatenate([[False], jumps]), np.nan, wrapped)


def andrews_figure(data: dict) -> Figure:
    """(a) the seven angles mod 2 pi against time (Hairer & Wanner II, Fig. 7.3), the test set's
    reference values at t = 0.03 s marked; (b) RK4's error against the reference and its
    difference from the finest run against dt, with a slope-4 guide."""
    fig = Figure(figsize=(12, 4.6), layout="constrained")
    ax_q, ax_c = fig.subplots(1, 2)
    ts = 1e3 * np.asarray(data["history"]["t"])
    qs = np.asarray(data["history"]["q"])
    for k, name in enumerate(ANGLES):
        line, = ax_q.plot(ts, _wrapped(qs[:, k]), label=name)
        ax_q.plot(1e3 * data["t"], _wrapped(np.array([data["reference"][k]]))[0], "x",
                  color=line.get_color(), markersize=8)
    ax_q.set(xlabel="t [ms]", ylabel="angle mod 2 pi [rad]",
             title="(a) Andrews' squeezer; x: test set reference at 30 ms")
    rows = sorted(data["convergence"], key=lambda r: r["dt"])
    dt = np.array([r["dt"] for r in rows])
    kw = dict(color=COLORS["rk4"], marker=MARKERS["rk4"])
    ax_c.loglog(dt, [r["max_abs_error"] for r in rows], label="against the test set reference", **kw)
    ax_c.loglog(dt[1:], [r["diff_from_finest"] for r in rows[1:]], ls="--", mfc="none",
                label="against the finest run", **kw)
    anchor = rows[-1]
    ax_c.loglog(dt, anchor["max_abs_error"] * (dt / anchor["dt"]) ** 4, ":", color="gray",
                label="slope 4")
    order = data.get("observed_order")
    ax_c.set(xlabel="step dt [s]", ylabel="max |angle error| at 30 ms [rad]",
             title="(b) RK4 convergence" + (f" (observed order {order:.2f})" if order else ""))
    for ax in (ax_q, ax_c):
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    return fig
