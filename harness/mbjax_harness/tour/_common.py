"""What the tour's scenes share: figures saved and checked, peers asked, animations written."""

import os
from pathlib import Path

import jax
import numpy as np

from mbjax_harness import peers



def _max_abs(x) -> float:
    """max |x| of an array, in NumPy (outside jit a JAX reduction compiles a program)."""
    return float(np.max(np.abs(np.asarray(x))))


def _save(fig, out: Path, name: str) -> str:
    """Write fig as out/name; with MBJAX_LINT_FIGURES set (the tests set it), first check that
    it reads (`mbjax_harness.plot.style.lint`: two labelled ticks on every log axis, a legend
    wherever several lines are drawn) and raise naming what does not."""
    fig.savefig(out / name, dpi=110)
    if os.environ.get("MBJAX_LINT_FIGURES"):
        from mbjax_harness.plot.style import lint

        problems = lint(fig)
        if problems:
            raise AssertionError(f"{name}: " + "; ".join(problems))
    return name


def _peer(name: str, compares: str, compute):
    """(value, record) of a comparison with peer engine `name`: compute()'s value and
    {"status": "compared", "compares": compares}, or None and the status saying why not: the
    peer is not installed (`mbjax_harness.peers.missing`), or it raised (a peer's failure is
    reported, not the scene's)."""
    why = peers.missing(name)
    if why is not None:
        return None, {"status": why, "compares": compares}
    try:
        value = compute()
    except Exception as error:  # noqa: BLE001 (any failure of the peer's run is reported)
        return None, {"status": f"failed: {type(error).__name__}: {error}"[:300],
                      "compares": compares}
    return value, {"status": "compared", "compares": compares}


def _needs(out: Path, name: str, what: str, records: dict) -> dict:
    """A scene that cannot run without an optional package: a figure that says what to
    install, the missing packages recorded as skipped peers."""
    from mbjax_harness.plot.style import Figure

    fig = Figure(figsize=(8, 2.5), layout="constrained")
    ax = fig.add_subplot()
    ax.axis("off")
    ax.text(0.5, 0.5, f"{what}: " + "; ".join(peers.note(peer, r["status"])
                                             for peer, r in records.items()),
            ha="center", va="center", wrap=True)
    _save(fig, out, f"{name}.png")
    return {"figure": f"{name}.png", "peers": records}


def _without_robot(out: Path, records: dict) -> dict:
    """The legged-gait scene where ANYmal's model cannot be had (`_needs`)."""
    return _needs(out, "legged-gait", "ANYmal's trot needs its model", records)



def _animate(out: Path, name: str, system, ts, qs, title: str, quick: bool) -> str:
    """Write the scene's animation, `name`.gif (`mbjax_harness.plot.animate.animate`), of a system
    moving through the saved states qs at times ts; returns the file name."""
    from mbjax_harness.plot.animate import animate

    animate(out / f"{name}.gif", system, ts, qs, title=title, frames=30 if quick else 60)
    return f"{name}.gif"



def _animate_body(out: Path, name: str, body, ts, qs, title: str, quick: bool) -> str:
    """Write `name`.gif of a single rigid body turning: its frame's triad at the fixed point and a
    stick along its symmetry axis (body z), whose tip leaves its path (nutation and precession)."""
    from mbjax_harness.plot.animate import stick_animation

    R = np.asarray(jax.jit(jax.vmap(body.rotation_matrix))(qs))
    p = np.stack([np.zeros((len(R), 3)), R[:, :, 2]], axis=1)
    stick_animation(out / f"{name}.gif", ts, np.stack([R, R], axis=1), p, [-1, 0], title=title,
                    trace=1, axis_length=0.4, frames=30 if quick else 60)
    return f"{name}.gif"


def _animate_tops(out: Path, runs: list[dict], quick: bool) -> str:
    """Write time-elements.gif: the tops of the primal (left) and mixed (right) runs side by side,
    each a stick from its pivot along its symmetry axis, whose tip leaves its path; the tilt is
    magnified (as the title says) so that the primal form's growth shows, not the mixed form's."""
    from mbjax_harness.plot.animate import stick_animation

    R = np.stack([run.pop("R") for run in runs], axis=1)                # (T, 2, 3, 3)
    axis = R[..., :, 2]
    tilt = np.arccos(np.clip(axis[..., 2], -1.0, 1.0))
    magnification = max(1, int(1.0 / max(float(tilt.max()), 1e-3)))    # the largest tilt ~ 1 rad
    azimuth = np.arctan2(axis[..., 1], axis[..., 0])
    shown = magnification * tilt
    tips = np.stack([np.sin(shown) * np.cos(azimuth), np.sin(shown) * np.sin(azimuth),
                     np.cos(shown)], axis=-1)
    pivots = np.array([[-0.8, 0.0, 0.0], [0.8, 0.0, 0.0]])
    ts = np.asarray(runs[0]["t"])
    stick_animation(out / "time-elements.gif", ts, R, pivots + tips, [-1, -1],
                    title=f"primal (left), mixed (right), tilt x{magnification}", trace=[0, 1],
                    triads=False, anchors=pivots, frames=30 if quick else 60)
    return "time-elements.gif"
