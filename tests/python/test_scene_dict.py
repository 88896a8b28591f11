"""Scene.from_dict / to_dict: the scene file's schema as a dict, read by the same reader (same
statics, same messages with the file's name replaced by "scene")."""

import json

import numpy as np
import pytest

import shapectl
from conftest import BAR, CLAMPED, SOURCE_DIR

SCENES = SOURCE_DIR / "scenes"


def assert_same_statics(a, b):
    sa, sb = shapectl.statics(a), shapectl.statics(b)
    assert sa.converged and sb.converged
    assert (sa.iterations, sa.energy) == (sb.iterations, sb.energy)
    np.testing.assert_array_equal(sa.positions, sb.positions)


def test_to_dict_then_from_dict_gives_the_files_statics(bar_scene):
    d = bar_scene.to_dict()
    assert d["robot"]["urdf"] == str((SOURCE_DIR / "data/robots/yumi/yumi.urdf").resolve())
    json.dumps(d)  # plain JSON types: writable as a scene file
    again = shapectl.Scene.from_dict(d)
    assert again.source == "scene"
    assert_same_statics(again, bar_scene)
    # The same dict back: nothing lost or added on the way.
    assert again.to_dict() == d


def test_relative_file_names_resolve_against_base_dir(bar_scene, tmp_path, monkeypatch):
    as_written = json.loads(BAR.read_text())  # "../data/robots/yumi/yumi.urdf"
    assert_same_statics(shapectl.Scene.from_dict(as_written, base_dir=SCENES), bar_scene)
    # The default base is the current directory.
    monkeypatch.chdir(SCENES)
    assert_same_statics(shapectl.Scene.from_dict(as_written), bar_scene)
    # to_dict(base_dir) writes them relative to it, as a scene file there would name them.
    relative = bar_scene.to_dict(base_dir=SCENES)
    assert relative["robot"]["urdf"] == "../data/robots/yumi/yumi.urdf"
    assert relative["robot"]["collision_spheres"] == "../data/robots/yumi/yumi_spheres.json"
    moved = tmp_path / "elsewhere"
    moved.mkdir()
    monkeypatch.chdir(moved)  # where ../data does not exist
    with pytest.raises(ValueError, match="yumi.urdf"):
        shapectl.Scene.from_dict(as_written)


def test_a_scene_without_robot_round_trips():
    clamped = shapectl.Scene.load(CLAMPED)
    d = clamped.to_dict()
    assert "robot" not in d
    assert_same_statics(shapectl.Scene.from_dict(d), clamped)


@pytest.mark.parametrize("change, field", [
    (lambda d: d["object"]["material"].update(youngs_modulus=-3), "object.material.youngs_modulus"),
    (lambda d: d["object"].update(materail=d["object"].pop("material")), "object.materail"),
    (lambda d: d["grips"][0]["region"]["box"].update(min=[5, 5, 5], max=[6, 6, 6]), "grips[0]"),
    (lambda d: d["robot"]["reference_joints"].update(yumi_joint_1_l=3.5),
     "robot.reference_joints.yumi_joint_1_l"),
])
def test_bad_input_raises_the_clis_message_naming_scene(cli, write_json, change, field):
    d = shapectl.Scene.load(BAR).to_dict()
    change(d)
    path = write_json("bad_scene.json", d)
    run = cli("statics", path)
    assert run.exit_code == 1, run.stderr
    with pytest.raises(ValueError) as error:
        shapectl.Scene.from_dict(d)
    assert str(error.value) == run.error_message().replace(str(path), "scene")
    assert str(error.value).startswith(f"scene: {field}")


def test_what_is_not_a_scene_dict_is_named():
    with pytest.raises(ValueError, match="scene: expected a dict of the scene file's schema"):
        shapectl.Scene.from_dict([1, 2])
    with pytest.raises(ValueError, match="scene: object: expected"):
        shapectl.Scene.from_dict({"object": 5})
