"""The examples in examples/python run and write what they say (CTest: python_examples).
The batch study runs on a 2-worker LocalCluster (processes, a thread each) over 56 target sets on
the default bar and one bad one, which is reported failed while every other completes."""

import csv
import json
import re
import signal
import subprocess
import sys

import matplotlib.image
import numpy as np
import pytest

import shapectl
from conftest import BAR, SOURCE_DIR

EXAMPLES = SOURCE_DIR / "examples" / "python"
sys.path.insert(0, str(EXAMPLES))
from bar_shapes import bent_centerline  # noqa: E402


def run_example(name, *args, cwd):
    completed = subprocess.run([sys.executable, str(EXAMPLES / name), *map(str, args)],
                               capture_output=True, text=True, cwd=cwd)
    assert completed.returncode == 0, completed.stdout + completed.stderr
    return completed


def png(path, height, width):
    image = matplotlib.image.imread(path)
    assert image.shape == (height, width, 4)  # the figure size at 100 dpi, RGBA
    assert np.isfinite(image).all() and image[..., :3].std() > 0  # something drawn
    return image


def test_solve_convergence_plots_both_optimizers(tmp_path):
    out = run_example("solve_convergence.py", "--out", tmp_path / "convergence.png", cwd=tmp_path)
    png(tmp_path / "convergence.png", 400, 1000)
    assert "gauss-newton: " in out.stdout and "lbfgs: " in out.stdout


def test_centerline_sweep_charts_the_reachable_error(tmp_path):
    run_example("centerline_sweep.py", "--steps", 4, "--max-lift", 0.06,
                "--out", tmp_path / "sweep.png", cwd=tmp_path)
    png(tmp_path / "sweep.png", 450, 700)
    numbers = np.load(tmp_path / "sweep.npz")
    np.testing.assert_allclose(numbers["lift"], [0, 0.02, 0.04, 0.06])
    for key in ("up_error_mean", "up_error_max", "up_and_sideways_error_mean"):
        assert numbers[key].shape == (4,) and np.isfinite(numbers[key]).all(), key
        assert (numbers[key] >= 0).all()
    assert (numbers["up_error_max"] >= numbers["up_error_mean"]).all()


def test_make_dataset_writes_equilibria_at_sampled_joints(tmp_path, bar_scene):
    run_example("make_dataset.py", "--samples", 12, "--seed", 3, "--out", tmp_path / "d.npz",
                cwd=tmp_path)
    data = np.load(tmp_path / "d.npz")
    joints, positions = data["joints"], data["positions"]
    count = len(joints)
    assert count >= 10, count  # a few may be left out, not most
    assert joints.shape == (count, 14) and positions.shape == (count, 425, 3)
    assert data["min_clearance"].shape == (count,) and (data["min_clearance"] > 0).all()
    assert np.isfinite(joints).all() and np.isfinite(positions).all()
    assert list(data["joint_names"]) == bar_scene.joint_names
    assert data["tets"].shape == (bar_scene.tet_count, 4)
    # Each sample is the equilibrium at its joints, and the samples differ.
    np.testing.assert_array_equal(positions[5], shapectl.statics(bar_scene, joints[5]).positions)
    assert np.abs(positions[0] - positions[1]).max() > 1e-3


def test_batch_reachability_on_two_local_workers_reports_the_bad_task(tmp_path, bar_scene):
    bad = {"targets": [{"node": 425, "position": [0.4, 0.0, 0.3]}]}  # the bar has 425 nodes
    (tmp_path / "extra.json").write_text(json.dumps([bad]))
    out = run_example("batch_reachability.py", "--scene", BAR, "--lifts", 8, "--shifts", 7,
                      "--extra", tmp_path / "extra.json", "--workers", 2,
                      "--max-iterations", 20, "--out", tmp_path / "reach", cwd=tmp_path)
    assert "57 target sets:" in out.stdout and "1 failed" in out.stdout
    last = out.stderr.split("\r")[-1]  # the progress bar's last state
    assert "57/57" in last and "failed=1" in last, out.stderr

    table = np.load(tmp_path / "reach.npz")
    np.testing.assert_array_equal(table["task"], np.arange(57))
    status = list(table["status"])
    assert status[:56] == ["done"] * 56 and status[56] == "failed"
    error = str(table["error"][56])
    assert error.startswith("ValueError: targets: targets[0].node") and "425" in error
    assert all(e == "" for e in table["error"][:56])
    assert table["joints"].shape == (57, 14)
    assert np.isfinite(table["joints"][:56]).all() and np.isnan(table["joints"][56]).all()
    assert np.isfinite(table["error_mean"][:56]).all() and np.isnan(table["error_mean"][56])
    assert np.isnan(table["lift"][56]) and len(set(table["lift"][:56])) == 8
    # Both worker processes took tasks.
    assert len({w for w in table["worker"][:56]}) == 2, set(table["worker"])
    # A row is the solve this process computes for its target set.
    k = 30
    mine = shapectl.solve(bar_scene, bent_centerline(bar_scene, table["lift"][k], table["shift"][k]),
                          max_iterations=20)
    np.testing.assert_allclose(table["joints"][k], mine.joints, rtol=0, atol=1e-12)
    assert table["error_mean"][k] == pytest.approx(mine.error_mean, rel=1e-9)
    assert table["termination"][k] == mine.termination

    with open(tmp_path / "reach.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 57
    assert list(rows[0])[:3] == ["lift", "shift", "task"] and list(rows[0])[-1] == "error"
    assert all(name in rows[0] for name in bar_scene.joint_names)
    assert rows[56]["status"] == "failed" and rows[56]["error"] == error


def test_ctrl_c_stops_the_batch_study_and_keeps_the_finished_rows(tmp_path):
    # A study far longer than the test: SIGINT (Ctrl-C) once a few solves are in.
    study = subprocess.Popen(
        [sys.executable, str(EXAMPLES / "batch_reachability.py"), "--scene", str(BAR),
         "--lifts", "30", "--shifts", "30", "--workers", "1", "--out", str(tmp_path / "reach")],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    progress = ""
    while not re.search(r"\b([3-9]|\d\d+)/900\b", progress):
        chunk = study.stderr.read(1)
        assert chunk, "the study ended before 3 solves: " + progress
        progress += chunk
    study.send_signal(signal.SIGINT)
    stderr = progress + study.stderr.read()
    assert study.wait(timeout=60) == 130, stderr
    finished = int(re.search(r"wrote the (\d+) of 900 target sets finished", stderr).group(1))
    assert 3 <= finished < 900, stderr

    table = np.load(tmp_path / "reach.npz")
    assert len(table["task"]) == finished and set(table["status"]) == {"done"}
    assert np.isfinite(table["joints"]).all() and table["joints"].shape == (finished, 14)
    with open(tmp_path / "reach.csv", newline="") as f:
        assert len(list(csv.DictReader(f))) == finished
