"""calibrate() from Python: recovers a known stiffness from synthetic observations, agrees with
`shapectl calibrate`, names bad observations as the CLI does, releases the GIL."""

import json

import numpy as np
import pytest

import shapectl
from conftest import SOURCE_DIR, counted_during

CANTILEVER = SOURCE_DIR / "scenes" / "yumi_cantilever.json"  # held at one end: its sag shows E


@pytest.fixture(scope="module")
def model():
    return shapectl.Scene.load(CANTILEVER)


def swung(scene, changes):
    joints = scene.reference_joints.copy()
    for index, delta in changes.items():
        joints[index] += delta
    return joints


def synthetic_observations(model, stiffer=1.5, sigma=0.0003, seed=5):
    """OBS.json (as a dict) of a "real" bar `stiffer` × as stiff as the model: 15 markers at
    three poses from this module's own statics, with Gaussian noise of `sigma` m."""
    d = model.to_dict()
    d["object"]["material"]["youngs_modulus"] *= stiffer
    truth = shapectl.Scene.from_dict(d)
    rng = np.random.default_rng(seed)
    nodes = range(3, model.node_count, 28)
    frames = []
    for changes in ({}, {0: 0.1, 6: 0.2}, {3: -0.1, 5: 0.15}):
        joints = swung(model, changes)
        equilibrium = shapectl.statics(truth, joints)
        assert equilibrium.converged, equilibrium.reason
        observed = equilibrium.positions + rng.normal(0, sigma, equilibrium.positions.shape)
        frames.append({"joints": dict(zip(model.joint_names, joints)),
                       "markers": [{"node": i, "position": observed[i]} for i in nodes],
                       "sigma": sigma})
    return {"frames": frames}


def as_json(value):
    return json.loads(json.dumps(value, default=lambda a: a.tolist()))


def test_recovers_a_stiffer_bar_within_a_few_percent(model):
    observations = synthetic_observations(model)
    result = shapectl.calibrate(model, observations, fit="youngs_modulus")
    assert result.converged, result.reason
    [stiffness] = result.parameters
    assert (stiffness.name, stiffness.unit, stiffness.identifiable) == ("youngs_modulus", "Pa", True)
    assert stiffness.initial == pytest.approx(2e5)
    assert stiffness.fitted == pytest.approx(1.5 * 2e5, rel=0.03)
    assert 0 < stiffness.standard_deviation < 0.03 * stiffness.fitted
    assert result.rms_after < result.rms_before / 5
    assert 0.5 < result.chi_squared_per_dof < 2
    assert len(result.frames) == 3 and all(f.markers == 16 for f in result.frames)
    assert result.identifiability == []
    # The calibrated scene carries the fitted value, and its dict is CALIBRATED.json's.
    material = result.scene.to_dict()["object"]["material"]
    assert material["youngs_modulus"] == pytest.approx(stiffness.fitted, rel=1e-12)
    assert material["density"] == model.to_dict()["object"]["material"]["density"]


def test_matches_the_cli_on_the_same_file(cli, write_json, tmp_path, model):
    path = write_json("obs.json", as_json(synthetic_observations(model)))
    run = cli("calibrate", CANTILEVER, "--observations", path, "--report", tmp_path / "report.json",
              out="calibrated.json")
    assert run.exit_code == 0, run.stderr
    report = json.loads((tmp_path / "report.json").read_text())
    result = shapectl.calibrate(model, str(path))  # the default fit: E and the grip offsets
    assert result.converged == report["converged"] and result.iterations == report["iterations"]
    assert [p.name for p in result.parameters] == [p["name"] for p in report["parameters"]]
    for mine, theirs in zip(result.parameters, report["parameters"]):
        assert mine.fitted == pytest.approx(theirs["fitted"], rel=1e-9, abs=1e-12), mine.name
        assert mine.identifiable == theirs["identifiable"]
    assert result.rms_after == pytest.approx(report["rms_after"], rel=1e-9)
    # CALIBRATED.json's grip offset is the calibrated scene's.
    [mine], [theirs] = result.scene.to_dict()["grips"], run.result["grips"]
    for key in ("position", "rpy"):
        np.testing.assert_allclose(mine["offset"][key], theirs["offset"][key], rtol=0, atol=1e-9)


@pytest.mark.parametrize("change, field", [
    (lambda o: o["frames"][0]["markers"][0].update(node=500), "frames[0].markers[0].node"),
    (lambda o: o["frames"][1]["joints"].pop("yumi_joint_3_l"), "frames[1].joints"),
    (lambda o: o["frames"][2].update(sigma=-1), "frames[2].sigma"),
    # Issue 32: a joint at 1e6 rad made calibrate walk there for hours; outside its limits now.
    (lambda o: o["frames"][1]["joints"].update(yumi_joint_3_l=1e6),
     "frames[1].joints.yumi_joint_3_l: expected a value within the joint's limits"),
])
def test_bad_observations_raise_the_clis_message(cli, write_json, model, change, field):
    observations = as_json(synthetic_observations(model))
    change(observations)
    path = write_json("obs.json", observations)
    run = cli("calibrate", CANTILEVER, "--observations", path, out="calibrated.json")
    assert run.exit_code == 1, run.stderr
    with pytest.raises(ValueError) as from_file:
        shapectl.calibrate(model, str(path))
    assert str(from_file.value) == run.error_message()
    assert f"{path}: {field}" in str(from_file.value)
    # A dict is named "observations" where the CLI names the file.
    with pytest.raises(ValueError) as from_dict:
        shapectl.calibrate(model, observations)
    assert str(from_dict.value) == run.error_message().replace(str(path), "observations")


def test_bad_options_and_a_scene_without_robot_are_named(cli, write_json, model):
    observations = synthetic_observations(model)
    path = write_json("obs.json", as_json(observations))
    run = cli("calibrate", CANTILEVER, "--observations", path, "--fit", "stiffness")
    assert run.exit_code == 1
    with pytest.raises(ValueError) as error:
        shapectl.calibrate(model, observations, fit="stiffness")
    assert str(error.value) == run.error_message().replace("--fit", "fit")
    with pytest.raises(ValueError, match="observations: expected an OBSERVATIONS.json path or a "
                                         "dict of its schema, got <class 'list'>"):
        shapectl.calibrate(model, observations["frames"])
    with pytest.raises(ValueError, match="max_iterations: expected a number from 1 to 1000, got 0"):
        shapectl.calibrate(model, observations, max_iterations=0)
    for seconds in (0, -1, float("nan")):
        with pytest.raises(ValueError, match="max_seconds: expected a positive number"):
            shapectl.calibrate(model, observations, max_seconds=seconds)
    # Frames with joints for a scene without a robot (a clamped bar).
    clamped = SOURCE_DIR / "scenes" / "foam_bar_clamped.json"
    run = cli("calibrate", clamped, "--observations", path)
    assert run.exit_code == 1
    with pytest.raises(ValueError) as error:
        shapectl.calibrate(shapectl.Scene.load(clamped), path)
    assert str(error.value) == run.error_message()
    assert "frames[0].joints: the scene has no robot" in str(error.value)


def test_a_calibration_in_a_thread_does_not_block_other_python_threads(model):
    observations = synthetic_observations(model)
    advanced = counted_during(lambda: shapectl.calibrate(model, observations, fit=["youngs_modulus"]))
    assert advanced and advanced[-1] > 0, advanced


def test_verdicts_priors_and_bad_priors(model):
    """Issue 35: each parameter's verdict and prior (the grips' default 5 mm / 3°), as the CLI's
    report; prior= and bounds= take the CLI's syntax and name a bad entry."""
    observations = synthetic_observations(model)
    result = shapectl.calibrate(model, observations, fit="youngs_modulus,density")
    stiffness, density = result.parameters
    assert stiffness.verdict == "determined" and stiffness.prior is None
    assert density.verdict == "not determined" and not density.identifiable
    assert density.trades_off_with == ["youngs_modulus"]
    assert "hanging weight" in density.suggestion
    assert result.implausible == []
    grips = shapectl.calibrate(model, observations, prior="grip_offsets=2mm/1deg")
    assert grips.parameters[1].name.startswith("grip_offsets.") and grips.parameters[1].prior == 0.002
    assert grips.parameters[4].prior == pytest.approx(np.radians(1))
    assert all(not p.implausible for p in grips.parameters)
    with pytest.raises(ValueError, match="prior: object_pose.rotation=2furlongs"):
        shapectl.calibrate(model, observations, prior="object_pose.rotation=2furlongs")
    with pytest.raises(ValueError, match="bounds: youngs_modulus: the scene.s value is outside"):
        shapectl.calibrate(model, observations, bounds="youngs_modulus=1e6:1e8")


def test_depth_images_and_camera_poses(cli, write_json, tmp_path):
    """A frame's "depth_image" goes through the CLI's reader: a float32 .npy of the clamped bar's
    top face seen from 0.5 m straight above; camera_poses fits its camera; a bad dtype is named
    as the CLI names it."""
    clamped = SOURCE_DIR / "scenes" / "foam_bar_clamped.json"
    depth = np.full((40, 320), np.nan, dtype=np.float32)
    depth[5:35, :] = 0.485  # rows within ±15 px of cy = 19.5: the 3 cm wide top face
    np.save(tmp_path / "d.npy", depth)
    frame = {"depth_image": {"file": "d.npy",
                             "intrinsics": {"fx": 500, "fy": 500, "cx": 159.5, "cy": 19.5},
                             "camera_pose": {"position": [0, 0, 0.5], "rpy": [np.pi, 0, 0]}},
             "sigma": 0.001}
    path = write_json("obs.json", {"frames": [frame]})
    result = shapectl.calibrate(shapectl.Scene.load(clamped), str(path),
                                fit="object_pose,camera_poses", max_iterations=2)
    names = [p.name for p in result.parameters]
    assert names[6:] == [f"cameras[0].pose.{a}" for a in ("x", "y", "z", "rx", "ry", "rz")]
    assert result.frames[0].points == 320 * 30
    np.save(tmp_path / "d.npy", np.zeros(depth.shape, dtype=np.int16))
    run = cli("calibrate", clamped, "--observations", path)
    assert run.exit_code == 1
    with pytest.raises(ValueError) as error:
        shapectl.calibrate(shapectl.Scene.load(clamped), str(path))
    assert str(error.value) == run.error_message()
    assert "d.npy: header 'descr': expected '<f4' or '<f8'" in str(error.value)
