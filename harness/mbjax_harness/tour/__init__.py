"""What `mbjax tour` runs for each scene: a short simulation, a figure and a few numbers.

Each entry takes (out, quick) and returns a summary dict naming the figure it wrote in out. A
scene that compares with a peer engine (MuJoCo, Pinocchio) records each one under "peers", with
the status "compared" or why not ("unavailable: mujoco is not installed", "failed: ..."): the
command's closing line names the peers skipped from there, and the scene's figure and "what to
look at" sentence say what was not compared (`look_at`).

The first sentence of each scene's docstring is its line in `mbjax tour --list`.

The scenes live one family a module (`bodies`, `mechanisms`, `robots`, `optimisation`,
`contacts`; what they share in `_common`); this package holds the registry (`TOUR`, `COST`), the
"what to look at" sentences (`look_at`) and `run_scene`, and re-exports every scene and helper
under its old name (`mbjax_harness.tour.X`).
"""

import time
from pathlib import Path

from mbjax_harness import peers
from mbjax_harness.tour._common import (_animate, _animate_body, _animate_tops, _max_abs, _needs,
                                        _peer, _save, _without_robot)
from mbjax_harness.tour.bodies import (CHAIN_STEPS, QUICK_CHAIN_STEPS, heavy_top_tour,
                                       rigid_chain_tour, time_elements_tour, torque_free_body_tour)
from mbjax_harness.tour.contacts import CONTACT_ROBOTS, contacts_tour
from mbjax_harness.tour.mechanisms import (BEAM_MAGNIFICATION, FLEX_AGREEMENT, FLEX_DT,
                                           FLEX_DURATION, FLEX_IMPLICIT_DT, FLEX_MODES,
                                           FLEX_REFERENCE_ELEMENTS, LOOP_STEPS, QUICK_FLEX_DURATION,
                                           QUICK_FLEX_MODES, QUICK_LOOP_STEPS, QUICK_LOOP_SYSTEMS,
                                           _animate_beam, carpal_wrist_tour, closed_loops_tour,
                                           flexible_bodies_tour)
from mbjax_harness.tour.optimisation import (floating_base_tour, legged_gait_tour, mpc_tour,
                                             trajectory_optimisation_tour)
from mbjax_harness.tour.robots import _model_peers, _mujoco_sampled, controls_tour, models_tour

__all__ = [
    "BEAM_MAGNIFICATION", "CHAIN_STEPS", "CONTACT_ROBOTS", "COST", "FLEX_AGREEMENT", "FLEX_DT",
    "FLEX_DURATION", "FLEX_IMPLICIT_DT", "FLEX_MODES", "FLEX_REFERENCE_ELEMENTS", "LOOK_AT",
    "LOOP_STEPS", "QUICK_CHAIN_STEPS", "QUICK_FLEX_DURATION", "QUICK_FLEX_MODES",
    "QUICK_LOOP_STEPS", "QUICK_LOOP_SYSTEMS", "TOUR", "_animate", "_animate_beam", "_animate_body",
    "_animate_tops", "_max_abs", "_model_peers", "_mujoco_sampled", "_needs", "_peer", "_save",
    "_without_robot", "carpal_wrist_tour", "closed_loops_tour", "contacts_tour", "controls_tour",
    "flexible_bodies_tour", "floating_base_tour", "heavy_top_tour", "legged_gait_tour", "look_at",
    "models_tour", "mpc_tour", "rigid_chain_tour", "run_scene", "time_elements_tour",
    "torque_free_body_tour", "trajectory_optimisation_tour",
]


# what a reader should look at in each scene's figure and tables (`summary.md`), for the scenes
# that compare with no peer; `look_at` writes the others' from what ran
LOOK_AT = {
    "mpc": "the flange stays on its circle through the push and the unknown payload (middle "
           "panel), every tick's solve well inside the 10 ms control period (right panel)",
    "torque-free-body": "at the same step RK4 and RKMK4 land within 1e-4 rad of the closed form "
                        "while both Euler methods are off by more than a radian; the error "
                        "estimate column tracks the true error, and the status says which runs "
                        "to trust.",
    "heavy-top": "the energy drift: the implicit midpoint keeps the energy to round-off, RK4 and "
                 "RKMK4 to 1e-10, the Euler methods gain or lose tens of percent.",
    "rigid-chain": "error against run time: quartering RK4's step cuts its error about "
                   "250-fold (fourth order); the implicit midpoint costs more per step here.",
    "time-elements": "the tilt: the primal time element's grows at the rate its transition "
                     "matrix predicts, the mixed element's stays with the physical motion.",
    "closed-loops": "the constraint residual |Phi|: without stabilization it drifts, Baumgarte "
                    "bounds it, projection holds it at round-off; accuracy against run time per "
                    "method.",
    "flexible-bodies": "the tip histories: with geometric stiffening the modal beam follows the "
                       "nonlinear ANCF beam, without it the tip runs away once the spin passes "
                       "the first bending frequency; the implicit midpoint reaches the same "
                       "accuracy at 25 times RK4's step.",
    "carpal-wrist": "the stability column against the step: the chapter's explicit Euler goes "
                    "unstable past its critical step (about 7 ms) while RK4 stays stable to "
                    "about 35 ms, as their linearizations predict (the critical steps below).",
    "trajectory-optimisation": "the cost falling over the iterations and the flange reaching its "
                               "target at rest.",
    "floating-base": "the quadrotor pitching forward to fly over and back level to stop at its "
                     "target, the thrusts held inside their bounds; the same problem in "
                     "Crocoddyl is `mbjax bench trajopt`'s quadrotor-bounded.",
}



def look_at(name: str, scene: dict) -> str | None:
    """The "what to look at" sentence of scene `name` given its summary `scene`: `LOOK_AT`'s, or,
    for a scene that compares with peers, one that describes the comparisons that ran and says
    which did not, and why (`mbjax_harness.peers.note`)."""
    records = scene.get("peers", {})
    ran = [peers.TITLES[p] for p in ("mujoco", "pinocchio")
           if records.get(p, {}).get("status") == "compared"]
    not_run = "; ".join(peers.note(p, r["status"]) for p, r in records.items()
                        if r.get("status") != "compared")
    if name == "controls":
        text = ("the servo catching the push within millimetres (middle panel) and jax.grad "
                "agreeing with central differences (right panel)")
        if ran:
            return text + ("; the sampled-torque run ends where mujoco.rollout ends (its "
                           "difference is in the title and the runs table).")
        return text + f"; the sampled-torque run is not compared with MuJoCo ({not_run})."
    if name == "legged-gait":
        if "runs" not in scene:
            return f"nothing: ANYmal's model is not here ({not_run})."
        text = ("the feet taking turns on the ground in diagonal pairs, each pushing up to the "
                "edge of the cost's friction cone (right panel: 1 is the cone, whose barrier "
                "prices a small excess rather than forbidding it, in Crocoddyl's problem too)")
        record = records.get("crocoddyl", {})
        if record.get("status") == "compared":
            return text + (f"; Crocoddyl's FDDP on the same problem reaches the same cost "
                           f"(relative difference {record['relative_cost']:.1e}).")
        return text + f"; not compared with Crocoddyl ({peers.note('crocoddyl', record['status'])})."
    if name == "contacts":
        if "runs" not in scene:
            return f"nothing: the robots are MJCF files, which MuJoCo reads ({not_run})."
        worst = max(run["height_error_max_m"] for run in scene["runs"].values())
        return ("the Ant and the HalfCheetah landing on their legs and settling, their geoms "
                "finding their own contacts each step; MuJoCo's runs of the same files (dashed) "
                f"stay within {worst:.1e} m of mbjax's root heights (middle panel).")
    if name == "models":
        text = "the unpowered arm falls through its joint limits (left panel) and the status says so"
        if not ran:
            return text + f"; its dynamics are compared with no peer here ({not_run})."
        return (text + f"; the arm loaded from a URDF agrees with {' and '.join(ran)} on its "
                "dynamics (right panel)" + (f"; not compared: {not_run}." if not_run else "."))
    return LOOK_AT.get(name)


TOUR = {   # in the order the summary tells them
    "torque-free-body": torque_free_body_tour,
    "heavy-top": heavy_top_tour,
    "rigid-chain": rigid_chain_tour,
    "time-elements": time_elements_tour,
    "closed-loops": closed_loops_tour,
    "flexible-bodies": flexible_bodies_tour,
    "carpal-wrist": carpal_wrist_tour,
    "controls": controls_tour,
    "models": models_tour,
    "trajectory-optimisation": trajectory_optimisation_tour,
    "floating-base": floating_base_tour,
    "legged-gait": legged_gait_tour,
    "contacts": contacts_tour,
    "mpc": mpc_tour,
}

# Each scene's wall time in a quick tour from a cold cache, one scene at a time (benchmarks/README
# compile section): `mbjax tour` starts the longest first, which balances its workers best.
COST = {"contacts": 17.6, "time-elements": 17.0, "floating-base": 12.3, "flexible-bodies": 12.8,
        "carpal-wrist": 12.2, "closed-loops": 11.5, "rigid-chain": 10.4, "controls": 7.7, "trajectory-optimisation": 5.8,
        "torque-free-body": 5.4, "heavy-top": 4.6, "models": 4.2, "legged-gait": 85.0, "mpc": 12.0}



def run_scene(name: str, out: Path, quick: bool) -> dict:
    """The summary of scene `name`, with what to look at (`look_at`) and its wall time
    (compiling, running and drawing)."""
    start = time.perf_counter()
    result = TOUR[name](out, quick)
    sentence = look_at(name, result)
    if sentence:
        result["look_at"] = sentence
    result["wall_seconds"] = time.perf_counter() - start
    return result
