"""Generated bad input to every binding that takes arrays, lists or dicts (centre-lines, targets,
joints, warm starts, observations, scene dicts): each is refused with a TypeError or ValueError
that names the argument, never coerced into something the CLI would refuse, never a crash; and
an input over its bound is refused before it is copied."""

import datetime
import fractions
import json
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import shapectl
from conftest import BAR

NODES, JOINTS = 425, 14  # the YuMi bar
# A longdouble beyond float64 warns as numpy casts it (then it is refused as non-finite).
pytestmark = pytest.mark.filterwarnings("ignore:overflow encountered in cast:RuntimeWarning")
MAX_CENTERLINE_POINTS = 2000  # server/protocol.hpp: what a GUI client may send


@pytest.fixture(scope="module")
def bar():
    return shapectl.Scene.load(BAR)


@pytest.fixture(scope="module")
def controller(bar):
    with shapectl.Controller(bar, start=False) as c:
        yield c


def centerline(bar, rows):
    """A valid centre-line of `rows` points: the bar's ends, lifted 2 cm, and points between."""
    rest = bar.rest_positions
    t = np.linspace(0, 1, rows)[:, None]
    return (1 - t) * rest[0] + t * rest[-1] + [0, 0, 0.02]


def bad_arrays(valid, rng, rows_fixed=True):
    """(label, value) pairs, each something a file could not say where `valid` (a float64 array
    of the right shape) belongs: other dtypes, masks, non-finite values, other shapes (a row
    more or less when `rows_fixed`), lists of mixed types."""
    shape = valid.shape
    cases = [
        ("bool", valid > 0),
        ("complex128", valid.astype(np.complex128)),
        ("complex64 with an imaginary part", valid + 1j),
        ("object of floats", valid.astype(object)),
        ("str", valid.astype(str)),
        ("bytes", valid.astype(bytes)),
        ("datetime64", np.zeros(shape, "datetime64[s]")),
        ("timedelta64", np.zeros(shape, "timedelta64[s]")),
        ("structured", np.zeros(shape, [("a", "f8")])),
        ("masked, one entry", np.ma.array(valid, mask=np.eye(*shape, dtype=bool) if valid.ndim == 2
                                          else np.arange(shape[0]) == 0)),
        ("masked, nothing", np.ma.array(valid, mask=False)),
        ("longdouble beyond float64", np.full(shape, np.longdouble("1e4000"))),
        ("transposed", valid.T.copy() if valid.ndim == 2 else valid[None, :]),
        ("an extra axis", valid[None]),
        ("empty", valid[:0]),
        ("0-d", np.array(1.0)),
        ("a float", 1.0),
        ("a str", "1,2,3"),
        ("bytes of three", b"abc"),
        ("a set", {1.0, 2.0, 3.0}),
        ("a dict", {"x": 1.0}),
        ("a generator", (x for x in valid.ravel())),
        ("a memoryview", memoryview(valid)),
    ]
    if rows_fixed:
        cases += [("a row more", np.concatenate([valid, valid[:1]])), ("a row less", valid[:-1])]
    if valid.ndim == 2:
        cases += [("a column less", valid[:, :2]), ("a column more", np.hstack([valid, valid[:, :1]]))]
    for dtype in (np.float64, np.float32, np.float16):
        for bad in (np.nan, np.inf, -np.inf):
            a = valid.astype(dtype)
            a.flat[rng.integers(a.size)] = bad
            cases.append((f"{np.dtype(dtype).name} holding {bad}", a))
    # Lists: one entry replaced by something that is not a real number.
    strangers = [True, np.bool_(False), "3", b"3", None, 1 + 2j, np.complex64(1), float("nan"),
                 -float("inf"), 10 ** 400, fractions.Fraction(1, 3), datetime.date.today(), [1.0],
                 {"x": 1}, np.array([1.0, 2.0])]
    for stranger in strangers:
        rows = valid.tolist()
        k = int(rng.integers(len(rows)))
        if valid.ndim == 2:
            rows[k][int(rng.integers(shape[1]))] = stranger
        else:
            rows[k] = stranger
        cases.append((f"a list holding {stranger!r}", rows))
    if valid.ndim == 2:
        ragged = valid.tolist()
        ragged[int(rng.integers(len(ragged)))].pop()
        cases += [("a ragged list", ragged),
                  ("a list of str rows", ["abc"] * shape[0]),
                  ("a list of bool rows", [np.ones(3, bool)] * shape[0]),
                  ("a list nested one level more", [valid.tolist()])]
    return cases


def refused(call, name, label=""):
    """call() raises TypeError or ValueError whose message names `name`; returns the error."""
    with pytest.raises((TypeError, ValueError)) as error:
        call()
        print("accepted:", label)
    assert name in str(error.value), str(error.value)
    return error.value


def test_a_centerline_is_refused_for_every_bad_dtype_shape_and_value(bar, controller):
    rng = np.random.default_rng(1)
    valid = centerline(bar, 5)
    for label, value in bad_arrays(valid, rng, rows_fixed=False):
        refused(lambda: controller.set_centerline(value), "centerline", label)
    # A wrong type or dtype is a TypeError, a wrong value or shape a ValueError.
    for value, kind in ((valid > 0, TypeError), (np.ma.array(valid), TypeError),
                        (valid.astype(object), TypeError), ([[1, 2, "3"]] * 5, TypeError),
                        (valid * np.nan, ValueError), (valid[:, :2], ValueError)):
        assert isinstance(refused(lambda: controller.set_centerline(value), "centerline"), kind)
    infinite = valid.copy()
    infinite[3, 1] = -np.inf
    assert str(refused(lambda: controller.set_centerline(infinite), "centerline")) == \
        "centerline: expected finite numbers, got -inf at row 3, column 1"
    # The protocol's bounds: 2 to 2000 points, within 10 m of the origin.
    controller.set_centerline(centerline(bar, MAX_CENTERLINE_POINTS))
    controller.set_centerline(centerline(bar, 2).tolist())
    over = centerline(bar, MAX_CENTERLINE_POINTS + 1)
    for value in (over, over.tolist()):
        error = refused(lambda: controller.set_centerline(value), "centerline")
        assert "k from 2 to 2000" in str(error)
    far = centerline(bar, 5)
    far[2] = [10.5, 0, 0]
    assert "within 10 m of the origin" in str(refused(lambda: controller.set_centerline(far), "centerline"))
    # Nothing refused reached the controller: it holds the last good centre-line's targets.
    controller.step()
    assert controller.snapshot().target_nodes.size > 0


def test_joints_and_warm_starts_are_refused_for_every_bad_dtype_shape_and_value(bar):
    rng = np.random.default_rng(2)
    obj = shapectl.GrippedObject(bar)
    paused = shapectl.Controller(bar, start=False)
    paused.pause()
    joints = bar.reference_joints
    calls = {
        "statics": lambda v: shapectl.statics(bar, v),
        "kinematics of the scene": lambda v: shapectl.kinematics(bar, v),
        "kinematics of the robot": lambda v: shapectl.kinematics(bar.robot, v),
        "GrippedObject.solve": lambda v: obj.solve(joints=v),
        "Controller.jog": lambda v: paused.jog(v),
    }
    count = 0
    for label, value in bad_arrays(joints, rng):
        if isinstance(value, dict):
            continue  # a {name: rad} dict: the dict cases below
        for name, call in calls.items():
            refused(lambda: call(value), "joints", f"{name}: {label}")
            count += 1
    for label, value in bad_arrays(bar.rest_positions, rng):
        refused(lambda: obj.solve(warm_start=value), "warm_start", label)
        count += 1
    # The stacked (3n,) form is a form of positions, the same values.
    assert obj.solve(warm_start=bar.rest_positions.ravel(), max_iterations=1).positions.shape == (NODES, 3)
    assert count > 200
    paused.close()


SCALAR_STRANGERS = [("True", True), ("None", None), ("a str", "0.1"), ("complex", 1 + 1j),
                    ("NaN", float("nan")), ("float32 inf", np.float32("inf")),
                    ("complex128", np.complex128(1)), ("np.bool_", np.bool_(True)),
                    ("a list", [0.1]), ("an array", np.array([0.1])),
                    ("a 0-d object array", np.array(0.1, dtype=object)),
                    ("a masked scalar array", np.ma.array(0.1)), ("a Fraction", fractions.Fraction(1, 10)),
                    ("an int beyond float64", 10 ** 400), ("a set", {0.1})]


def point_values(rng):
    """(label, value): values a JSON file could not hold where a point [x, y, z] belongs, or
    holds only as something the reader refuses there."""
    return [(label, v) for label, v in bad_arrays(np.array([0.3, 0.0, 0.2]), rng)
            if not isinstance(v, (str, dict))] + SCALAR_STRANGERS


def test_values_inside_dicts_are_refused_as_the_files_reader_refuses_them(bar, controller):
    rng = np.random.default_rng(3)
    name = bar.joint_names[0]
    frame = {"joints": dict(zip(bar.joint_names, bar.reference_joints)), "sigma": 0.001}
    # Each call with a good value first (so a refusal below is the value's), then the bad ones.
    calls = {
        "targets": [
            (lambda v: shapectl.solve(bar, {"targets": [{"node": 3, "position": v}]}, max_iterations=1),
             bar.rest_positions[3] + [0, 0, 0.01]),
            (lambda v: shapectl.solve(bar, {"centerline": [v, centerline(bar, 2)[1]]}, max_iterations=1),
             centerline(bar, 2)[0]),
            (lambda v: controller.set_targets({"targets": [{"node": 3, "position": v}]}),
             bar.rest_positions[3]),
        ],
        "joints": [(lambda v: shapectl.statics(bar, {name: v}), 0.1),
                   (lambda v: shapectl.kinematics(bar, {name: v}), 0.1)],
        "observations": [
            (lambda v: shapectl.calibrate(bar, {"frames": [dict(frame, markers=[{"node": 3, "position": v}])]},
                                          max_iterations=1),
             bar.rest_positions[3]),
        ],
    }
    for list_of_calls in calls.values():
        for call, good in list_of_calls:
            call(good)
    count = 0
    for name_in_message, list_of_calls in calls.items():
        values = SCALAR_STRANGERS if name_in_message == "joints" else point_values(rng)
        for label, value in values:
            for call, _ in list_of_calls:
                refused(lambda: call(value), name_in_message, label)
                count += 1
    # A scene's numeric array: gravity.
    scene = json.loads(json.dumps(bar.to_dict()))
    shapectl.Scene.from_dict(dict(scene, gravity=np.array([0, 0, -9.81])))
    for label, value in point_values(rng)[::3]:
        refused(lambda: shapectl.Scene.from_dict(dict(scene, gravity=value)), "scene", label)
        count += 1
    assert count > 250
    # Masked, complex and object arrays are TypeErrors; NaN a ValueError.
    for value, kind in ((np.ma.array([1.0, 2.0, 3.0]), TypeError),
                        (np.array([1.0, 2.0, 3.0], dtype=object), TypeError),
                        (np.array([1j, 2, 3]), TypeError),
                        (np.array([np.nan, 0.0, 0.0]), ValueError)):
        assert isinstance(refused(lambda: shapectl.solve(bar, {"targets": [{"node": 3, "position": value}]}),
                                  "targets"), kind)


def test_the_controller_takes_the_protocols_bounds_from_a_dict_too(bar, controller):
    line = centerline(bar, MAX_CENTERLINE_POINTS + 1)
    error = refused(lambda: controller.set_targets({"centerline": line}), "targets")
    assert "at most 2000 points" in str(error)
    error = refused(lambda: controller.set_targets({"targets": [{"node": 3, "position": [20.0, 0, 0]}]}),
                    "targets")
    assert "within 10 m of the origin" in str(error)
    # solve() reads the dict as the CLI reads TARGETS.json: more points are fine there.
    assert shapectl.solve(bar, {"centerline": line}, max_iterations=1).target_nodes.size > 0


def test_number_arguments_refuse_bools_strings_and_complex_numbers(bar, controller):
    targets = {"targets": [{"node": 3, "position": bar.rest_positions[3] + [0, 0, 0.01]}]}
    obj = shapectl.GrippedObject(bar)
    integers = {"solve max_iterations": lambda v: shapectl.solve(bar, targets, max_iterations=v),
                "GrippedObject.solve max_iterations": lambda v: obj.solve(max_iterations=v),
                "calibrate max_iterations": lambda v: shapectl.calibrate(bar, {"frames": []}, max_iterations=v)}
    reals = {"solve max_seconds": lambda v: shapectl.solve(bar, targets, max_iterations=1, max_seconds=v),
             "solve tolerance": lambda v: shapectl.solve(bar, targets, max_iterations=1, tolerance=v),
             "wait_for_snapshot timeout": lambda v: controller.wait_for_snapshot(0, timeout=v)}
    strangers = [True, False, np.bool_(True), "1", b"1", 1 + 0j, np.complex64(1), None, [1], np.array([1]),
                 fractions.Fraction(1, 2)]
    for calls, extra in ((integers, [1.0, 1.5, np.float64(2), 2 ** 40]), (reals, [10 ** 400])):
        for name, call in calls.items():
            for value in strangers + extra:
                with pytest.raises(TypeError, match="incompatible function arguments"):
                    call(value)
    # numpy scalars of the right kind are numbers, and an int is a float.
    assert obj.solve(max_iterations=np.int64(1)).statics.iterations <= 1
    assert shapectl.solve(bar, targets, max_iterations=np.int32(1), tolerance=np.float32(0.5),
                          max_seconds=30).status == "reached"
    controller.wait_for_snapshot(0, timeout=np.float64(0.01))


def test_fit_lists_hold_names_only(bar):
    for fit in (["youngs_modulus", 3], [b"youngs_modulus"], 3, {"youngs_modulus": 1}):
        refused(lambda: shapectl.calibrate(bar, {"frames": []}, fit=fit), "fit")


PEAK_PROBE = textwrap.dedent("""
    import json, resource, sys
    import numpy as np
    import shapectl

    bar = shapectl.Scene.load(sys.argv[1])
    controller = shapectl.Controller(bar, start=False)
    obj = shapectl.GrippedObject(bar)
    rows = 20_000_000  # 480 MB as float64, ~1.5 GB as Python floats, ~280 MB as JSON
    view = np.broadcast_to(np.zeros(3), (rows, 3))  # 24 bytes
    inputs = {
        "centerline view": (view, controller.set_centerline),
        "warm_start view": (view, lambda v: obj.solve(warm_start=v)),
        "joints view": (np.broadcast_to(np.zeros(1), (rows,)), lambda v: shapectl.statics(bar, v)),
        "targets dict view": (view, lambda v: shapectl.solve(bar, {"centerline": v})),
        "observations dict view": (view, lambda v: shapectl.calibrate(bar, {"frames": [{"points": v}]})),
        # Lists last: freeing one leaves the peak above what the process then holds.
        "centerline list": ("list", controller.set_centerline),
        "targets dict list": ("list", lambda v: shapectl.solve(bar, {"centerline": v})),
    }
    peaks = {}
    for name, (value, call) in inputs.items():
        if isinstance(value, str):
            value = [[0.0, 0.0, 0.0]] * rows  # 160 MB of references to one row
        before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        try:
            call(value)
            peaks[name] = "accepted"
        except (TypeError, ValueError):
            peaks[name] = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before) * 1024
        del value
    print(json.dumps(peaks))
""")


def test_inputs_over_their_bound_are_refused_without_being_copied():
    # A fresh process: its peak RSS before each call is the memory it holds then (a list of 20
    # million references to one row is 160 MB, allocated before the measurement).
    probe = subprocess.run([sys.executable, "-c", PEAK_PROBE, str(BAR)], capture_output=True,
                           text=True, timeout=300)
    assert probe.returncode == 0, probe.stderr
    peaks = json.loads(probe.stdout)
    for name, grown in peaks.items():
        assert grown != "accepted", name
        # Each would take 280 MB or more if converted; 8 MB of JSON text is the most any may hold.
        assert grown < 40e6, (name, grown)
