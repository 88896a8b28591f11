"""solve() from Python agrees with `shapectl solve`; errors match the CLI's; the GIL is released."""

import json

import numpy as np
import pytest

import shapectl
from conftest import BAR, YUMI_SPHERES, YUMI_URDF, counted_during


def lifted_targets(scene, lift=0.01, every=53):
    """Every 53rd node of the equilibrium at the reference joints, lifted by `lift` metres."""
    positions = shapectl.statics(scene).positions
    return {"targets": [{"node": i, "position": positions[i] + [0, 0, lift]}
                        for i in range(0, scene.node_count, every)]}


def as_json(targets):
    return json.loads(json.dumps(targets, default=lambda a: a.tolist()))


@pytest.mark.parametrize("optimizer", ["gauss-newton", "lbfgs"])
def test_solve_matches_the_cli(cli, write_json, bar_scene, optimizer):
    targets = lifted_targets(bar_scene)
    run = cli("solve", BAR, "--targets", write_json("targets.json", as_json(targets)),
              "--optimizer", optimizer, "--max-iterations", "30")
    assert run.exit_code == 0, run.stderr
    py = shapectl.solve(bar_scene, targets, optimizer=optimizer, max_iterations=30)
    r = run.result
    assert (py.converged, py.termination, py.reason, py.iterations) == (
        r["converged"], r["termination"], r["reason"], r["iterations"])
    # The same verdict in the controller's words: reached only within the tolerance.
    assert (py.status, py.unreachable, py.status_reason, py.tolerance) == (
        r["status"], r["unreachable"], r["status_reason"], r["tolerance"])
    assert py.status == ("reached" if py.error_max <= 1e-3 else "best effort")
    assert sorted(py.joint_names) == sorted(r["joints"])  # the CLI's JSON sorts keys
    np.testing.assert_allclose(py.joints, [r["joints"][n] for n in py.joint_names], rtol=0, atol=1e-12)
    np.testing.assert_allclose(py.positions, r["positions"], rtol=0, atol=1e-12)
    for field in ("error_mean", "error_max", "objective", "min_clearance"):
        assert getattr(py, field) == pytest.approx(r[field], rel=1e-9), field
    assert py.limit_violations == [] and r["limit_violations"] == []
    np.testing.assert_array_equal(py.target_nodes, [t["node"] for t in r["targets"]])
    np.testing.assert_array_equal(py.target_positions, [t["position"] for t in r["targets"]])
    assert [h.iteration for h in py.history] == [h["iteration"] for h in r["history"]]
    np.testing.assert_allclose([h.error_mean for h in py.history], [h["error_mean"] for h in r["history"]], rtol=1e-9)
    assert py.timing.statics_solves == r["timing"]["statics_solves"]
    assert py.timing.gradient_evaluations == r["timing"]["gradient_evaluations"]
    for name, pose in py.tools.items():
        np.testing.assert_allclose(pose.position, r["tools"][name]["position"], rtol=0, atol=1e-12)
    # And it did something: the lifted nodes came up.
    assert py.history[0].error_mean > 5e-3 and py.error_mean < py.history[0].error_mean / 2


def test_a_targets_file_and_a_centerline_are_accepted(cli, write_json, bar_scene):
    rest = bar_scene.rest_positions
    ends = rest[np.argmin(rest[:, 1])], rest[np.argmax(rest[:, 1])]
    centerline = {"centerline": np.linspace(ends[0] + [0, 0, 0.02], ends[1] + [0, 0, 0.02], 5)}
    path = write_json("centerline.json", as_json(centerline))
    run = cli("solve", BAR, "--targets", path, "--max-iterations", "20")
    assert run.exit_code == 0, run.stderr
    from_file = shapectl.solve(bar_scene, path, max_iterations=20)
    from_dict = shapectl.solve(bar_scene, centerline, max_iterations=20)
    for py in (from_file, from_dict):
        np.testing.assert_array_equal(py.target_nodes, [t["node"] for t in run.result["targets"]])
        np.testing.assert_allclose(py.joints, [run.result["joints"][n] for n in py.joint_names], rtol=0, atol=1e-12)
    assert from_file.target_positions.shape == (len(run.result["targets"]), 3)


def test_bad_targets_raise_value_error_with_the_cli_message(cli, write_json, bar_scene):
    path = write_json("targets.json", {"targets": [{"node": 425, "position": [0, 0, 0]}]})
    run = cli("solve", BAR, "--targets", path)
    assert run.exit_code == 1
    with pytest.raises(ValueError) as error:
        shapectl.solve(bar_scene, str(path))
    assert str(error.value) == run.error_message()
    assert "targets[0].node" in str(error.value)
    # A dict is named "targets" where the CLI names the file; the rest of the message is the same.
    with pytest.raises(ValueError) as from_dict:
        shapectl.solve(bar_scene, {"targets": [{"node": 425, "position": [0, 0, 0]}]})
    assert str(from_dict.value) == run.error_message().replace(str(path), "targets")
    with pytest.raises(ValueError, match="targets: expected a TARGETS.json path or a dict of its "
                                         "schema, got <class 'int'>"):
        shapectl.solve(bar_scene, 7)
    with pytest.raises(ValueError, match="optimizer: expected one of the optimizer names, got newton"):
        shapectl.solve(bar_scene, lifted_targets(bar_scene), optimizer="newton")


def test_failed_reference_statics_raise_solver_error_like_the_cli(cli, write_json):
    scene = json.loads(BAR.read_text())
    scene["robot"]["urdf"] = str(YUMI_URDF)
    scene["robot"]["collision_spheres"] = str(YUMI_SPHERES)
    scene["statics"] = {"max_iterations": 1}
    path = write_json("one_newton_step.json", scene)
    targets = write_json("targets.json", {"targets": [{"node": 0, "position": [0.4, 0.1, 0.3]}]})
    run = cli("solve", path, "--targets", targets)
    assert run.exit_code == 2
    with pytest.raises(shapectl.SolverError) as error:
        shapectl.solve(shapectl.Scene.load(path), str(targets))
    assert str(error.value) == run.error_message()
    assert str(error.value).startswith("statics at the reference joints")
    assert isinstance(error.value, RuntimeError)


def test_a_solve_in_a_thread_does_not_block_other_python_threads(bar_scene):
    targets = lifted_targets(bar_scene, lift=0.03, every=17)
    advanced = counted_during(
        lambda: shapectl.solve(bar_scene, targets, optimizer="lbfgs", max_iterations=5))
    assert advanced and advanced[-1] > 0, advanced
