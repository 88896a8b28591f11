"""Statics and sensitivities from Python agree with `shapectl statics`; arrays in and out."""

import numpy as np
import pytest

import shapectl
from conftest import BAR, CLAMPED, FRAME


def assert_same_as_cli(py, cli_result):
    assert py.converged == cli_result["converged"]
    assert py.status == cli_result["status"]
    assert py.reason == cli_result["reason"]
    assert py.iterations == cli_result["iterations"]
    assert py.residual == pytest.approx(cli_result["residual"], rel=1e-9, abs=1e-15)
    assert py.energy == pytest.approx(cli_result["energy"], rel=1e-9, abs=1e-15)
    np.testing.assert_allclose(py.positions, np.array(cli_result["positions"]), rtol=0, atol=1e-12)


@pytest.mark.parametrize("scene_path", [BAR, FRAME])
def test_statics_at_the_reference_joints_match_the_cli(cli, scene_path):
    run = cli("statics", scene_path)
    assert run.exit_code == 0, run.stderr
    py = shapectl.statics(shapectl.Scene.load(scene_path))
    assert_same_as_cli(py, run.result)
    assert sorted(py.joint_names) == sorted(run.result["joints"])  # the CLI's JSON sorts keys
    np.testing.assert_array_equal(py.joints, [run.result["joints"][n] for n in py.joint_names])
    assert sorted(py.tools) == sorted(run.result["tools"])
    for name, pose in py.tools.items():
        np.testing.assert_allclose(pose.position, run.result["tools"][name]["position"], atol=1e-15)
        np.testing.assert_allclose(pose.rotation, run.result["tools"][name]["rotation"], atol=1e-15)


def test_statics_at_other_joints_match_the_cli(cli, write_json, bar_scene):
    joints = {"yumi_joint_1_l": -0.05, "yumi_joint_6_r": 0.2}
    run = cli("statics", BAR, "--joints", write_json("joints.json", {"joints": joints}))
    assert run.exit_code == 0, run.stderr
    by_name = shapectl.statics(bar_scene, joints)
    assert_same_as_cli(by_name, run.result)
    # The same θ as an array gives the same equilibrium.
    as_array = shapectl.statics(bar_scene, by_name.joints)
    np.testing.assert_array_equal(as_array.positions, by_name.positions)
    assert by_name.joints[bar_scene.joint_names.index("yumi_joint_1_l")] == -0.05


def test_a_scene_without_robot_matches_the_cli(cli):
    run = cli("statics", CLAMPED)
    assert run.exit_code == 0, run.stderr
    scene = shapectl.Scene.load(CLAMPED)
    assert not scene.has_robot and scene.robot is None
    py = shapectl.statics(scene)
    assert_same_as_cli(py, run.result)
    assert py.joints is None and py.tools == {}
    with pytest.raises(ValueError, match="the scene has no robot"):
        shapectl.statics(scene, {"a": 1.0})


def test_arrays_have_the_documented_shapes_and_dtypes(bar_scene):
    n, m = bar_scene.node_count, len(bar_scene.joint_names)
    assert (n, m) == (425, 14)
    eq = shapectl.statics(bar_scene)
    assert eq.positions.shape == (n, 3) and eq.positions.dtype == np.float64
    assert eq.joints.shape == (m,) and eq.joints.dtype == np.float64
    assert bar_scene.rest_positions.shape == (n, 3)
    assert bar_scene.reference_joints.shape == (m,)
    assert bar_scene.tets.shape == (bar_scene.tet_count, 4) and bar_scene.tets.max() == n - 1
    pose = eq.tools["left"]
    assert pose.position.shape == (3,) and pose.rotation.shape == (3, 3)
    np.testing.assert_allclose(pose.rotation @ pose.rotation.T, np.eye(3), atol=1e-12)
    # Gravity sags the held bar: the equilibrium is not the rest shape.
    assert np.abs(eq.positions - bar_scene.rest_positions).max() > 1e-4


def test_sensitivity_matches_central_differences(bar_scene):
    obj = shapectl.GrippedObject(bar_scene)
    state = obj.solve()
    assert state.statics.converged
    S = obj.sensitivity(state)
    assert S.shape == (3 * obj.node_count, obj.joint_count) and S.dtype == np.float64
    h = 1e-5
    for j in (0, 9):  # a left and a right arm joint
        step = np.zeros(obj.joint_count)
        step[j] = h
        plus = obj.solve(obj.reference_joints + step, warm_start=state.positions)
        minus = obj.solve(obj.reference_joints - step, warm_start=state.positions)
        fd = (plus.positions - minus.positions).reshape(-1) / (2 * h)
        assert np.abs(fd).max() > 1e-3  # the joint moves the bar
        np.testing.assert_allclose(S[:, j], fd, rtol=0, atol=1e-3 * np.abs(fd).max())


def test_bad_arrays_and_joints_raise_value_error(bar_scene):
    obj = shapectl.GrippedObject(bar_scene)
    with pytest.raises(ValueError, match=r"warm_start: expected an array of shape \(425, 3\), got an array of shape \(424, 3\)"):
        obj.solve(warm_start=np.zeros((424, 3)))
    with pytest.raises(ValueError, match=r"joints: expected an array of shape \(14,\), got a list of 3 entries"):
        shapectl.statics(bar_scene, [0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="joints.no_such_joint"):
        shapectl.statics(bar_scene, {"no_such_joint": 0.1})
    with pytest.raises(ValueError, match="finite"):
        shapectl.statics(bar_scene, np.full(14, np.nan))
    with pytest.raises(ValueError, match="robot"):
        shapectl.GrippedObject(shapectl.Scene.load(CLAMPED))


def test_a_bad_scene_raises_value_error_with_the_cli_message(cli, write_json):
    scene = write_json("scene.json", {"object": {"mesh": {"box": {"size": [0.1, 0.02, 0.02], "cells": [4, 1, 1]}},
                                                  "material": {"mu": -3, "kappa": 5e4, "density": 40}},
                                       "fixed": {"nodes": [0, 1, 2, 3]}})
    run = cli("statics", scene)
    assert run.exit_code == 1
    with pytest.raises(ValueError) as error:
        shapectl.Scene.load(scene)
    assert str(error.value) == run.error_message()
    assert "object.material.mu" in str(error.value)
