"""scripts/compare_equilibria.py against stand-ins for shapectl: equal results pass, results
that differ by more than --tol or in an iteration count fail, and a binary that fails is said."""
import json
import os
import stat
import subprocess
import sys

SCRIPT = os.path.join(os.path.dirname(__file__), "..", "..", "scripts", "compare_equilibria.py")

# A stand-in for `shapectl statics|solve SCENE [...] --out FILE`: positions from the scene's
# "nodes", moved by SHIFT metres in x; ITERATIONS iterations; exit FAIL if set.
FAKE = r'''#!{python}
import json, sys
args = sys.argv[1:]
if {fail}: sys.exit("fake: refused")
scene = json.load(open(args[1]))
out = args[args.index("--out") + 1]
result = {{"positions": [[x + {shift}, y, z] for x, y, z in scene["nodes"]],
           "iterations": {iterations}, "status": "converged"}}
if "robot" in scene:
    result["joints"] = {{"j1": 0.1}}
if args[0] == "solve":
    assert json.load(open(args[args.index("--targets") + 1]))["targets"]
    result["timing"] = {{"statics_solves": 3}}
json.dump(result, open(out, "w"))
'''


def fake(tmp_path, name, shift=0.0, iterations=2, fail=False):
    path = tmp_path / name
    path.write_text(FAKE.format(python=sys.executable, shift=shift, iterations=iterations,
                                fail=fail))
    path.chmod(path.stat().st_mode | stat.S_IEXEC)
    return str(path)


def scenes(tmp_path):
    nodes = [[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.2, 0.0, 0.1]]
    robot = tmp_path / "robot.json"
    robot.write_text(json.dumps({"object": {}, "robot": {}, "nodes": nodes}))
    clamped = tmp_path / "clamped.json"
    clamped.write_text(json.dumps({"object": {}, "nodes": nodes}))
    other = tmp_path / "world.json"
    other.write_text(json.dumps({"world": {}}))
    return [str(robot), str(clamped), str(other)]


def compare(old, new, scene_files, *extra):
    return subprocess.run([sys.executable, SCRIPT, old, new, "--scenes", *scene_files, *extra],
                          capture_output=True, text=True)


def test_equal_results_pass_and_non_scenes_are_skipped(tmp_path):
    r = compare(fake(tmp_path, "old"), fake(tmp_path, "new"), scenes(tmp_path))
    assert r.returncode == 0, r.stdout + r.stderr
    assert r.stdout.count(" same") == 3  # robot: statics and solve; clamped: statics
    assert "world.json" in r.stdout and "skipped" in r.stdout


def test_a_node_moved_beyond_the_tolerance_fails(tmp_path):
    old, new = fake(tmp_path, "old"), fake(tmp_path, "new", shift=1e-9)
    r = compare(old, new, scenes(tmp_path))
    assert r.returncode == 1 and "DIFFERENT" in r.stdout and "1e-09" in r.stdout
    assert compare(old, new, scenes(tmp_path), "--tol", "1e-8").returncode == 0


def test_another_iteration_count_fails(tmp_path):
    r = compare(fake(tmp_path, "old"), fake(tmp_path, "new", iterations=3), scenes(tmp_path))
    assert r.returncode == 1 and "iterations 2/3" in r.stdout


def test_a_failing_binary_is_reported(tmp_path):
    r = compare(fake(tmp_path, "old"), fake(tmp_path, "new", fail=True), scenes(tmp_path))
    assert r.returncode == 2 and "fake: refused" in r.stdout


def test_a_missing_binary_is_refused(tmp_path):
    r = compare(str(tmp_path / "nothing"), fake(tmp_path, "new"), scenes(tmp_path))
    assert r.returncode != 0 and "expected an executable shapectl" in r.stderr
