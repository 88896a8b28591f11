"""Many independent solves fanned out over a Dask cluster, gathered into one table.

    import shapectl, shapectl.batch as batch
    scene = shapectl.Scene.load("scenes/yumi_bar.json")
    with batch.connect() as client:               # a LocalCluster; connect("tcp://host:8786")
        rows = batch.solve_many(client, scene, target_sets, max_iterations=30)
    batch.write_table(rows, "reach", scene.joint_names)     # reach.npz and reach.csv

Every task gives exactly one row, in the order of `target_sets`: a solve that ends (converged
or not) is "done" with its numbers; bad targets, a failed solve, an exception or a lost worker
make it "failed" with the reason in `error`. Nothing is dropped.

The scene travels with the tasks as a dict (Scene.to_dict(): file names absolute), and each
worker process loads it once. On a multi-machine cluster the files it names (URDF, collision
spheres, mesh files) must be at the same paths on every node: shared storage, or shapectl's data
installed under the same prefix everywhere; the bundled scenes' meshes are boxes, inside the dict.

Each worker process runs shapectl's tuning (docs/runtime.md) with TBB's threads at the worker's
thread count, so workers sharing a machine do not each start a thread per core: solve_many
registers a worker plugin for it; workers started by hand get it from
`dask-worker --preload shapectl.batch ...` (dask_setup below) as well.
"""

import contextlib
import csv
import json
import math
import os
import socket
import sys
import threading
import time

import numpy as np

import shapectl

# The numeric and text fields of a row (besides "joints"), in table order.
FIELDS = ("task", "status", "termination", "converged", "iterations", "error_mean", "error_max",
          "min_clearance", "objective", "seconds", "worker", "error")

_scenes = {}  # on a worker: scene dict (as JSON text) -> Scene, loaded once per process
_scenes_lock = threading.Lock()


@contextlib.contextmanager
def connect(scheduler=None, workers=2, threads_per_worker=1):
    """A dask.distributed Client: of the running scheduler at `scheduler` ("tcp://host:8786"),
    or of a LocalCluster of `workers` processes with `threads_per_worker` threads each (one
    thread: a solve keeps a core busy). Closes what it opened."""
    from distributed import Client, LocalCluster

    if scheduler:
        with Client(scheduler) as client:
            yield client
        return
    with LocalCluster(n_workers=workers, threads_per_worker=threads_per_worker, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        yield client


def _configure_worker(worker):
    state = getattr(worker, "state", worker)  # Dask >= 2022.8 keeps nthreads in worker.state
    shapectl.configure_runtime(threads=state.nthreads)


def dask_setup(worker):
    """`dask-worker --preload shapectl.batch`: the worker's tuning at its thread count."""
    _configure_worker(worker)


class RuntimePlugin:
    """A Dask worker plugin: shapectl's tuning in each worker process, TBB's threads at the
    worker's thread count. Workers inside the client's process (LocalCluster(processes=False))
    share its threads and keep its tuning."""

    name = "shapectl-runtime"

    def __init__(self):
        self.client_pid = os.getpid()

    def setup(self, worker):
        if os.getpid() != self.client_pid:
            _configure_worker(worker)


def _scene(scene_dict):
    key = json.dumps(scene_dict, sort_keys=True)
    with _scenes_lock:
        if key not in _scenes:
            _scenes.clear()  # one study at a time: keep memory bounded
            _scenes[key] = shapectl.Scene.from_dict(scene_dict)
        return _scenes[key]


def _row(task, **fields):
    row = {"task": task, "status": "failed", "termination": "", "converged": False,
           "iterations": -1, "error_mean": math.nan, "error_max": math.nan,
           "min_clearance": math.nan, "objective": math.nan, "seconds": math.nan,
           "worker": "", "error": "", "joints": []}
    row.update(fields)
    return row


def solve_task(task, targets, scene, options):
    """One solve on a worker: the row of task number `task` (see the module's docstring)."""
    worker = f"{socket.gethostname()}:{os.getpid()}"
    start = time.perf_counter()
    try:
        result = shapectl.solve(_scene(scene), targets, **options)
    except (ValueError, shapectl.SolverError) as e:
        return _row(task, worker=worker, error=f"{type(e).__name__}: {e}")
    return _row(task, status="done", termination=result.termination, converged=result.converged,
                iterations=result.iterations, error_mean=result.error_mean,
                error_max=result.error_max,
                min_clearance=math.nan if result.min_clearance is None else result.min_clearance,
                objective=result.objective, seconds=time.perf_counter() - start, worker=worker,
                joints=result.joints.tolist())


class Interrupted(KeyboardInterrupt):
    """Ctrl-C during solve_many: `rows` are the tasks finished so far, in task order (each keeps
    its "task" number); the others were cancelled."""

    def __init__(self, rows):
        super().__init__(f"interrupted after {len(rows)} finished tasks")
        self.rows = rows


def _progress_bar(total, stream):
    """tqdm's bar with its rate and ETA on `stream` (None: none), the failures as its postfix."""
    from tqdm import tqdm

    return tqdm(total=total, file=stream, disable=stream is None, desc="batch", unit="solve",
                mininterval=0.5, postfix={"failed": 0})


def _finished_row(task, future):
    if future.status == "finished":
        return future.result()
    # An exception the task did not expect, a worker lost, a cancelled task.
    try:
        reason = future.exception()
    except Exception as e:  # cancelled: no exception to fetch
        reason = e
    return _row(task, error=f"{type(reason).__name__}: {reason}")


def solve_many(client, scene, target_sets, progress=sys.stderr, **options):
    """shapectl.solve(scene, targets, **options) for every entry of `target_sets` (dicts of the
    TARGETS.json schema) on the cluster behind `client`; returns one row per entry, in order.
    scene: a Scene (sent as to_dict()) or a dict of the scene schema with absolute file names.
    progress: where the progress bar goes (None: nowhere). Ctrl-C (KeyboardInterrupt) cancels
    the tasks not finished and raises Interrupted with the rows that are."""
    scene_dict = scene.to_dict() if isinstance(scene, shapectl.Scene) else scene
    from distributed import as_completed

    client.register_worker_plugin(RuntimePlugin())

    # The scene once to every worker, not once per task.
    [scene_on_workers] = client.scatter([scene_dict], broadcast=True, hash=False)
    futures = client.map(solve_task, range(len(target_sets)), target_sets,
                         scene=scene_on_workers, options=options, pure=False)
    task_of = {future.key: task for task, future in enumerate(futures)}
    rows = [None] * len(futures)
    failed = 0
    with _progress_bar(len(futures), progress) as bar:
        try:
            for future in as_completed(futures):
                task = task_of[future.key]
                rows[task] = _finished_row(task, future)
                future.release()
                failed += rows[task]["status"] == "failed"
                bar.set_postfix(failed=failed, refresh=False)
                bar.update()
        except KeyboardInterrupt:
            client.cancel([f for task, f in enumerate(futures) if rows[task] is None])
            raise Interrupted([row for row in rows if row is not None]) from None
    return rows


def table(rows, joint_names):
    """The rows as columns: numpy arrays named as FIELDS (plus any other keys the rows share, e.g.
    a study's parameters, first), and "joints" of shape (tasks, m), NaN for failed tasks."""
    extra = [key for key in rows[0] if key not in FIELDS and key != "joints"] if rows else []
    columns = {key: np.array([row[key] for row in rows]) for key in extra + list(FIELDS)}
    joints = np.full((len(rows), len(joint_names)), math.nan)
    for i, row in enumerate(rows):
        if len(row["joints"]):
            joints[i] = row["joints"]
    columns["joints"] = joints
    columns["joint_names"] = np.array(joint_names)
    return columns


def write_table(rows, prefix, joint_names):
    """PREFIX.npz (table()'s arrays) and PREFIX.csv (one line per task, a column per joint)."""
    columns = table(rows, joint_names)
    np.savez(f"{prefix}.npz", **columns)
    names = [key for key in columns if key not in ("joints", "joint_names", "error")]
    with open(f"{prefix}.csv", "w", newline="") as out:
        writer = csv.writer(out)
        writer.writerow(names + list(joint_names) + ["error"])
        for i in range(len(rows)):
            writer.writerow([columns[key][i] for key in names] + list(columns["joints"][i])
                            + [columns["error"][i]])
