"""The `mbjax` command: choices, exit codes and what each subcommand writes."""

import json
import shutil
import subprocess

import pytest

from mbjax.bench import peers
from mbjax.cli import main


def test_console_script_is_installed():
    exe = shutil.which("mbjax")
    assert exe is not None, "the mbjax console script is not on PATH (pip install the package)"
    out = subprocess.run([exe, "reproduce", "--list"], capture_output=True, text=True, check=True)
    assert "integrators" in out.stdout.split()


@pytest.mark.parametrize("argv", [["reproduce", "nope"], ["bench", "nope"], ["frobnicate"],
                                  ["tour", "--bogus"], ["reproduce"]])
def test_bad_names_and_options_exit_2_with_choices(argv, capsys):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    if argv[0] in ("reproduce", "bench") and len(argv) > 1:
        assert "integrators" in err  # the valid choices are listed
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


def test_tour_quick(tmp_path):
    assert main(["tour", "--quick", "--out", str(tmp_path)]) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert set(summary["scenes"]) == {"torque-free-body", "heavy-top"}
    for scene in summary["scenes"].values():
        assert (tmp_path / scene["figure"]).stat().st_size > 10_000
    assert "torque-free-body" in (tmp_path / "summary.md").read_text()
    rkmk4 = summary["scenes"]["torque-free-body"]["integrators"]["rkmk4"]
    assert rkmk4["final_error_rad"] < 1e-4 and rkmk4["status"] == "success"


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
