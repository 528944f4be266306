"""Figures of the flexible bodies (Anderson 1993 §3.1-3.2): `mbjax reproduce spin-up-beam`,
`mbjax reproduce flexible-slider-crank` and the tour's flexible-bodies scene."""

import numpy as np

from mbjax_harness.plot.style import Figure

FIRST_BENDING = 3.8          # rad/s, the spin-up beam's first bending frequency
REFERENCE_STYLE = dict(color="black", ls="--", lw=1.2)


def _array(values) -> np.ndarray:
    """JSON lists (null for non-finite) as a float array with NaN."""
    return np.array([np.nan if v is None else v for v in values], float)


def spin_up_figure(data: dict) -> Figure:
    """(a) tip deflection against time: the modal model with and without geometric stiffening and
    the ANCF reference, omega on a twin axis; the unstiffened curve is cut at the axis limits.
    (b) |tip deflection| on a log axis, where the unstiffened run's divergence shows; (c) the
    axial tip displacement: the modal model's (its axial mode's centrifugal stretch minus the
    bending's foreshortening) and the ANCF beam's."""
    fig = Figure(figsize=(16, 4.6), layout="constrained")
    ax_d, ax_l, ax_a = fig.subplots(1, 3, width_ratios=(1.25, 1, 0.8))
    ts = np.asarray(data["t"])
    tip, free = _array(data["tip_deflection"]), _array(data["tip_deflection_no_stiffening"])
    ref = data["reference"]
    ref_t, ref_tip = np.asarray(ref["t"]), _array(ref["tip_deflection"])
    modes = data["modes"]["n_bending"]
    lo = 1.6 * min(np.nanmin(tip), np.nanmin(ref_tip))
    ax_d.plot(ts, tip, color="#1f77b4", lw=2, label=f"modal, {modes} bending modes, stiffened")
    ax_d.plot(ref_t, ref_tip, label=f"ANCF, {ref['n_elements']} elements (reference)",
              **REFERENCE_STYLE)
    ax_d.plot(ts, np.where(free < lo, np.nan, free), color="#d62728",
              label="modal, no stiffening (leaves the axis)")
    ax_d.axhline(0.0, color="gray", lw=0.5)
    ax_d.set_ylim(lo, 0.15 * abs(lo))
    ax_d.set(xlabel="t [s]", ylabel="tip deflection [m] (< 0: lagging)",
             title=f"(a) Kane's spin-up beam: peak {data['peak']:.4f} m, reference "
                   f"{data['reference_peak']:.4f} m ({100 * data['peak_relative_error']:.2f} %)")
    ax_w = ax_d.twinx()
    omega = np.asarray(data["omega"])
    ax_w.plot(ts, omega, color="gray", lw=1, ls=":")
    ax_w.axhline(FIRST_BENDING, color="gray", lw=0.5, ls=":")
    ax_w.set_ylabel("omega [rad/s] (dotted; 3.8: first bending frequency)", color="gray")
    ax_w.set_ylim(0.0, 1.1 * max(omega.max(), 6.0))
    ax_d.legend(fontsize=8, loc="lower left")

    crossing = ts[np.argmax(omega >= FIRST_BENDING)] if np.any(omega >= FIRST_BENDING) else None
    with np.errstate(invalid="ignore"):
        ax_l.semilogy(ts[1:], np.abs(tip[1:]), color="#1f77b4", lw=2, label="modal, stiffened")
        ax_l.semilogy(ref_t[1:], np.abs(ref_tip[1:]), label="ANCF reference", **REFERENCE_STYLE)
        ax_l.semilogy(ts[1:], np.abs(free[1:]), color="#d62728", label="modal, no stiffening")
    if crossing is not None:
        ax_l.axvline(crossing, color="gray", lw=0.8, ls=":")
        ax_l.annotate("omega = 3.8 rad/s", (crossing, np.nanmax(np.abs(tip))), fontsize=8,
                      textcoords="offset points", xytext=(4, 20), color="gray")
    ax_l.set(xlabel="t [s]", ylabel="|tip deflection| [m]",
             title="(b) without geometric stiffening the tip diverges")
    ax_a.plot(ts, 1e3 * _array(data["axial_tip_displacement"]), color="#1f77b4", lw=2,
              label="modal: stretch - foreshortening")
    if "axial_stretch" in data:
        ax_a.plot(ts, 1e3 * _array(data["axial_stretch"]), color="#1f77b4", lw=1, ls=":",
                  label="modal: axial mode (stretch) alone")
    if "tip_axial" in ref:
        ax_a.plot(ref_t, 1e3 * _array(ref["tip_axial"]), label="ANCF reference", **REFERENCE_STYLE)
    ax_a.axhline(0.0, color="gray", lw=0.5)
    ax_a.set(xlabel="t [s]", ylabel="axial tip displacement [mm]",
             title="(c) axial tip displacement")
    for ax in (ax_d, ax_l, ax_a):
        ax.grid(alpha=0.3, which="both")
    ax_l.legend(fontsize=8)
    ax_a.legend(fontsize=8)
    return fig


SLIDER_COLORS = {"1": "#ff7f0e", "2": "#2ca02c", "3": "#1f77b4"}


def slider_crank_figure(data: dict) -> Figure:
    """(a) the rod's midpoint deflection against time for 1, 2, 3 beam elements and the ANCF rod
    (Anderson 1993 Fig. 5); (b) each model's difference from the ANCF rod over the history, with the
    tolerance; (c) the peak |deflection| against the number of elements."""
    fig = Figure(figsize=(15, 4.6), layout="constrained")
    ax_d, ax_e, ax_p = fig.subplots(1, 3, width_ratios=(2.2, 1.6, 1))
    ts = 1e3 * np.asarray(data["t"])
    ref = data["reference"]
    ref_d = _array(ref["midpoint_deflection_in"])
    for n, values in data["by_elements"].items():
        ax_d.plot(ts, _array(values), color=SLIDER_COLORS.get(n), lw=1.5,
                  label=f"modal, {n} element{'s' * (n != '1')}")
        ax_e.plot(ts, _array(values) - ref_d, color=SLIDER_COLORS.get(n), lw=1.2,
                  label=f"{n} element{'s' * (n != '1')}: max {data['max_abs_differences'][n]:.3g} in")
    ax_d.plot(1e3 * np.asarray(ref["t"]), ref_d,
              label=f"ANCF, {ref['n_elements']} elements (reference)", **REFERENCE_STYLE)
    ax_d.axhline(0.0, color="gray", lw=0.5)
    ax_d.set(xlabel="t [ms]", ylabel="midpoint deflection [in]",
             title="(a) flexible slider-crank, 125.6 rad/s (Anderson 1993 Fig. 5)")
    ax_d.legend(fontsize=8)
    tolerance = data.get("history_tolerance_in")
    if tolerance:
        for sign in (1, -1):
            ax_e.axhline(sign * tolerance, color="0.5", ls="--", lw=0.8,
                         label=f"tolerance {tolerance:g} in" if sign == 1 else None)
        ax_e.set_ylim(-3 * tolerance, 3 * tolerance)     # a coarser model may leave the panel
    ax_e.set(xlabel="t [ms]", ylabel="modal - ANCF [in]",
             title="(b) the history's error (largest in the legend)")
    ax_e.legend(fontsize=7)
    ns = [int(n) for n in data["peaks"]]
    ax_p.plot(ns, list(data["peaks"].values()), "o-", color="#1f77b4", label="modal")
    ax_p.axhline(data["reference_peak"], label="ANCF reference", **REFERENCE_STYLE)
    ax_p.set_xticks(ns)
    ax_p.set(xlabel="beam elements", ylabel="peak |midpoint deflection| [in]",
             title="(c) convergence with elements")
    ax_p.legend(fontsize=8)
    for ax in (ax_d, ax_e, ax_p):
        ax.grid(alpha=0.3)
    return fig


def flexible_tour_figure(runs: list[dict], histories: dict, reference: tuple, title: str) -> Figure:
    """(a) the largest tip-deflection difference from the ANCF reference against run time, one
    point per modal model (bending modes, stiffening; diamonds: the simplified implicit midpoint,
    "integrator" "implicit"); (b) the tip histories."""
    fig = Figure(figsize=(12, 4.6), layout="constrained")
    ax_w, ax_h = fig.subplots(1, 2)
    for stiffening, implicit, marker, color, label in (
            (True, False, "o-", "#1f77b4", "stiffened, RK4"),
            (False, False, "s--", "#d62728", "no stiffening, RK4"),
            (True, True, "D", "#2ca02c", "stiffened, implicit midpoint")):
        rows = [r for r in runs if r["stiffening"] == stiffening
                and (r.get("integrator") == "implicit") == implicit]
        if not rows:
            continue
        ax_w.loglog([r["seconds"] for r in rows], [r["error"] for r in rows], marker, color=color,
                    label=label)
        for r in rows:
            ax_w.annotate(f"{r['n_bending']} mode{'s' * (r['n_bending'] != 1)}",
                          (r["seconds"], r["error"]), fontsize=7, textcoords="offset points",
                          xytext=(4, 2))
    ax_w.set(xlabel="run time after compilation [s]",
             ylabel="max |tip - ANCF tip| [m]", title="(a) speed against accuracy")
    lo = 1.6 * np.min(reference[1])
    for name, (ts, tip) in histories.items():
        tip = np.asarray(tip, float)
        ax_h.plot(ts, np.where(np.isfinite(tip) & (tip >= lo), tip, np.nan), label=name)
    ax_h.plot(reference[0], reference[1], label=f"ANCF, {reference[2]} elements", **REFERENCE_STYLE)
    ax_h.set_ylim(lo, 0.15 * abs(lo))
    ax_h.set(xlabel="t [s]", ylabel="tip deflection [m]",
             title="(b) tip deflection (unstiffened runs leave the axis)")
    for ax in (ax_w, ax_h):
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    fig.suptitle(title)
    return fig
