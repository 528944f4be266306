"""The `mbjax` command: choices, exit codes and what each subcommand writes."""

import json
import math
import shutil
import subprocess
import sys

import numpy as np
import pytest

from mbjax_harness import peers
from mbjax_harness.crocoddyl.terms import crocoddyl_working
from mbjax_harness.cli import main


def test_console_script_is_installed():
    exe = shutil.which("mbjax")
    assert exe is not None, "the mbjax console script is not on PATH (pip install the package)"
    out = subprocess.run([exe, "reproduce", "--list"], capture_output=True, text=True, check=True)
    assert {"integrators", "tree-scaling"} <= set(out.stdout.split())


@pytest.mark.parametrize("argv", [["reproduce", "nope"], ["bench", "nope"], ["frobnicate"],
                                  ["tour", "--bogus"], ["reproduce"], ["bench"]])
def test_bad_names_and_options_exit_2_with_choices(argv, capsys):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    if argv[0] in ("reproduce", "bench") and len(argv) > 1:
        assert "integrators" in err  # the valid choices are listed
        assert ("tree-scaling" if argv[0] == "reproduce" else "rigid") in err
    if argv == ["frobnicate"]:
        assert "tour" in err and "reproduce" in err and "bench" in err


def test_reproduce_list(capsys):
    assert main(["reproduce", "--list"]) == 0
    assert "integrators" in capsys.readouterr().out.split()


def test_version(capsys):
    import jax

    import mbjax

    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    assert f"mbjax {mbjax.__version__}" in out and f"jax {jax.__version__}" in out


@pytest.mark.parametrize("command", ["reproduce", "bench", "tour"])
def test_list_gives_one_line_per_name_saying_what_it_does(command, capsys):
    from mbjax_harness.bench import SUITES
    from mbjax_harness.reproduce import REPRODUCTIONS
    from mbjax_harness.tour import TOUR

    names = {"reproduce": REPRODUCTIONS, "bench": SUITES, "tour": TOUR}[command]
    assert main([command, "--list"]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert [line.split()[0] for line in lines] == sorted(names)
    for line in lines:            # a whole sentence on a line of 100 characters (`describe`)
        _, description = line.split(maxsplit=1)
        assert 10 < len(description) and len(line) <= 100 and not description.startswith("`mbjax")
        assert description.endswith(".") and not description.endswith("..."), line
        assert description[0].isupper() or description[0] == "`", line


def test_a_command_names_the_files_it_wrote_and_the_peers_it_skipped(tmp_path, capsys):
    from mbjax_harness.cli import _report

    (tmp_path / "suite.jsonl").write_text("{}")
    records = [{"engine": "mbjax", "status": "success"},
               {"engine": "exudyn", "status": "unavailable: exudyn is not installed"},
               {"cells": [{"engine": "mujoco", "status": "failed: SolverError"}]}]
    _report([tmp_path / "suite.jsonl", tmp_path / "suite.png"], records)
    out = capsys.readouterr().out.splitlines()
    assert out[0] == f"wrote {tmp_path / 'suite.jsonl'}"          # only what exists
    assert out[1] == ("peers skipped: exudyn: unavailable: exudyn is not installed; "
                      "mujoco: failed: SolverError")
    _report([tmp_path / "suite.jsonl"], [{"engine": "mbjax", "status": "success"}])
    assert capsys.readouterr().out.splitlines()[1] == "peers skipped: none"


@pytest.mark.slow
def test_reproduce_integrators(tmp_path):
    """The JSON of the issue, with fitted orders matching theory (1, 1, 4, 2, 4)."""
    assert main(["reproduce", "integrators", "--quick", "--out", str(tmp_path)]) == 0
    data = json.loads((tmp_path / "integrators.json").read_text())
    assert (tmp_path / "integrators.png").stat().st_size > 10_000
    for record in data["results"]:
        assert set(record) >= {"integrator", "dt", "error", "seconds", "energy_drift"}
    for name, expected in data["expected_orders"].items():
        assert abs(data["orders"][name] - expected) < 0.3, (name, data["orders"][name])
    top = data["heavy_top"]
    assert 0.01 < top["rk4_stability_limit_dt"] < 0.2
    stable = {(r["integrator"], r["dt"]): r["stable"] for r in top["results"]}
    assert all(stable[("implicit_midpoint", dt)] for _, dt in stable)
    assert not stable[("explicit_euler", max(dt for _, dt in stable))]


def test_reproduce_tree_scaling(tmp_path):
    """The JSON of the issue: exactly these keys, finite positive times, one per n; the timed
    computations agree with each other and with Pinocchio (the run checks it and stops on a
    disagreement: `check_agreement`, given one made on purpose, raises)."""
    assert main(["reproduce", "tree-scaling", "--quick", "--out", str(tmp_path)]) == 0
    data = json.loads((tmp_path / "tree-scaling.json").read_text())
    keys = {"n", "recursive_s", "dense_s"} | ({"pinocchio_aba_s"} if peers.available("pinocchio") else set())
    assert set(data) == keys
    assert len({len(values) for values in data.values()}) == 1 and len(data["n"]) >= 2
    assert data["n"] == sorted(data["n"]) and min(data["n"]) >= 1
    for key in keys - {"n"}:
        assert all(math.isfinite(t) and t > 0 for t in data[key]), (key, data[key])
    assert (tmp_path / "tree-scaling.png").stat().st_size > 10_000
    from mbjax_harness.reproduce import tree_scaling

    with pytest.raises(RuntimeError, match="at n = 3 the dense accelerations differ"):
        tree_scaling.check_agreement(3, {"recursive": np.ones(3),
                                         "dense": np.array([1.0, 1.0, 1.0 + 1e-6])})
    tree_scaling.check_agreement(3, {"recursive": np.ones(3), "dense": np.ones(3) + 1e-12})


# The tour's scenes in three groups of similar cost, so the two xdist workers share them.
TOUR_GROUPS = {
    "rigid": ("torque-free-body", "heavy-top", "rigid-chain", "closed-loops", "floating-base"),
    "time-elements": ("time-elements", "flexible-bodies", "controls"),
    "carpal-wrist": ("carpal-wrist", "models", "trajectory-optimisation"),
    "legged-gait": ("legged-gait",),
    "contacts": ("contacts",),
    "mpc": ("mpc",),
}


TOUR_GROUPS_ALL = [scene for group in TOUR_GROUPS.values() for scene in group]


def test_tour_groups_cover_every_scene():
    from mbjax_harness.tour import TOUR

    assert sorted(s for group in TOUR_GROUPS.values() for s in group) == sorted(TOUR)
    assert set(TOUR) == {"torque-free-body", "heavy-top", "rigid-chain", "time-elements",
                         "closed-loops", "flexible-bodies", "carpal-wrist", "controls", "models",
                         "trajectory-optimisation", "floating-base", "legged-gait", "contacts",
                         "mpc"}


def test_tour_rejects_an_unknown_scene(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["tour", "--scene", "no-such-scene"])
    assert exit_info.value.code == 2 and "carpal-wrist" in capsys.readouterr().err


def test_tour_rejects_jobs_below_one(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["tour", "--jobs", "0"])
    assert exit_info.value.code == 2 and "--jobs: must be at least 1" in capsys.readouterr().err


def test_the_gait_scene_says_what_to_install_without_the_robot(tmp_path, monkeypatch):
    """Without example-robot-data (a test extra, not a dependency) the legged-gait scene writes
    a figure that says what to install, and the summary names it as a skipped peer."""
    from mbjax_harness.tour import legged_gait_tour, look_at

    monkeypatch.setitem(sys.modules, "example_robot_data", None)
    scene = legged_gait_tour(tmp_path, quick=True)
    assert (tmp_path / scene["figure"]).stat().st_size > 5_000 and "runs" not in scene
    assert scene["peers"]["example_robot_data"]["status"].startswith("unavailable")
    assert "pip install example-robot-data" in look_at("legged-gait", scene)


def test_the_contact_scene_says_what_to_install_without_mujoco(tmp_path, monkeypatch):
    """Without MuJoCo (a test extra; it reads the MJCF files) the contacts scene writes a
    figure that says so, and the summary names it as a skipped peer."""
    from mbjax_harness.tour import contacts_tour, look_at

    monkeypatch.setitem(sys.modules, "mujoco", None)
    scene = contacts_tour(tmp_path, quick=True)
    assert (tmp_path / scene["figure"]).stat().st_size > 5_000 and "runs" not in scene
    assert scene["peers"]["mujoco"]["status"].startswith("unavailable")
    assert "pip install mujoco" in look_at("contacts", scene)


def test_tour_in_workers(tmp_path):
    """Scenes side by side in worker processes (`mbjax_harness.parallel`), the summary in the tour's
    order whichever finishes first."""
    assert main(["tour", "--quick", "--out", str(tmp_path), "--jobs", "2",
                 "--scene", "heavy-top", "--scene", "torque-free-body"]) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert list(summary["scenes"]) == ["torque-free-body", "heavy-top"]
    for scene in summary["scenes"].values():
        assert (tmp_path / scene["figure"]).stat().st_size > 10_000 and scene["wall_seconds"] > 0
    assert summary["scenes"]["torque-free-body"]["integrators"]["rkmk4"]["final_error_rad"] < 1e-4


# about a minute each on 2 cores: slow. The default suite runs two scenes of the tour in
# test_tour_in_workers; the scenes' physics is tested through the library (tests/rigid, tfe, flex,
# loops, wrist, trajopt, model).
@pytest.mark.slow
@pytest.mark.parametrize("group", list(TOUR_GROUPS))
def test_tour_quick(tmp_path, group):
    scenes = TOUR_GROUPS[group]        # one after another here: xdist runs the groups side by side
    assert main(["tour", "--quick", "--out", str(tmp_path), "--jobs", "1",
                 *[arg for scene in scenes for arg in ("--scene", scene)]]) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert set(summary["scenes"]) == set(scenes)
    for scene in summary["scenes"].values():
        assert (tmp_path / scene["figure"]).stat().st_size > 10_000
        from PIL import Image              # every scene animates its mechanism, frame by frame
        with Image.open(tmp_path / scene["animation"]) as gif:
            assert gif.format == "GIF" and gif.n_frames >= 20
    markdown = (tmp_path / "summary.md").read_text()
    assert all(f"## {scene}" in markdown for scene in scenes)
    # written for people: a sentence per scene on what to look at, headers in words with units
    assert markdown.count("*What to look at:*") == len(scenes)
    assert "_rad |" not in markdown and "seconds |" not in markdown and "run time [s]" in markdown
    TOUR_CHECKS[group](summary["scenes"])


def _check_rigid(scenes):
    rkmk4 = scenes["torque-free-body"]["integrators"]["rkmk4"]
    assert rkmk4["final_error_rad"] < 1e-4 and rkmk4["status"] == "success"
    chain = scenes["rigid-chain"]
    assert chain["reference_status"] == 0
    loops = scenes["closed-loops"]["integrators"]
    assert loops["coupled, projection dt=2 ms"]["residual"] < 1e-10
    assert loops["coupled, none dt=2 ms"]["error_rad"] < 1e-4
    rows = chain["integrators"]
    # the accuracy status (the tour asks rtol 1e-3, atol 1e-4): runs off by more than that say so
    assert all(row["status"] == "inaccurate" for row in rows.values() if row["error_rad"] > 1e-3)
    assert rows["rk4 dt=5 ms"]["status"] == "success"
    top_ = scenes["heavy-top"]["integrators"]
    assert top_["explicit_euler"]["energy_drift"] > 1 and top_["explicit_euler"]["status"] == \
        "inaccurate"
    assert top_["rk4"]["status"] == "success" and top_["rk4"]["energy_drift"] < 1e-6
    # RK4 at 5 ms follows the Dopri8 reference of the falling chain to micro-radians
    assert rows["rk4 dt=5 ms"]["error_rad"] < 1e-5 and rows["rk4 dt=5 ms"]["energy_error"] < 1e-5
    # the quadrotor flown on SE(3) by iLQR reaches its target within its bounded thrusts
    flight = scenes["floating-base"]["runs"]["ilqr"]
    assert flight["status"] == "success" and flight["final_position_error_m"] < 1e-3
    assert 0.1 <= flight["thrust_range_n"][0] and flight["thrust_range_n"][1] <= 5.0


def _check_time_elements(scenes):
    # time elements on the sleeping top: the primal form's tilt grows at its transition matrix's
    # rate, the mixed form's stays with the physical one
    tfe = scenes["time-elements"]
    primal, mixed = tfe["runs"]["primal"], tfe["runs"]["mixed"]
    assert primal["predicted_growth"] > 0.2
    assert abs(primal["measured_growth"] / primal["predicted_growth"] - 1) < 0.1
    assert abs(mixed["predicted_growth"]) < 1e-9 and abs(mixed["measured_growth"]) < 0.02
    assert mixed["max_tilt"] < 1.1 * tfe["physical_max_tilt"] and primal["max_tilt"] > 10 * mixed["max_tilt"]
    # the spin-up beam: the stiffened modal tip follows the ANCF beam, the unstiffened one runs away
    flex = scenes["flexible-bodies"]["runs"]
    assert flex["2 modes, stiffened"]["peak_relative_error"] < 5e-3
    assert flex["2 modes, stiffened"]["max_error_m"] < 0.02
    assert (flex["2 modes, no stiffening"]["max_error_m"] or math.inf) > 1.0
    # ... and the summary says so next to the integration's own status
    assert flex["2 modes, stiffened"]["against_reference"] == "agrees"
    assert flex["2 modes, no stiffening"]["against_reference"] == "departs"
    # the simplified implicit midpoint steps over the axial mode (50 ms, 14 times RK4's limit)
    implicit = flex["2 modes, stiffened, implicit midpoint 50 ms"]
    assert implicit["status"] == "success" and implicit["max_error_m"] < 2e-3
    # controls: the push moves the flange by millimetres and the servo catches it; a sampled
    # torque history gives MuJoCo's trajectory; jax.grad of the reach loss is the central difference
    controls = scenes["controls"]
    # the push spins joint 6 past its URDF velocity limit (2.61 rad/s): a note, not a failure
    assert controls["runs"]["pushed"]["status"] in ("success", "limit exceeded")
    assert 1e-3 < controls["runs"]["pushed"]["peak_flange_displacement_m"] < 0.1
    if peers.available("mujoco"):
        assert controls["runs"]["sampled"]["max_abs_diff_mujoco_rad"] < 1e-9
        assert controls["peers"]["mujoco"]["status"] == "compared"
    else:
        assert controls["peers"]["mujoco"]["status"] == "unavailable: mujoco is not installed"
    for row in controls["gradients"].values():
        assert row["relative_difference"] < 1e-6


def _check_carpal_wrist(scenes):
    # the Carpal Wrist: the chapter's explicit Euler fails first, where the others hold
    # (quick: against RK4; test_time_response checks all four boundaries)
    wrist = scenes["carpal-wrist"]["integrators"]
    assert not wrist["explicit_euler dt=10 ms"]["stable"] and wrist["rk4 dt=10 ms"]["stable"]
    assert not wrist["rk4 dt=40 ms"]["stable"]
    # models: the arm's frames by name, its limits in the status, its dynamics against the peers
    models = scenes["models"]
    assert "flange" in models["frames"] and models["status"] == "limit exceeded"
    assert 0 < models["first_limit_exceeded_s"] < 0.6
    for peer in ("pinocchio", "mujoco"):        # or, where not installed, says so
        record = models["peers"][peer]
        if peers.available(peer):
            assert record["status"] == "compared" and record["max_relative_difference"] < 1e-12
        else:
            assert record["status"] == peers.missing(peer)
    # trajectory optimisation: iLQR brings the arm's flange to its target
    reach = scenes["trajectory-optimisation"]["runs"]["ilqr"]
    assert reach["status"] == "success" and reach["final_error_m"] < 1e-5


def _check_legged_gait(scenes):
    # ANYmal's trot: iLQR solves it in two compiled phases, every foot on the ground pushing;
    # Crocoddyl's FDDP on the same problem reaches the same optimum (or, not installed, says so)
    scene = scenes["legged-gait"]
    run = scene["runs"]["ilqr"]
    assert run["status"] == "success" and run["phases"] == 2
    assert run["least_normal_force_on_the_ground_n"] > 0
    record = scene["peers"]["crocoddyl"]
    if crocoddyl_working() is None:
        assert record["status"] == "compared" and abs(record["relative_cost"]) < 1e-6
        assert abs(record["mbjax_cost_in_crocoddyl"] - run["cost"]) < 1e-8 * run["cost"]
    else:
        assert record["status"] != "compared"


def _check_contacts(scenes):
    # the Ant and the HalfCheetah dropped on the floor land and settle as MuJoCo's runs of the
    # same files do, to round-off (the same soft constraints, the same integrators)
    scene = scenes["contacts"]
    assert scene["peers"]["mujoco"]["status"] == "compared"
    for run in scene["runs"].values():
        assert run["status"] == "success" and run["height_error_max_m"] < 1e-9


def _check_mpc(scenes):
    # the arm follows its circle through the push within a few millimetres, every tick solved
    # within the control period at the median; Crocoddyl's loop on the same plant tracks alike
    scene = scenes["mpc"]
    run = scene["runs"]["mbjax"]
    assert run["tracking_error_rms_m"] < 0.01 and run["solve_ms_median"] < 10.0
    record = scene["peers"]["crocoddyl"]
    if crocoddyl_working() is None:
        assert abs(record["tracking_error_rms_m"] - run["tracking_error_rms_m"]) < (
            0.01 * run["tracking_error_rms_m"])


TOUR_CHECKS = {"rigid": _check_rigid, "time-elements": _check_time_elements,
               "carpal-wrist": _check_carpal_wrist, "legged-gait": _check_legged_gait,
               "contacts": _check_contacts, "mpc": _check_mpc}


@pytest.mark.slow     # a benchmark script: the library is tested in tests/wrist
def test_bench_wrist_quick(tmp_path):
    """`mbjax bench wrist --quick` (a README claim; about 15 s): RK4's error falls at fourth
    order, the Lagrange and Newton-Euler inverse dynamics agree, the sweep covers every variant
    with finite, distinct peak torques."""
    assert main(["bench", "wrist", "--quick", "--out", str(tmp_path)]) == 0
    records = [json.loads(line) for line in (tmp_path / "wrist.jsonl").read_text().splitlines()
               if line]
    wp = sorted((r for r in records if r["kind"] == "work-precision"), key=lambda r: r["dt"])
    assert len(wp) == 2 and all(r["status"] == "success" for r in wp)
    ratio = wp[1]["error"] / wp[0]["error"]
    assert 4**4 / 3 < ratio < 4**4 * 3, ratio                    # dt 4x: error 256x
    routes = [r for r in records if r["kind"] == "route"]
    assert len(routes) == 3 and all(r["lagrange_newton_euler_max_diff"] < 1e-9 for r in routes)
    sweep = [r for r in records if r["kind"] == "sweep"]
    assert sweep and sweep[0]["variants"] == 125
    assert 0 < sweep[0]["peak_torque_min"] < sweep[0]["peak_torque_max"] < np.inf
    assert (tmp_path / "wrist.png").stat().st_size > 10_000


@pytest.mark.slow     # a benchmark script: the integrators are tested in tests/integrate
def test_bench_integrators_quick(tmp_path):
    assert main(["bench", "integrators", "--quick", "--out", str(tmp_path)]) == 0
    records = [json.loads(line) for line in (tmp_path / "integrators.jsonl").read_text().split("\n")
               if line]
    engines = {r["engine"] for r in records}
    assert "mbjax" in engines
    if peers.available("mujoco"):
        assert "mujoco" in engines
        # same chart, same step: MuJoCo's RK4 and mbjax's RKMK4 land on the same answer
        by = {(r["engine"], r["integrator"], r["batch"]): r for r in records}
        assert abs(by[("mbjax", "rkmk4", 1)]["error"] - by[("mujoco", "RK4", 1)]["error"]) < 1e-9
    assert (tmp_path / "integrators.png").exists()


@pytest.mark.slow
def test_bench_rigid_quick(tmp_path):
    """About a minute on 2 cores: every record kind is there and mbjax agrees with the peers."""
    assert main(["bench", "rigid", "--quick", "--out", str(tmp_path)]) == 0
    records = [json.loads(line) for line in (tmp_path / "rigid.jsonl").read_text().split("\n") if line]
    assert {r["kind"] for r in records} == {"forward", "looped", "gradient", "summary"}
    single = [r for r in records if r["kind"] == "forward" and r["engine"] == "mbjax" and r["batch"] == 0]
    assert {r["method"] for r in single} == {"recursive", "dense"}
    assert all(r["run_s"] > 0 and r["compile_s"] >= 0 for r in single)
    assert all(r["rel_diff"] < 1e-9 for r in records if "rel_diff" in r)
    assert all(r["finite"] and r["grad_over_forward"] > 0 for r in records if r["kind"] == "gradient")
    if peers.available("pinocchio"):
        assert any(r["engine"] == "pinocchio" and "per_state_s" in r for r in records)
    assert (tmp_path / "rigid.png").stat().st_size > 10_000


@pytest.mark.slow     # tests/tfe/test_stability checks the tables; notebook 03 prints them
def test_reproduce_vertical_top(tmp_path):
    """Borri 1990 Tables 1-2 (the quick run's rows) to the issue's tolerances, and eq 7.10."""
    assert main(["reproduce", "vertical-top", "--quick", "--out", str(tmp_path)]) == 0
    data = json.loads((tmp_path / "vertical-top.json").read_text())
    assert set(data) >= {"exact", "reduced", "stability_boundary"}
    for quadrature in ("exact", "reduced"):
        assert set(data[quadrature]) == {"2", "3", "4"}
        for nodes, rows in data[quadrature].items():
            paper = {row["dt"]: row for row in data["paper"][quadrature][nodes]}
            assert len(rows) >= 3
            for row in rows:
                assert set(row) == {"dt", "re", "im"}
                printed = paper[row["dt"]]
                assert abs(row["im"] - printed["im"]) < 2e-4
                if printed["re"] > 1e-4:
                    assert abs(row["re"] / printed["re"] - 1) < 0.01, (quadrature, nodes, row)
                else:
                    assert abs(row["re"]) < 1e-4
    b = data["stability_boundary"]
    assert set(b) >= {"omega", "dt", "exact", "reduced", "physical"}
    assert abs(b["omega"] - 5 / 3) < 1e-12
    closed = [b["physical"] * math.sqrt(1 + (b["omega"] * dt) ** 2 / 12) for dt in b["dt"]]
    for found, expected in zip(b["exact"], closed, strict=True):
        assert abs(found / expected - 1) < 1e-8
    assert all(abs(found / b["physical"] - 1) < 1e-8 for found in b["reduced"] + b["mixed"])
    assert (tmp_path / "vertical-top.png").stat().st_size > 10_000


@pytest.mark.slow
def test_reproduce_torque_free_tfe(tmp_path):
    """Borri 1990 Fig. 1 over the quick run's 2 s: the issue's keys, every case converged, errors
    well below 0.2 rad, and the mixed 4-node element ahead of the primal one at every spacing;
    the accuracy status (rtol 1e-3, atol 1e-4) is inaccurate exactly where the error against
    the closed form is past 1e-3 rad, and the estimate within a factor 10 of that error."""
    assert main(["reproduce", "torque-free-tfe", "--quick", "--out", str(tmp_path)]) == 0
    data = json.loads((tmp_path / "torque-free-tfe.json").read_text())
    cases = {(c["form"], c["nodes"], c["spacing"]): c for c in data["cases"]}
    assert {(n, s) for _, n, s in cases} == {(2, 0.015), (3, 0.015), (4, 0.015), (4, 0.03), (4, 0.045)}
    for case in cases.values():
        assert set(case) >= {"form", "nodes", "spacing", "t", "error", "max_error", "seconds"}
        assert case["seconds"] > 0
        assert len(case["t"]) == len(case["error"]) and case["max_error"] == max(case["error"])
        assert case["max_error"] < 0.2
        assert case["status"] == ("inaccurate" if case["max_error"] > 1e-3 else "success"), case
        assert case["max_error"] / 10 < case["error_estimate"] < 10 * case["max_error"]
    for spacing in (0.015, 0.03, 0.045):
        assert cases[("mixed", 4, spacing)]["max_error"] < cases[("primal", 4, spacing)]["max_error"]
    assert (tmp_path / "torque-free-tfe.png").stat().st_size > 10_000


@pytest.mark.slow
def test_reproduce_top_long_run(tmp_path):
    """Every run's measured growth matches its one-element map; the mixed form about the steady
    rotation conserves energy and vertical angular momentum; the accuracy status (the tilt to
    about 0.01 rad) is inaccurate exactly for the runs whose tilt leaves 0.01 rad (the physical
    one stays below 1e-3)."""
    assert main(["reproduce", "top-long-run", "--quick", "--out", str(tmp_path)]) == 0
    data = json.loads((tmp_path / "top-long-run.json").read_text())
    runs = {(r["form"], r["march"]): r for r in data["runs"]}
    assert len(runs) == 6
    for r in runs.values():
        assert r["status"] == ("inaccurate" if r["max_tilt"] > 0.01 else "success"), r["form"]
    for r in runs.values():
        if r["predicted_growth"] > 0.05:
            assert abs(r["measured_growth"] / r["predicted_growth"] - 1) < 0.1, r["form"]
        else:
            assert abs(r["measured_growth"]) < 0.02
    mixed = runs[("mixed", "steady")]
    assert max(map(abs, mixed["energy_error"])) < 1e-12 and max(map(abs, mixed["momentum_error"])) < 1e-12
    assert runs[("primal", "steady")]["max_tilt"] > 100 * data["tilt0"]


@pytest.mark.slow
def test_bench_tfe_quick(tmp_path):
    """Every method ran and converged; the 4-node elements beat the 2-node ones in accuracy."""
    assert main(["bench", "tfe", "--quick", "--out", str(tmp_path)]) == 0
    records = [json.loads(line) for line in (tmp_path / "tfe.jsonl").read_text().split("\n") if line]
    assert {r["scene"] for r in records} == {"torque-free body", "heavy top"}
    assert all(r["status"] == "success" and r["run_s"] > 0 for r in records)
    for scene in ("torque-free body", "heavy top"):
        best = {}
        for r in records:
            if r["scene"] == scene and r["family"] == "tfe":
                key = (r["form"], r["nodes"])
                best[key] = min(best.get(key, math.inf), r["error"])
        assert all(best[(form, 4)] < best[(form, 2)] / 100 for form in ("primal", "mixed"))
    assert (tmp_path / "tfe.png").stat().st_size > 10_000


@pytest.mark.slow
def test_bench_loops_quick(tmp_path):
    """Every route ran; smaller steps are more accurate; the two routes agree in the scaling."""
    assert main(["bench", "loops", "--quick", "--out", str(tmp_path)]) == 0
    records = [json.loads(line) for line in (tmp_path / "loops.jsonl").read_text().split("\n") if line]
    wp = [r for r in records if r["kind"] == "work-precision"]
    assert {r["route"] for r in wp} == {"coupled", "O(n + m^3)"}
    for route in ("coupled", "O(n + m^3)"):
        rows = sorted((r for r in wp if r["route"] == route), key=lambda r: r["dt"])
        assert rows[0]["error"] < rows[-1]["error"] / 8          # RK4: 16x per halving
    scaling = [r for r in records if r["kind"] == "scaling"]
    assert all(r["status"] == "success" and r["max_abs_diff"] < 1e-10 for r in scaling)
    assert (tmp_path / "loops.png").stat().st_size > 10_000


@pytest.mark.slow
def test_reproduce_closed_chain(tmp_path):
    """The issue's keys; the two formulations agree; projection holds the constraints, no
    stabilization drifts above it."""
    assert main(["reproduce", "closed-chain", "--quick", "--out", str(tmp_path)]) == 0
    data = json.loads((tmp_path / "closed-chain.json").read_text())
    assert set(data) == {"n", "recursive_s", "dense_s", "max_abs_diff", "drift", "drift_status"}
    assert len({len(data[k]) for k in ("n", "recursive_s", "dense_s", "max_abs_diff")}) == 1
    assert max(data["max_abs_diff"]) < 1e-8
    final = {name: rows[-1][1] for name, rows in data["drift"].items()}
    assert final["projection"] < 1e-10 < final["none"]
    assert final["baumgarte"] < final["none"]
    # Anderson 1993's epsilon-dynamics: the position feedback bounds the drift the paper's form leaves
    assert final["epsilon=0.2,kappa=10"] < final["epsilon=0.2"] / 5
    # each run's status says what its residual shows (the closed system's tolerance is 1e-6)
    for name, check in data["drift_status"].items():
        assert ("constraint violated" in check["status"]) == (
            max(r for _, r in data["drift"][name]) > 1e-6), (name, check)
    assert data["drift_status"]["projection"]["energy_drift"] < 1e-3
    assert (tmp_path / "closed-chain.png").stat().st_size > 10_000


@pytest.mark.slow
def test_reproduce_spin_up_beam(tmp_path):
    """Kane's spin-up beam, quick (10 s, 4 bending modes, ANCF with 8 elements; about 1.5 min on
    2 cores, most of it compiling): the issue's keys in metres; with geometric stiffening the modal
    tip lags and peaks within 0.5 % of the independent ANCF beam (Kane et al.: about -0.57 m near
    7 s) and stays within 1e-3 m of it over the whole run; without stiffening it runs away once omega nears the first
    bending frequency (3.8 rad/s), far beyond the stiffened tip, while still valid JSON."""
    assert main(["reproduce", "spin-up-beam", "--quick", "--out", str(tmp_path)]) == 0
    text = (tmp_path / "spin-up-beam.json").read_text()
    data = json.loads(text)
    assert "NaN" not in text and "Infinity" not in text
    contract = ("t", "tip_deflection", "tip_deflection_no_stiffening", "axial_tip_displacement")
    assert set(contract) <= set(data)
    assert len({len(data[k]) for k in contract}) == 1 and data["t"][0] == 0.0 and data["t"][-1] >= 8.0
    tip = [float("nan") if v is None else v for v in data["tip_deflection"]]
    free = [float("inf") if v is None else abs(v) for v in data["tip_deflection_no_stiffening"]]
    ref = data["reference"]
    assert ref["t"] == data["t"] and ref["n_elements"] >= 4
    peak, ref_peak = min(tip), min(ref["tip_deflection"])
    assert -0.6 < ref_peak < -0.54 and 6.0 < data["t"][tip.index(peak)] < 8.0
    assert abs(peak - ref_peak) < 5e-3 * abs(ref_peak)
    assert max(abs(a - b) for a, b in zip(tip, ref["tip_deflection"])) == data["max_abs_difference"]
    assert data["max_abs_difference"] < data["history_tolerance"] == 1e-3
    assert data["history_status"] == "success"
    assert all(math.isfinite(x) and x <= 1e-6 for x in tip)         # the tip lags throughout
    assert data["status"] == "success"
    assert free[-1] > 20 * max(abs(x) for x in tip)
    # the centrifugal stretch: positive, below the rigid bound m omega^2 L^2 / (3 E A) = 0.5 mm;
    # the tip's axial displacement is dominated by the bending's foreshortening, as in the ANCF beam
    assert 0.0 < data["axial_stretch"][-1] < 5.2e-4
    k = tip.index(peak)
    axial, ref_axial = data["axial_tip_displacement"][k], ref["tip_axial"][k]
    assert ref_axial < -0.01 and abs(axial - ref_axial) < 0.05 * abs(ref_axial)
    assert (tmp_path / "spin-up-beam.png").stat().st_size > 10_000


@pytest.mark.slow
def test_reproduce_flexible_slider_crank(tmp_path):
    """Anderson 1993 Fig. 5, quick (one crank revolution, 1 and 2 elements): the issue's keys; the
    2-element rod's peak midpoint deflection within 8 % of the ANCF rod's, closer than 1
    element's, and the deflection first bows away from O (positive) as the rod is pulled."""
    assert main(["reproduce", "flexible-slider-crank", "--quick", "--out", str(tmp_path)]) == 0
    data = json.loads((tmp_path / "flexible-slider-crank.json").read_text())
    assert {"t", "midpoint_deflection_in"} <= set(data)
    assert len(data["t"]) == len(data["midpoint_deflection_in"]) > 50
    assert data["midpoint_deflection_in"] == data["by_elements"][str(data["n_elements"])]
    assert set(data["by_elements"]) >= {"1", "2"}
    d = data["midpoint_deflection_in"]
    assert all(v is not None and math.isfinite(v) for v in d)
    ref = data["reference"]["midpoint_deflection_in"]
    peak, ref_peak = max(map(abs, d)), max(map(abs, ref))
    assert 0.05 < ref_peak < 0.3                      # inches: Anderson 1993 Fig. 5's scale
    assert abs(peak - ref_peak) < 0.08 * ref_peak
    one = max(map(abs, data["by_elements"]["1"]))
    assert abs(peak - ref_peak) < abs(one - ref_peak)
    assert all(s == "success" for s in data["status"].values())
    assert data["max_abs_differences"]["2"] < data["history_tolerance_in"] == 0.01
    assert data["history_status"]["2"] == "success"
    assert data["history_status"]["1"].startswith("inaccurate") == (data["max_abs_differences"]["1"] > 0.01)
    assert (tmp_path / "flexible-slider-crank.png").stat().st_size > 10_000


@pytest.mark.slow
def test_bench_flexible_quick(tmp_path):
    """Both scenes, quick (a few minutes on 2 cores, mostly compilation): on the spin-up beam
    (0-8 s) more modes are more accurate, 4 modes within 1e-3 m of the 8-element ANCF beam with RK4
    and with the simplified implicit midpoint at 14 times RK4's step; without geometric stiffening
    the error is orders of magnitude larger; on the slider-crank the 2-element rod is within
    0.01 in; exudyn's ANCF cable agrees with mbjax's ANCF beams (or says why not); the summaries
    name the fastest run within each tolerance."""
    assert main(["bench", "flexible", "--quick", "--out", str(tmp_path)]) == 0
    records = [json.loads(line) for line in (tmp_path / "flexible.jsonl").read_text().split("\n") if line]
    spin = [r for r in records if r["scene"] == "spin-up"]
    assert {r["kind"] for r in spin} >= {"ancf", "modal", "peer", "summary"}
    modal = {(r["n_bending"], r["stiffening"], r["integrator"][:4]): r for r in spin if r["kind"] == "modal"}
    assert set(modal) == {(1, True, "rk4"), (4, True, "rk4"), (4, True, "impl"), (4, False, "rk4")}
    assert all(r["status"] == "success" and r["run_s"] > 0 for r in modal.values())
    assert modal[4, True, "rk4"]["error"] < modal[1, True, "rk4"]["error"] / 2
    assert modal[4, True, "rk4"]["error"] < 1e-3 and modal[4, True, "impl"]["error"] < 1e-3
    assert modal[4, True, "impl"]["dt"] > 10 * modal[4, True, "rk4"]["dt"]
    assert modal[4, False, "rk4"]["error"] > 100 * modal[4, True, "rk4"]["error"]
    ancf = [r for r in spin if r["kind"] == "ancf"]
    assert [r["n_elements"] for r in ancf] == [8, 4] and ancf[0]["error"] == 0.0
    assert -0.58 < ancf[0]["peak"] < -0.56
    crank = [r for r in records if r["scene"] == "slider-crank"]
    rod = [r for r in crank if r["kind"] == "modal"]
    assert {r["integrator"][:4] for r in rod} == {"rk4", "impl"}
    assert all(r["error"] < 0.01 for r in rod)
    for scene in (spin, crank):
        exudyn = [r for r in scene if r["kind"] == "peer"]
        if peers.available("exudyn"):
            assert all(r["status"] == "success" and r["error"] < 0.01 for r in exudyn)
        else:
            assert exudyn[0]["status"].startswith("unavailable")
    summary = {(r["scene"], r["of"]): r["fastest"] for r in records if r["kind"] == "summary"}
    assert summary["spin-up", "modal"]["error"] <= 1e-3
    assert (tmp_path / "flexible.png").stat().st_size > 10_000


@pytest.mark.slow
def test_reproduce_carpal_wrist(tmp_path):
    """The issue's JSON schema and claims: explicit Euler unstable at a step where the others are
    stable, as the linearization predicts; Newton-Euler agreement; the synthesized torques inside
    the limit bring the tool closer to the goal than the clipped baseline."""
    assert main(["reproduce", "carpal-wrist", "--quick", "--out", str(tmp_path)]) == 0
    data = json.loads((tmp_path / "carpal-wrist.json").read_text())
    assert (tmp_path / "carpal-wrist.png").stat().st_size > 10_000
    for row in data["integrators"]:
        assert set(row) == {"name", "dt", "error", "energy_drift", "stable"}
    stable = {(r["name"], r["dt"]): r["stable"] for r in data["integrators"]}
    assert not stable[("explicit_euler", 0.01)]
    assert all(stable[(name, 0.01)] for name in ("semi_implicit_euler", "rk4", "implicit_midpoint"))
    assert 0.005 < data["critical_dt"]["explicit_euler"] < 0.01
    assert data["newton_euler_max_diff"] < 1e-10
    trajectory, baseline = data["trajectory"], data["baseline"]
    assert set(trajectory) >= {"final_pose_error", "effort", "iterations"}
    assert trajectory["final_pose_error"] < 0.2 * baseline["pose_error_clipped"]
    assert trajectory["peak_torque"] <= data["torque_limit"] < baseline["peak_torque"]


@pytest.mark.slow
def test_bench_throughput_quick(tmp_path):
    """About three minutes on 2 cores: every record kind, the peers' agreement and the targets."""
    assert main(["bench", "throughput", "--quick", "--out", str(tmp_path)]) == 0
    records = [json.loads(line) for line in (tmp_path / "throughput.jsonl").read_text().splitlines()]
    kinds = {r["kind"] for r in records}
    assert kinds == {"forward", "rollout", "gradient", "summary"}
    ours = [r for r in records if r["kind"] == "forward" and r["engine"] == "mbjax"]
    if peers.available("pinocchio"):
        assert all(r["rel_diff_pinocchio"] < (1e-5 if r["dtype"] == "float32" else 1e-12) for r in ours)
    if peers.available("mujoco"):
        rollouts = [r for r in records if r["kind"] == "rollout" and r["engine"] == "mbjax"]
        assert all(r["max_diff_mujoco_rad"] < 1e-8 for r in rollouts)
    grads = {(r["mode"], r["checkpoint"]): r for r in records if r["kind"] == "gradient"}
    assert all(r["finite"] for r in grads.values())
    assert grads[("grad", True)]["memory_slope"] < 0.7 < grads[("grad", False)]["memory_slope"]
    targets = records[-1]["targets"]
    assert {"forward_vs_pinocchio_per_call", "rollout_vs_mujoco", "gradient_over_forward",
            "gpu_forward_evals_per_s"} <= set(targets)
    for name, t in targets.items():
        # a measured target's verdict follows from its value; an unmeasured one says why
        if t["met"] is None:
            assert t.get("note"), name
        elif t["met"]:
            assert t["missed_by"] is None and t["value"] > 0, (name, t)
        else:      # missed: by the factor between value and target, in the direction that counts
            ratios = (t["value"] / t["target"], t["target"] / t["value"])
            assert t["missed_by"] > 1 and any(np.isclose(t["missed_by"], r) for r in ratios), t
    assert (tmp_path / "throughput.png").stat().st_size > 10_000


def test_compilation_cache_folder_and_switch(tmp_path, monkeypatch):
    """The CLI and notebooks keep compiled programs in a user folder (JAX's config, recorded here
    rather than changed for the test process); MBJAX_NO_CACHE turns it off."""
    import jax

    from mbjax._src.cache import cache_folder, use_compilation_cache

    updates = {}
    monkeypatch.setattr(jax.config, "update", lambda key, value: updates.__setitem__(key, value))
    monkeypatch.delenv("JAX_COMPILATION_CACHE_DIR", raising=False)
    monkeypatch.delenv("JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert cache_folder() == tmp_path / "mbjax" / "jax"
    assert use_compilation_cache() == tmp_path / "mbjax" / "jax" and (tmp_path / "mbjax" / "jax").is_dir()
    assert updates == {"jax_compilation_cache_dir": str(tmp_path / "mbjax" / "jax"),
                       "jax_persistent_cache_min_compile_time_secs": 0.0}
    monkeypatch.setenv("MBJAX_NO_CACHE", "1")
    updates.clear()
    assert use_compilation_cache() is None and not updates


@pytest.mark.slow
def test_bench_speed_quick(tmp_path):
    """The 7-link chain through every library of `mbjax bench speed`: every peer that imports
    agrees with mbjax, gradients are finite, the checkpointed gradient's memory grows like
    sqrt(T), the targets are recorded."""
    assert main(["bench", "speed", "--quick", "--out", str(tmp_path)]) == 0
    records = [json.loads(line) for line in (tmp_path / "speed.jsonl").read_text().splitlines()]
    rows = {r["library"]: r for r in records if "library" in r and "skipped" not in r}
    assert "mbjax" in rows and rows["mbjax"]["grad_finite"]
    kernels = rows["mbjax"]["kernels"]
    assert kernels["entry"] and (kernels["per_step"] or kernels["one_kernel_loops"])
    for peer in ("pinocchio", "jaxsim", "adam", "frax"):
        if peer in rows:
            assert rows[peer]["rel_diff_mbjax"] < 1e-12
    assert rows["mbjax"]["jac_s"] > 0 and rows["mbjax"]["jac_vmap_s"] > 0
    if "pinocchio" in rows:
        assert rows["pinocchio"]["jac_s"] > 0
    memory = rows["mbjax"]["grad_memory"]          # XLA's compiled sizes, not timings
    assert memory["plain"]["slope"] > 0.9 and memory["checkpoint"]["slope"] < 0.6
    targets = records[-1]["targets"]
    assert any(t["target"].startswith("chain7: one jitted call's fixed cost") for t in targets)
    assert (tmp_path / "speed.png").stat().st_size > 10_000


@pytest.mark.slow
def test_bench_compile(tmp_path):
    """`mbjax bench compile` (about 2.5 min on 2 cores): the warm tour loads from the persistent
    cache every program the cold tour compiled, scene by scene (no timing is asserted), with a
    worker per core and one scene at a time; the first calls outside jit are recorded; each
    scene's target is there."""
    from mbjax_harness.parallel import cores

    assert main(["bench", "compile", "--out", str(tmp_path)]) == 0
    records = [json.loads(line) for line in (tmp_path / "compile.jsonl").read_text().splitlines()]
    tours = {(r["jobs"], r["cache"]): r for r in records if r["kind"] == "tour"}
    assert set(tours) == {(jobs, cache) for jobs in (1, cores()) for cache in ("cold", "warm")}
    assert {n: s["programs"] for n, s in tours[1, "warm"]["scenes"].items()} == \
        {n: s["programs"] for n, s in tours[1, "cold"]["scenes"].items()}
    assert all(s["programs"] > 0 for s in tours[1, "cold"]["scenes"].values())
    assert all(set(tour["scenes"]) == set(TOUR_GROUPS_ALL) for tour in tours.values())
    first = next(r for r in records if r["kind"] == "first_calls")
    assert set(first["forward_dynamics"]) == set(first["mass_matrix"]) == {"first_s", "call_s"}
    targets = {t["target"] for t in records[-1]["targets"]}
    assert {f"scene {name}, cold cache" for name in TOUR_GROUPS_ALL} < targets
    assert (tmp_path / "compile.png").stat().st_size > 10_000


@pytest.mark.slow     # every solver on every problem: tests/trajopt checks each
def test_reproduce_trajopt(tmp_path):
    """`mbjax reproduce trajopt --quick`: each problem by iLQR and the arm by multiple shooting
    too (the first-order baselines and the other problems' shooting are the full run's), the
    JSON's keys, each problem's animation;
    iLQR reaches the arm's target (to 1e-5 m; multiple shooting too, at iLQR's optimum), the acrobot's upright pose (to 1e-2 m), the
    four-bar's crank angle (1e-4 rad) and the slewing beam's goal with its tip still (within
    0.1 mm while it coasts), with the lowest cost, and the Carpal Wrist's goal pose under its
    torque limit."""
    assert main(["reproduce", "trajopt", "--quick", "--out", str(tmp_path)]) == 0
    data = json.loads((tmp_path / "trajopt.json").read_text())
    rows = {(r["name"], r["solver"]): r for r in data["problems"]}
    assert set(rows) == {("arm-reach", "multiple-shooting")} | {
        (p, "ilqr") for p in ("arm-reach", "acrobot-swingup", "four-bar", "slewing-beam",
                              "carpal-wrist")}
    for row in rows.values():
        assert set(row) >= {"name", "solver", "iterations", "seconds", "final_error", "cost",
                            "status"}
        assert row["iterations"] > 0 and row["seconds"] > 0 and math.isfinite(row["cost"])
    for problem, error in (("arm-reach", 1e-5), ("acrobot-swingup", 1e-2), ("four-bar", 1e-4),
                           ("slewing-beam", 1e-4)):
        ilqr = rows[problem, "ilqr"]
        assert ilqr["status"] == "success" and ilqr["final_error"] < error
        assert all(ilqr["cost"] <= row["cost"] for (p, _), row in rows.items() if p == problem)
    # multiple shooting lands on iLQR's optimum of the arm's reach (to 1e-4: the merit's tail)
    ms, ilqr = rows["arm-reach", "multiple-shooting"], rows["arm-reach", "ilqr"]
    assert ms["status"] == "success" and ms["final_error"] < 1e-5
    assert abs(ms["cost"] - ilqr["cost"]) <= 1e-4 * ilqr["cost"]
    # the Carpal Wrist's START -> GOAL under the torque limit: the issue asks 1e-3 (Adam's
    # synthesis reached 4.9e-3); iLQR's tail, the effort among clamped torques, is slow
    assert rows["carpal-wrist", "ilqr"]["final_error"] < 1e-4
    assert (tmp_path / "trajopt.png").stat().st_size > 10_000
    from PIL import Image                      # each problem's iLQR solution moving
    assert set(data["animations"]) == {p for p, _ in rows}
    for gif_name in data["animations"].values():
        with Image.open(tmp_path / gif_name) as gif:
            assert gif.format == "GIF" and gif.n_frames >= 15


@pytest.mark.slow     # a benchmark script: MPC is tested in tests/trajopt/test_mpc.py
def test_bench_mpc_quick(tmp_path):
    """`mbjax bench mpc --quick` writes mpc.jsonl with the issue's keys: a row per problem and
    engine (problem, engine, control_rate_hz, solve_ms_median, solve_ms_max, tracking_error,
    status) and a row per engine for the batch (problem, engine, robots, seconds); the two
    engines' loops on the same plant track alike."""
    assert main(["bench", "mpc", "--quick", "--out", str(tmp_path)]) == 0
    records = [json.loads(line) for line in (tmp_path / "mpc.jsonl").read_text().splitlines()]
    rows = [r for r in records if "solve_ms_median" in r]
    assert {r["engine"] for r in rows} >= {"mbjax"} and rows
    for r in rows:
        assert {"problem", "engine", "control_rate_hz", "solve_ms_median", "solve_ms_max",
                "tracking_error", "status"} <= set(r)
    batch = [r for r in records if "robots" in r]
    assert batch and all({"problem", "engine", "robots", "seconds"} <= set(r) for r in batch)
    if crocoddyl_working() is None:
        for problem in {r["problem"] for r in rows}:
            ours, theirs = (next(r for r in rows if r["problem"] == problem and r["engine"] == e)
                            for e in ("mbjax", "crocoddyl"))
            assert abs(ours["tracking_error"] - theirs["tracking_error"]) < (
                0.01 * theirs["tracking_error"])
