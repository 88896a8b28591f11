"""scripts/bench_table.py: the README table is rewritten between its markers and nowhere else.

Rendering only, from small made-up results: nothing is timed here.
"""
import json
import os
import re
import subprocess
import sys

import pytest

SCRIPT = os.path.join(os.path.dirname(__file__), "..", "..", "scripts", "bench_table.py")
sys.path.insert(0, os.path.dirname(SCRIPT))
import bench_table  # noqa: E402

BEFORE = "# Project\n\nText above, kept as it is.\n\n"
AFTER = "\nText below | with a pipe, kept too.\n"


def fields():
    """Every {source.figure:unit} of the table's rows."""
    found = set()
    for what, figure in bench_table.ROWS:
        found.update(re.findall(r"\{([^}]*)\}", what + figure))
    return sorted(found)


def fake_results(path, low=0.002, high=0.003):
    """Two runs of every source the table names, each figure `low` in one and `high` in the other."""
    sources = {}
    for field in fields():
        source, figure = field.split(":")[0].split(".")
        entry = sources.setdefault(source, {"command": source + " --fake", "date": "2026-01-01",
                                            "machine": "test", "revision": "abc1234",
                                            "runs": [{}, {}]})
        entry["runs"][0][figure], entry["runs"][1][figure] = low, high
    with open(path, "w") as f:
        json.dump({"sources": sources}, f)


def run(*args):
    return subprocess.run([sys.executable, SCRIPT, "render", *args], capture_output=True,
                          text=True)


def test_rewrites_only_between_the_markers(tmp_path):
    results, readme = tmp_path / "results.json", tmp_path / "README.md"
    fake_results(results)
    old_table = "| stale | table |\n| --- | --- |\n| a | 1 |"
    readme.write_text(BEFORE + bench_table.BEGIN + "\n" + old_table + "\n" + bench_table.END + AFTER)
    r = run("--results", str(results), "--readme", str(readme))
    assert r.returncode == 0, r.stderr
    text = readme.read_text()
    assert text.startswith(BEFORE + bench_table.BEGIN + "\n| what | figure |\n")
    assert text.endswith("\n" + bench_table.END + AFTER)
    assert "stale" not in text
    rows = [l for l in text.splitlines() if l.startswith("| ") and "---" not in l]
    assert len(rows) == len(bench_table.ROWS) + 1  # and the header
    # Each figure is the range over the two runs: 2–3 ms, 0.002–0.003 s, 2000–3000 µs.
    assert "2–3 ms" in text and "0.002–0.003 s" in text and "2000–3000 µs" in text
    assert "`statics --fake`: 2026-01-01, test, revision abc1234, 2 runs" in text
    # Rendering again changes nothing.
    assert run("--results", str(results), "--readme", str(readme)).returncode == 0
    assert readme.read_text() == text


@pytest.mark.parametrize("markers", [
    "",  # none
    bench_table.BEGIN + "\n",  # no end
    bench_table.END + "\n" + bench_table.BEGIN + "\n",  # the wrong way round
    (bench_table.BEGIN + "\n" + bench_table.END + "\n") * 2,  # twice
])
def test_fails_clearly_without_one_pair_of_markers(tmp_path, markers):
    results, readme = tmp_path / "results.json", tmp_path / "README.md"
    fake_results(results)
    readme.write_text(BEFORE + markers + AFTER)
    r = run("--results", str(results), "--readme", str(readme))
    assert r.returncode == 1
    assert str(readme) in r.stderr and bench_table.BEGIN in r.stderr and bench_table.END in r.stderr
    assert readme.read_text() == BEFORE + markers + AFTER


def test_a_source_missing_from_the_results_is_named(tmp_path):
    results, readme = tmp_path / "results.json", tmp_path / "README.md"
    fake_results(results)
    document = json.loads(results.read_text())
    del document["sources"]["gui"]
    results.write_text(json.dumps(document))
    readme.write_text(BEFORE + bench_table.BEGIN + "\n" + bench_table.END + AFTER)
    r = run("--results", str(results), "--readme", str(readme))
    assert r.returncode == 1 and "'gui'" in r.stderr
    assert readme.read_text() == BEFORE + bench_table.BEGIN + "\n" + bench_table.END + AFTER


def test_figures_keep_three_significant_digits():
    assert [bench_table.format_value(v, "ms") for v in (0.0078, 0.131, 0.02461, 0.0180)] == \
        ["7.8", "131", "24.6", "18"]
    assert bench_table.format_value(7.2e-05, "ms") == "0.072"
    assert bench_table.format_value(4.6e-06, "us") == "4.6"
    assert bench_table.format_value(761.6, "mb") == "762"
    assert bench_table.format_value(2500, "int") == "2,500"


def test_the_committed_table_is_the_rendered_one(tmp_path):
    """README.md holds exactly what bench/results.json renders to."""
    root = os.path.join(os.path.dirname(SCRIPT), "..")
    readme = tmp_path / "README.md"
    original = open(os.path.join(root, "README.md")).read()
    readme.write_text(original)
    r = run("--results", os.path.join(root, "bench", "results.json"), "--readme", str(readme))
    assert r.returncode == 0, r.stderr
    assert readme.read_text() == original, "run: python3 scripts/bench_table.py render"
