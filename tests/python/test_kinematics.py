"""Kinematics from Python agree with `shapectl kinematics`."""

import numpy as np
import pytest

import shapectl
from conftest import BAR, YUMI_SPHERES, YUMI_URDF


def test_link_poses_clearances_and_violations_match_the_cli(cli, write_json):
    # Joint 1 beyond its limit (±2.94 rad) and the elbows bent: a violation and close pairs.
    joints = {"yumi_joint_1_l": 3.0, "yumi_joint_2_r": -1.2, "yumi_joint_3_l": 0.4}
    run = cli("kinematics", YUMI_URDF, "--joints", write_json("joints.json", {"joints": joints}),
              "--spheres", YUMI_SPHERES)
    assert run.exit_code == 0, run.stderr
    robot = shapectl.Robot.load(YUMI_URDF)
    py = shapectl.kinematics(robot, joints, spheres=YUMI_SPHERES)

    assert sorted(py.links) == sorted(run.result["links"])
    for name, pose in py.links.items():
        np.testing.assert_allclose(pose.position, run.result["links"][name]["position"], rtol=0, atol=1e-15)
        np.testing.assert_allclose(pose.rotation, run.result["links"][name]["rotation"], rtol=0, atol=1e-15)
    assert py.min_clearance == pytest.approx(run.result["min_clearance"], rel=1e-12)
    assert py.margin == run.result["margin"]
    assert len(py.closest_pairs) == len(run.result["closest_pairs"]) == 10
    for mine, theirs in zip(py.closest_pairs, run.result["closest_pairs"]):
        assert list(mine.links) == theirs["links"]
        assert list(mine.spheres) == theirs["spheres"]
        assert mine.clearance == pytest.approx(theirs["clearance"], rel=1e-12, abs=1e-15)
    assert [(v.joint, v.value, v.lower, v.upper) for v in py.limit_violations] == [
        (v["joint"], v["value"], v["lower"], v["upper"]) for v in run.result["limit_violations"]]
    assert [v.joint for v in py.limit_violations] == ["yumi_joint_1_l"]


def test_without_spheres_there_is_no_clearance(cli):
    run = cli("kinematics", YUMI_URDF)
    assert run.exit_code == 0, run.stderr
    py = shapectl.kinematics(shapectl.Robot.load(YUMI_URDF))
    assert py.min_clearance is None and py.closest_pairs == [] and "min_clearance" not in run.result
    np.testing.assert_array_equal(py.joints, np.zeros(len(py.joint_names)))
    for name in ("gripper_l_tcp", "gripper_r_tcp"):
        np.testing.assert_allclose(py.links[name].position, run.result["links"][name]["position"], rtol=0, atol=1e-15)


def test_a_scene_robot_gives_tools_and_its_spheres(bar_scene):
    robot = bar_scene.robot
    assert robot.has_collision_spheres and robot.joint_names == bar_scene.joint_names
    assert robot.lower_limits.shape == (14,) and np.all(robot.lower_limits < robot.upper_limits)
    at_reference = shapectl.kinematics(bar_scene)
    np.testing.assert_array_equal(at_reference.joints, bar_scene.reference_joints)
    assert at_reference.min_clearance > 0.05  # the README: 58 mm clear at the reference pose
    assert at_reference.limit_violations == []
    # The tools agree with statics' at the same joints.
    eq = shapectl.statics(bar_scene)
    for name in ("left", "right"):
        np.testing.assert_array_equal(at_reference.tools[name].position, eq.tools[name].position)


def test_bad_input_raises_value_error_with_the_cli_message(cli, write_json):
    bad = write_json("joints.json", {"joints": {"no_such_joint": 1.0}})
    run = cli("kinematics", YUMI_URDF, "--joints", bad)
    assert run.exit_code == 1
    with pytest.raises(ValueError, match="no_such_joint"):
        shapectl.kinematics(shapectl.Robot.load(YUMI_URDF), {"no_such_joint": 1.0})
    missing = str(YUMI_URDF) + ".missing"
    run = cli("kinematics", missing)
    assert run.exit_code == 1
    with pytest.raises(ValueError) as error:
        shapectl.Robot.load(missing)
    assert str(error.value) == run.error_message()
