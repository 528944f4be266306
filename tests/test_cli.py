"""The `mbjax` command: choices, exit codes and what each subcommand writes."""

import json
import math
import shutil
import subprocess

import pytest

from mbjax.bench import peers
from mbjax.cli import main


def test_console_script_is_installed():
    exe = shutil.which("mbjax")
    assert exe is not None, "the mbjax console script is not on PATH (pip install the package)"
    out = subprocess.run([exe, "reproduce", "--list"], capture_output=True, text=True, check=True)
    assert {"integrators", "tree-scaling"} <= set(out.stdout.split())


@pytest.mark.parametrize("argv", [["reproduce", "nope"], ["bench", "nope"], ["frobnicate"],
                                  ["tour", "--bogus"], ["reproduce"]])
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
    """The JSON of the issue: exactly these keys, finite positive times, one per n."""
    assert main(["reproduce", "tree-scaling", "--quick", "--out", str(tmp_path)]) == 0
    data = json.loads((tmp_path / "tree-scaling.json").read_text())
    keys = {"n", "recursive_s", "dense_s"} | ({"pinocchio_aba_s"} if peers.available("pinocchio") else set())
    assert set(data) == keys
    assert len({len(values) for values in data.values()}) == 1 and len(data["n"]) >= 2
    assert data["n"] == sorted(data["n"]) and min(data["n"]) >= 1
    for key in keys - {"n"}:
        assert all(math.isfinite(t) and t > 0 for t in data[key]), (key, data[key])
    assert (tmp_path / "tree-scaling.png").stat().st_size > 10_000


def test_tour_quick(tmp_path):
    assert main(["tour", "--quick", "--out", str(tmp_path)]) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert set(summary["scenes"]) == {"torque-free-body", "heavy-top", "rigid-chain"}
    for scene in summary["scenes"].values():
        assert (tmp_path / scene["figure"]).stat().st_size > 10_000
    markdown = (tmp_path / "summary.md").read_text()
    assert "torque-free-body" in markdown and "rigid-chain" in markdown
    rkmk4 = summary["scenes"]["torque-free-body"]["integrators"]["rkmk4"]
    assert rkmk4["final_error_rad"] < 1e-4 and rkmk4["status"] == "success"
    chain = summary["scenes"]["rigid-chain"]
    assert chain["reference_status"] == 0
    rows = chain["integrators"]
    assert all(row["status"] == "success" for row in rows.values())
    # RK4 at 5 ms follows the Dopri8 reference of the falling chain to micro-radians
    assert rows["rk4 dt=5 ms"]["error_rad"] < 1e-5 and rows["rk4 dt=5 ms"]["energy_error"] < 1e-5


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
