"""Which bends of the bar can the robot reach? A grid of centre-lines (middle raised by `lift`,
moved sideways by `shift`), each solved independently on a Dask cluster, gathered into one table:
PREFIX.npz and PREFIX.csv, one row per target set, with its reachable error, the joints, and for
a task that failed, why. The default grid (8 x 10 bends) takes about 20 s on 2 cores;
Ctrl-C stops it and still writes the rows finished so far (exit status 130).

On this machine (a LocalCluster of --workers processes):
    PYTHONPATH=build/python /usr/bin/python3 examples/python/batch_reachability.py --out reach
On a running cluster (dask-scheduler on one node, dask-worker tcp://HOST:8786 on each):
    /usr/bin/python3 examples/python/batch_reachability.py --scheduler tcp://HOST:8786 --out reach
The workers need the shapectl package and the files the scene names at the same paths
(docs/python.md).
"""

import json
import math
import sys

import numpy as np

import shapectl
import shapectl.batch as batch
from bar_shapes import argument_parser, bent_centerline


def main():
    parser = argument_parser(__doc__)
    parser.add_argument("--lifts", type=int, default=8, help="grid steps of the lift")
    parser.add_argument("--shifts", type=int, default=10, help="grid steps of the shift")
    parser.add_argument("--max-lift", type=float, default=0.12, help="m")
    parser.add_argument("--max-shift", type=float, default=0.08, help="m, either side")
    parser.add_argument("--extra", help="a JSON list of further target sets (TARGETS.json "
                                        "schema), solved after the grid")
    parser.add_argument("--scheduler", help="a running scheduler (tcp://host:8786); default: "
                                            "a LocalCluster on this machine")
    parser.add_argument("--workers", type=int, default=2, help="LocalCluster processes")
    parser.add_argument("--max-iterations", type=int, default=30)
    parser.add_argument("--max-seconds", type=float, default=20.0, help="per solve")
    parser.add_argument("--out", default="reach", help="writes OUT.npz and OUT.csv")
    args = parser.parse_args()

    # Loaded here first: a bad scene stops the study before any task is sent.
    scene = shapectl.Scene.load(args.scene)
    study = [(lift, shift) for lift in np.linspace(0, args.max_lift, args.lifts)
             for shift in np.linspace(-args.max_shift, args.max_shift, args.shifts)]
    target_sets = [bent_centerline(scene, lift, shift) for lift, shift in study]
    if args.extra:
        with open(args.extra) as f:
            extra = json.load(f)
        study += [(math.nan, math.nan)] * len(extra)
        target_sets += extra

    interrupted = False
    try:
        with batch.connect(args.scheduler, workers=args.workers) as client:
            rows = batch.solve_many(client, scene, target_sets,
                                    max_iterations=args.max_iterations,
                                    max_seconds=args.max_seconds)
    except batch.Interrupted as stop:
        rows, interrupted = stop.rows, True
    rows = [{"lift": study[r["task"]][0], "shift": study[r["task"]][1], **r} for r in rows]
    batch.write_table(rows, args.out, scene.joint_names)
    if interrupted:
        print(f"interrupted: wrote the {len(rows)} of {len(study)} target sets finished to "
              f"{args.out}.npz and {args.out}.csv", file=sys.stderr)
        sys.exit(130)

    failed = [r for r in rows if r["status"] == "failed"]
    reached = sum(r["status"] == "done" and r["error_mean"] < 1e-3 for r in rows)
    print(f"{len(rows)} target sets: {reached} reached within 1 mm, {len(failed)} failed; "
          f"wrote {args.out}.npz and {args.out}.csv")
    for r in failed:
        print(f"  task {r['task']}: {r['error']}", file=sys.stderr)


if __name__ == "__main__":
    main()
