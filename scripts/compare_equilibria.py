#!/usr/bin/env python3
"""The "no behaviour change" check: two shapectl binaries give the same equilibria.

For every scene in scenes/ (or those given with --scenes) it runs, with each binary:

  statics SCENE --out R.json             the equilibrium at the reference joints
  solve SCENE --targets T.json --out R.json --max-iterations N
                                         Gauss-Newton towards fixed targets (robot scenes)

and compares the positions (the largest distance of any node), the joints (largest
difference) and the iteration counts (statics: Newton iterations; solve: optimizer
iterations and statics solves). The targets are every 17th node of OLD's reference
equilibrium moved 1 cm up (world z): the same file for both binaries, no randomness and no
time limit, so both runs of one binary give the same answer to the last bit (a thread-count
independent build; docs/benchmarks.md). Exit 0 when every distance is within --tol and every
count is equal, 1 otherwise, 2 when a run fails. Files that are not scenes (no "object") are
skipped, and say so.

    python3 scripts/compare_equilibria.py /work/old/shapectl build/shapectl
    python3 scripts/compare_equilibria.py OLD NEW --tol 1e-9 --scenes scenes/yumi_bar.json
"""
import argparse
import glob
import json
import math
import os
import subprocess
import sys
import tempfile

TARGET_EVERY = 17  # every 17th node is a target: 25 on the 425-node bar
TARGET_LIFT = 0.01  # m, straight up: reachable on every bundled robot scene


class RunFailed(Exception):
    pass


def run_json(binary, args, out):
    """Runs `binary args --out out` and returns the result file, or raises RunFailed."""
    command = [binary, *args, "--out", out]
    run = subprocess.run(command, capture_output=True, text=True)
    if run.returncode != 0:
        last = (run.stderr.strip().splitlines() or [""])[-1]
        raise RunFailed("%s exited %d: %s" % (" ".join(command), run.returncode, last))
    with open(out) as f:
        return json.load(f)


def max_node_distance(a, b):
    if len(a) != len(b):
        return math.inf
    return max((math.dist(p, q) for p, q in zip(a, b)), default=0.0)


def max_joint_difference(a, b):
    if set(a) != set(b):
        return math.inf
    return max((abs(a[k] - b[k]) for k in a), default=0.0)


def write_targets(reference, path):
    """TARGETS.json from a statics result: every TARGET_EVERY-th node lifted TARGET_LIFT."""
    targets = [{"node": i, "position": [p[0], p[1], p[2] + TARGET_LIFT]}
               for i, p in enumerate(reference["positions"]) if i % TARGET_EVERY == 0]
    with open(path, "w") as f:
        json.dump({"targets": targets}, f)


def compare(name, old, new, counts):
    """One table row: distances and counts of two results."""
    row = {"run": name,
           "distance": max_node_distance(old["positions"], new["positions"]),
           "joints": max_joint_difference(old.get("joints", {}), new.get("joints", {})),
           "counts": ["%s %s/%s" % (c, old[c], new[c]) if c in old else
                      "%s %s/%s" % (c, old["timing"][c], new["timing"][c]) for c in counts]}
    row["same_counts"] = all((old[c] == new[c]) if c in old else
                             (old["timing"][c] == new["timing"][c]) for c in counts)
    return row


def scene_rows(scene, old_bin, new_bin, work, max_iterations):
    with open(scene) as f:
        description = json.load(f)
    if "object" not in description:
        return [], "not a scene (no \"object\")"
    tag = os.path.splitext(os.path.basename(scene))[0]
    old = run_json(old_bin, ["statics", scene], os.path.join(work, tag + ".old.json"))
    new = run_json(new_bin, ["statics", scene], os.path.join(work, tag + ".new.json"))
    rows = [compare("statics", old, new, ["iterations", "status"])]
    if "robot" not in description:
        return rows, None
    targets = os.path.join(work, tag + ".targets.json")
    write_targets(old, targets)
    args = ["solve", scene, "--targets", targets, "--max-iterations", str(max_iterations)]
    old = run_json(old_bin, args, os.path.join(work, tag + ".solve.old.json"))
    new = run_json(new_bin, args, os.path.join(work, tag + ".solve.new.json"))
    rows.append(compare("solve", old, new, ["iterations", "statics_solves", "status"]))
    return rows, None


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("old", help="the shapectl binary before the change")
    parser.add_argument("new", help="the shapectl binary after it")
    parser.add_argument("--tol", type=float, default=1e-12,
                        help="largest node distance (m) and joint difference (rad) allowed")
    parser.add_argument("--scenes", nargs="+", help="SCENE.json files (default: scenes/*.json)")
    parser.add_argument("--max-iterations", type=int, default=20,
                        help="solve's iteration limit (default 20)")
    args = parser.parse_args()
    for binary in (args.old, args.new):
        if not (os.path.isfile(binary) and os.access(binary, os.X_OK)):
            sys.exit("compare_equilibria: %s: expected an executable shapectl" % binary)
    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    scenes = args.scenes or sorted(glob.glob(os.path.join(root, "scenes", "*.json")))

    print("%-24s %-8s %12s %12s  %-58s %s" % ("scene", "run", "max dist m", "joints rad",
                                             "counts old/new", "verdict"))
    differ = failed = False
    with tempfile.TemporaryDirectory(prefix="compare_equilibria.") as work:
        for scene in scenes:
            name = os.path.basename(scene)
            try:
                rows, skipped = scene_rows(scene, args.old, args.new, work, args.max_iterations)
            except (RunFailed, OSError, ValueError, KeyError) as e:
                print("%-24s failed: %s" % (name, e))
                failed = True
                continue
            if skipped:
                print("%-24s skipped: %s" % (name, skipped))
            for r in rows:
                ok = r["distance"] <= args.tol and r["joints"] <= args.tol and r["same_counts"]
                differ |= not ok
                print("%-24s %-8s %12.3g %12.3g  %-58s %s" % (
                    name, r["run"], r["distance"], r["joints"], ", ".join(r["counts"]),
                    "same" if ok else "DIFFERENT"))
    if failed:
        return 2
    print("all within %g" % args.tol if not differ else "some differ by more than %g" % args.tol)
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
