"""The model corpus: each real model's largest relative difference from its format's engine."""

import numpy as np

from mbjax_harness.plot.style import Figure


def corpus_figure(data: dict) -> Figure:
    """Two panels: URDF robots against Pinocchio (fixed and floating base) and MJCF models
    against MuJoCo; log-scale max relative difference, models that did not load marked."""
    panels = [("URDF (example-robot-data) vs Pinocchio", data["urdf"],
               lambda r: f"{r['robot']}{' (floating)' if r['floating'] else ''}"),
              ("MJCF (dm_control, gymnasium) vs MuJoCo", data["mjcf"], lambda r: r["model"])]
    heights = [max(len(rows), 1) for _, rows, _ in panels]
    fig = Figure(figsize=(10, 0.17 * sum(heights) + 2.0), layout="constrained")
    axes = fig.subplots(2, 1, height_ratios=heights)
    floor = 1e-17
    for ax, (title, rows, label) in zip(axes, panels, strict=True):
        y = np.arange(len(rows))
        diff = np.array([r["max_relative_difference"] if r["max_relative_difference"] is not None
                         else np.nan for r in rows], dtype=float)
        loaded = np.array([r["loads"] for r in rows], dtype=bool)
        ax.barh(y, np.where(np.isfinite(diff), np.maximum(diff, floor), 0.0), left=floor,
                color=np.where(loaded, "C0", "C3"))
        for i in np.flatnonzero(~np.isfinite(diff)):
            note = rows[i].get("note", "")
            why = ("not compared" if loaded[i] else "empty file, not a robot" if "no links" in note
                   else "no joint: floating base only" if "no movable joint" in note
                   else "did not load")
            ax.text(floor * 3, i, why, va="center", fontsize=6, color="C3")
        ax.set_xscale("log")
        ax.set_xlim(floor, 1e-6)
        ax.set_yticks(y, [label(r) for r in rows], fontsize=6)
        ax.set_ylim(len(rows) - 0.5, -0.5)
        ax.set_title(f"{title}: {int(loaded.sum())} of {len(rows)} load", fontsize=9)
        ax.grid(alpha=0.3, axis="x", which="both")
    axes[-1].set_xlabel("max |mbjax - peer| / max(1, |peer|)")
    return fig
