"""What the examples share: the default scene (the YuMi holding the foam bar), their command
line's start, and a family of target shapes for a bar, centre-lines bent up and sideways."""

import argparse
from pathlib import Path

import numpy as np

DEFAULT_SCENE = Path(__file__).resolve().parents[2] / "scenes" / "yumi_bar.json"


def argument_parser(doc):
    """An example's command line: its docstring's first paragraph, and --scene."""
    parser = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    parser.add_argument("--scene", default=DEFAULT_SCENE, help="SCENE.json (default: the bar)")
    return parser


def bar_ends(scene):
    """The ends of the bar's axis at rest, world frame (m): the principal direction of its rest
    nodes through their centroid, from the first node's projection to the last."""
    x = scene.rest_positions
    centre = x.mean(axis=0)
    axis = np.linalg.svd(x - centre, full_matrices=False)[2][0]
    along = (x - centre) @ axis
    return centre + along.min() * axis, centre + along.max() * axis


def bent_centerline(scene, lift, shift, points=9):
    """Centre-line targets ({"centerline": (points, 3)}): the bar's axis with its middle raised
    by `lift` and moved sideways (horizontally, across the bar) by `shift`, metres, along half a
    sine; the ends stay. A bend makes the line longer than its chord: the grippers must come
    closer, and a large one asks for more than they can give."""
    a, b = bar_ends(scene)
    up = np.array([0.0, 0.0, 1.0])
    side = np.cross(up, b - a)
    side /= np.linalg.norm(side)
    s = np.linspace(0.0, 1.0, points)[:, None]
    return {"centerline": a + s * (b - a) + np.sin(np.pi * s) * (lift * up + shift * side)}
