"""The continuous controller from Python: targets in, snapshots out, pause and jog, from threads;
its shapes are the CLI's statics at its joints."""

import threading

import numpy as np
import pytest

import shapectl
from conftest import BAR

DEADLINE_SECONDS = 60  # a bound on waiting, not a speed requirement


def wait_until(controller, predicate):
    snapshot = controller.snapshot()
    waited = 0.0
    while not predicate(snapshot):
        assert waited < DEADLINE_SECONDS, f"controller stayed {snapshot.status}: {snapshot.last_error}"
        snapshot = controller.wait_for_snapshot(snapshot.sequence, timeout=0.5)
        waited += 0.5
    return snapshot


def assert_statics_match_the_cli(cli, write_json, snapshot):
    joints = dict(zip(snapshot.joint_names, snapshot.joints.tolist()))
    run = cli("statics", BAR, "--joints", write_json("joints.json", {"joints": joints}))
    assert run.exit_code == 0, run.stderr
    # Warm-started elsewhere, converged to the same equilibrium within the force tolerance.
    np.testing.assert_allclose(snapshot.positions, run.result["positions"], rtol=0, atol=1e-6)


def test_targets_set_from_another_thread_are_reached(cli, write_json, bar_scene):
    reference = shapectl.statics(bar_scene).positions
    nodes = list(range(0, bar_scene.node_count, 53))
    targets = {"targets": [{"node": i, "position": reference[i] + [0, 0, 0.01]} for i in nodes]}
    with shapectl.Controller(bar_scene) as controller:
        first = controller.snapshot()
        assert first.status == "idle" and first.positions.shape == (425, 3)
        np.testing.assert_array_equal(first.joints, bar_scene.reference_joints)
        setter = threading.Thread(target=controller.set_targets, args=(targets,))
        setter.start()
        setter.join()
        done = wait_until(controller, lambda s: s.status == "reached")
    assert done.error_mean < 1e-3 and done.safe and done.iterations > 0
    assert done.unreachable == [] and done.status_reason == "" and done.tolerance == 1e-3
    np.testing.assert_array_equal(done.target_nodes, nodes)
    assert done.target_positions.shape == (len(nodes), 3) and done.target_positions.dtype == np.float64
    assert done.joints.shape == (14,) and sorted(done.links) == sorted(bar_scene.robot.link_names)
    assert_statics_match_the_cli(cli, write_json, done)


def test_pause_jog_and_resume(cli, write_json, bar_scene):
    with shapectl.Controller(bar_scene) as controller:
        with pytest.raises(ValueError, match="paused before jogging"):
            controller.jog({"yumi_joint_1_l": 0.0})
        controller.pause()
        wait_until(controller, lambda s: s.paused)
        goal = bar_scene.reference_joints.copy()
        goal[0] += 0.05
        controller.jog(goal)
        jogged = wait_until(controller, lambda s: np.array_equal(s.joints, goal))
        assert jogged.paused and jogged.status == "paused" and jogged.last_error == ""
        assert_statics_match_the_cli(cli, write_json, jogged)
        # A dict jog changes only the named joint.
        controller.jog({"yumi_joint_6_r": float(goal[13] + 0.05)})
        again = wait_until(controller, lambda s: s.joints[13] != goal[13])
        np.testing.assert_array_equal(again.joints[:13], goal[:13])
        controller.resume()
        wait_until(controller, lambda s: not s.paused)
        controller.reset()
        back = wait_until(controller, lambda s: np.array_equal(s.joints, bar_scene.reference_joints))
        assert back.target_nodes.shape == (0,)


def test_stepping_without_the_thread_and_bad_requests(bar_scene):
    with shapectl.Controller(bar_scene, start=False) as controller:
        with pytest.raises(ValueError) as error:
            controller.set_targets({"targets": [{"node": 425, "position": [0, 0, 0]}]})
        assert str(error.value).startswith("targets: targets[0].node")
        with pytest.raises(ValueError, match="centerline"):
            controller.set_centerline(np.zeros((1, 3)))
        rest = bar_scene.rest_positions
        controller.set_centerline(np.array([rest[0], rest[-1]]) + [0, 0, 0.02])
        before = controller.snapshot().sequence
        for _ in range(3):
            controller.step()
        after = controller.snapshot()
        assert after.sequence > before and after.iterations > 0 and after.target_nodes.size > 0
    with pytest.raises(ValueError, match="optimizer: expected one of the optimizer names"):
        shapectl.Controller(bar_scene, optimizer="newton")
    closed = shapectl.Controller(bar_scene, start=False)
    closed.close()
    with pytest.raises(ValueError, match="closed"):
        closed.snapshot()
