"""Scenes with "obstacles" from Python (docs/contact.md): the keys pass through Scene.from_dict
and to_dict, and statics and solve results carry "contacts" as the CLI's RESULT.json does, the
obstacles' force on the object upwards; with contact.self also its "self" part."""

import json

import numpy as np
import pytest

import shapectl
from conftest import BAR, SOURCE_DIR

GAP = 0.0005  # m: every obstacle this far from the object at the start, within d̂ = 1 mm
SIZE = [0.1, 0.04, 0.04]
DENSITY = 40
GRAVITY = 9.81


def boxed_block():
    """A foam block on a table in a pocket: four frictionless walls hold it sideways (without
    them nothing would, and Newton would meet a singular matrix), the table alone carries its
    weight. Nothing is fixed."""
    hx, hy, hz = (s / 2 for s in SIZE)
    walls = [([-hx - GAP, 0, 0], [1, 0, 0]), ([hx + GAP, 0, 0], [-1, 0, 0]),
             ([0, -hy - GAP, 0], [0, 1, 0]), ([0, hy + GAP, 0], [0, -1, 0])]
    return {
        "object": {"mesh": {"box": {"size": SIZE, "cells": [5, 2, 2]}},
                   "material": {"youngs_modulus": 2e5, "poisson_ratio": 0.3, "density": DENSITY},
                   "pose": {"position": [0, 0, hz + GAP], "rpy": [0, 0, 0]}},
        "gravity": [0, 0, -GRAVITY],
        "obstacles": [{"name": "table", "plane": {"point": [0, 0, 0], "normal": [0, 0, 1]}}]
        + [{"name": f"wall {k + 1}", "plane": {"point": p, "normal": n}} for k, (p, n) in enumerate(walls)],
        "contact": {"distance": 0.001},
    }


def test_the_scene_keys_pass_through_from_dict_and_to_dict():
    scene = shapectl.Scene.from_dict(boxed_block())
    d = scene.to_dict()
    assert [o["name"] for o in d["obstacles"]] == ["table", "wall 1", "wall 2", "wall 3", "wall 4"]
    assert d["contact"]["distance"] == 0.001
    again = shapectl.Scene.from_dict(json.loads(json.dumps(d)))
    assert [o["name"] for o in again.to_dict()["obstacles"]] == [o["name"] for o in d["obstacles"]]


def test_a_block_resting_on_a_table_is_carried_by_it(cli, write_json):
    scene = boxed_block()
    weight = DENSITY * np.prod(SIZE) * GRAVITY
    py = shapectl.statics(shapectl.Scene.from_dict(scene))
    assert py.converged, py.reason
    c = py.contacts
    # The table pushes up with the weight; the walls' pushes cancel and have no vertical part.
    np.testing.assert_allclose(c["force_total"], [0, 0, weight], rtol=0, atol=1e-4 * weight)
    np.testing.assert_allclose(c["by_obstacle"]["table"]["force"], [0, 0, weight], rtol=0, atol=1e-4 * weight)
    assert c["by_obstacle"]["table"]["count"] > 0
    assert c["count"] == sum(o["count"] for o in c["by_obstacle"].values())
    assert 0 < c["min_distance"] < 0.001
    # Resting: the block sank from 0.5 mm to a gap of order d̂/2 and stays above the table.
    assert 0 < py.positions[:, 2].min() < GAP
    # The CLI's RESULT.json says the same.
    run = cli("statics", write_json("scene.json", scene))
    assert run.exit_code == 0, run.stderr
    assert run.result["contacts"]["count"] == c["count"]
    np.testing.assert_allclose(run.result["contacts"]["force_total"], c["force_total"], rtol=0, atol=1e-12)


def test_without_obstacles_there_are_no_contacts(bar_scene):
    assert shapectl.statics(bar_scene).contacts is None


def test_a_solve_reports_the_contacts_of_its_best_joints(bar_scene):
    # The bar over a peg across its middle, 0.5 mm below it: it sags onto it.
    d = json.loads(json.dumps(bar_scene.to_dict()))
    z = 0.25527 - 0.015 - GAP - 0.01
    d["obstacles"] = [{"name": "peg", "capsule": {"a": [0.33, 0, z], "b": [0.45, 0, z], "radius": 0.01}}]
    scene = shapectl.Scene.from_dict(d)
    positions = shapectl.statics(scene).positions
    targets = {"targets": [{"node": i, "position": positions[i]} for i in range(0, 425, 53)]}
    r = shapectl.solve(scene, targets, max_iterations=3)
    peg = r.contacts["by_obstacle"]["peg"]
    assert peg["count"] == r.contacts["count"] > 0
    assert r.contacts["force_total"][2] > 0
    np.testing.assert_array_equal(peg["force"], r.contacts["force_total"])
    # Part of the weight is on the peg, the rest in the grips.
    weight = 40 * 0.32 * 0.03 * 0.03 * 9.81
    assert r.contacts["force_total"][2] < weight


def slit_bar(bar_scene, press):
    """The YuMi bar slit through its middle (tests/data/slit_bar.py), its upper slab's middle
    pressed down by `press` N onto the lower one, with contact.self."""
    d = json.loads(json.dumps(bar_scene.to_dict()))
    d["object"]["mesh"] = {"file": str(SOURCE_DIR / "tests" / "data" / "slit_bar.node")}
    d["loads"] = [{"box": {"min": [-0.021, -1, 0.0005], "max": [0.021, 1, 0.0076]},
                   "force": [0, 0, -press]}]
    d["contact"] = {"self": True}
    return d


def test_self_contact_has_its_count_and_gap_as_in_the_cli(bar_scene, cli, write_json):
    d = slit_bar(bar_scene, 0.5)
    py = shapectl.statics(shapectl.Scene.from_dict(d))
    assert py.converged, py.reason
    c = py.contacts
    # No obstacle: nothing in the obstacles' part; the slab pressed shut within d̂.
    assert (c["count"], c["min_distance"], c["by_obstacle"]) == (0, None, {})
    np.testing.assert_array_equal(c["force_total"], [0, 0, 0])
    assert c["self"]["count"] > 0
    assert 0 < c["self"]["min_distance"] < 0.001
    run = cli("statics", write_json("scene.json", d))
    assert run.exit_code == 0, run.stderr
    assert run.result["contacts"]["self"]["count"] == c["self"]["count"]
    assert run.result["contacts"]["self"]["min_distance"] == pytest.approx(c["self"]["min_distance"], rel=1e-9)
    # A solve's best joints: the slit stays shut.
    targets = {"targets": [{"node": i, "position": py.positions[i]} for i in range(0, 306, 17)]}
    r = shapectl.solve(shapectl.Scene.from_dict(d), targets, max_iterations=2)
    assert r.contacts["self"]["count"] > 0
    # Open: none, no gap.
    assert shapectl.statics(shapectl.Scene.from_dict(slit_bar(bar_scene, 0))).contacts["self"] == {
        "count": 0, "min_distance": None}


def test_without_self_contact_there_is_no_self_part(bar_scene):
    d = slit_bar(bar_scene, 0)
    d["contact"] = {"self": False}
    assert shapectl.statics(shapectl.Scene.from_dict(d)).contacts is None


@pytest.mark.parametrize("contact, field", [
    ({"friction": -0.3}, "contact.friction"),
    ({"self": 1}, "contact.self"),
    ({"distance": -1}, "contact.distance"),
])
def test_what_is_not_modelled_or_bad_is_refused_naming_the_field(contact, field):
    d = boxed_block()
    d["contact"] = contact
    with pytest.raises(ValueError, match=r"^scene: " + field.replace(".", r"\.") + ": "):
        shapectl.Scene.from_dict(d)
