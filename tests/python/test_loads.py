"""Scenes with "loads" and "regions" from Python: the same equilibria and loads_total as the CLI,
the same errors naming the field."""

import json

import numpy as np
import pytest

import shapectl
from conftest import CLAMPED

TIP = {"box": {"min": [0.159, -1, -1], "max": [1, 1, 1]}}
SOFT_ROOT = {"box": {"min": [-1, -1, -1], "max": [0, 1, 1]},
             "material": {"youngs_modulus": 5e4, "poisson_ratio": 0.3, "density": 40}}


def clamped_with(**keys):
    scene = json.loads(CLAMPED.read_text())
    scene.update(keys)
    return scene


def test_statics_with_loads_and_regions_match_the_cli(cli, write_json):
    scene = clamped_with(loads=[dict(TIP, force=[0, 0.01, -0.05]), {"nodes": [3], "force": [0.02, 0, 0]}],
                         regions=[SOFT_ROOT])
    run = cli("statics", write_json("scene.json", scene))
    assert run.exit_code == 0, run.stderr
    py = shapectl.statics(shapectl.Scene.from_dict(scene))
    assert py.converged and run.result["converged"]
    assert py.iterations == run.result["iterations"]
    np.testing.assert_allclose(py.positions, run.result["positions"], rtol=0, atol=1e-12)
    assert py.loads_total.shape == (3,)
    np.testing.assert_allclose(py.loads_total, [0.02, 0.01, -0.05], rtol=0, atol=1e-15)
    np.testing.assert_array_equal(py.loads_total, run.result["loads_total"])
    # Without loads the total is zero, and the loaded, softer bar hangs lower.
    plain = shapectl.statics(shapectl.Scene.load(CLAMPED))
    np.testing.assert_array_equal(plain.loads_total, [0, 0, 0])
    assert py.positions[:, 2].min() < plain.positions[:, 2].min() - 0.01


def test_a_solve_reports_the_loads_total(bar_scene):
    scene = json.loads(json.dumps(bar_scene.to_dict()))
    scene["loads"] = [{"box": {"min": [-0.01, -1, -1], "max": [0.01, 1, 1]}, "force": [0, 0, -0.2]}]
    loaded = shapectl.Scene.from_dict(scene)
    positions = shapectl.statics(loaded).positions
    targets = {"targets": [{"node": i, "position": positions[i]} for i in range(0, 425, 53)]}
    r = shapectl.solve(loaded, targets, max_iterations=5)
    np.testing.assert_array_equal(r.loads_total, [0, 0, -0.2])
    # The loaded equilibrium is where it starts: its own targets are met.
    assert r.error_max < 1e-6


@pytest.mark.parametrize("keys, field", [
    ({"loads": [{"nodes": [425], "force": [0, 0, 1]}]}, "loads[0].nodes[0]"),
    ({"loads": [{"box": {"min": [1, 1, 1], "max": [2, 2, 2]}, "force": [0, 0, 1]}]}, "loads[0].box"),
    ({"regions": [dict(SOFT_ROOT, material={"mu": -1, "kappa": 1e4, "density": 40})]},
     "regions[0].material.mu"),
])
def test_bad_loads_and_regions_raise_value_error_naming_the_field(keys, field):
    with pytest.raises(ValueError, match=r"^scene: " + field.replace("[", r"\[").replace("]", r"\]") + ": "):
        shapectl.Scene.from_dict(clamped_with(**keys))


def test_calibrate_takes_each_frames_loads_and_separates_stiffness_and_density():
    """Issue 35: frames of a bar 20 % softer and 25 % denser, unloaded and with 7 g and 14 g on
    its free end, each with its "loads": E and density both determined, each within 3 %."""
    truth_material = {"youngs_modulus": 1.6e5, "poisson_ratio": 0.3, "density": 50}
    model = shapectl.Scene.load(CLAMPED)
    rng = np.random.default_rng(9)
    frames = []
    for grams in (0, 7, 14):
        loads = [dict(TIP, force=[0, 0, -grams * 1e-3 * 9.81])] if grams else []
        truth = clamped_with(loads=loads)
        truth["object"]["material"] = truth_material
        equilibrium = shapectl.statics(shapectl.Scene.from_dict(truth))
        assert equilibrium.converged, equilibrium.reason
        observed = equilibrium.positions + rng.normal(0, 0.0005, equilibrium.positions.shape)
        frames.append({"markers": [{"node": i, "position": observed[i].tolist()}
                                   for i in range(3, model.node_count, 28)],
                       "sigma": 0.0005, "loads": loads})
    result = shapectl.calibrate(model, {"frames": frames}, fit="youngs_modulus,density")
    assert result.converged, result.reason
    stiffness, density = result.parameters
    assert (stiffness.verdict, density.verdict) == ("determined", "determined")
    assert stiffness.fitted == pytest.approx(1.6e5, rel=0.03)
    assert density.fitted == pytest.approx(50, rel=0.03)
    # Without the loads the same frames cannot say which: density held, loads suggested.
    for frame in frames:
        del frame["loads"]
    blind = shapectl.calibrate(model, {"frames": frames}, fit="youngs_modulus,density")
    assert blind.parameters[1].verdict == "not determined"
    assert '"loads"' in blind.parameters[1].suggestion
