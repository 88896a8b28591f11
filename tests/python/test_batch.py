"""shapectl.batch on an in-process cluster: one row per task in order, whatever happened to it
(batch_reachability's test runs it on worker processes)."""

import csv
import io

import numpy as np

import shapectl
import shapectl.batch as batch
from distributed import Client, LocalCluster


def test_every_task_has_its_row_even_when_it_raises_something_unexpected(bar_scene, tmp_path):
    positions = shapectl.statics(bar_scene).positions
    lifted = {"targets": [{"node": 212, "position": positions[212] + [0, 0, 0.01]}]}
    not_json = {"targets": [{"node": 212, "position": {1, 2, 3}}]}  # a set: json_from's TypeError
    tasks = [lifted, not_json, {"targets": [{"node": -1, "position": [0, 0, 0]}]}, lifted]
    progress = io.StringIO()
    with LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        rows = batch.solve_many(client, bar_scene, tasks, progress=progress, max_iterations=10)

    assert [r["task"] for r in rows] == [0, 1, 2, 3]
    assert [r["status"] for r in rows] == ["done", "failed", "failed", "done"]
    # An exception the task does not catch comes back through Dask: still one row, with it.
    assert rows[1]["error"].startswith("TypeError: targets: not JSON serializable: set")
    assert rows[2]["error"].startswith("ValueError: targets: targets[0].node: expected")
    assert rows[0]["error_mean"] < 1e-3 and rows[0]["joints"] == rows[3]["joints"]
    # tqdm's bar: its last state counts every task, with the failures.
    last = progress.getvalue().rstrip("\n").split("\r")[-1]
    assert "4/4" in last and "failed=2" in last, progress.getvalue()
    # Workers inside this process share its threads: its tuning is left as it was.
    assert shapectl.runtime_settings()["threads"] == 0

    batch.write_table(rows, tmp_path / "t", bar_scene.joint_names)
    table = np.load(tmp_path / "t.npz")
    assert list(table["status"]) == ["done", "failed", "failed", "done"]
    assert table["joints"].shape == (4, 14) and np.isnan(table["joints"][1:3]).all()
    with open(tmp_path / "t.csv", newline="") as f:
        lines = list(csv.reader(f))
    assert lines[0] == list(batch.FIELDS[:-1]) + bar_scene.joint_names + ["error"]
    assert len(lines) == 5 and lines[2][-1] == rows[1]["error"]


def test_each_worker_process_runs_the_tuning_at_its_thread_count(bar_scene):
    positions = shapectl.statics(bar_scene).positions
    lifted = {"targets": [{"node": 212, "position": positions[212] + [0, 0, 0.01]}]}
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        rows = batch.solve_many(client, bar_scene, [lifted], progress=None, max_iterations=3)
        [settings] = client.run(lambda: shapectl.runtime_settings()).values()
    assert rows[0]["status"] == "done"
    assert settings["threads"] == 1 and settings["tbb_thread_limit"] == 1
    assert settings["blas_idle_timeout"] == 4 and settings["keep_freed_heap"]
    assert shapectl.runtime_settings()["threads"] == 0  # the client's process: its own
