"""Shared helpers: the bundled scenes, and running the built CLI to compare against.

CTest sets PYTHONPATH (build/python), SHAPECTL_CLI and SHAPECTL_SOURCE_DIR; by hand:
PYTHONPATH=build/python /usr/bin/python3 -m pytest tests/python
"""

import json
import os
import subprocess
from pathlib import Path

import pytest

SOURCE_DIR = Path(os.environ.get("SHAPECTL_SOURCE_DIR", Path(__file__).resolve().parents[2]))
CLI = Path(os.environ.get("SHAPECTL_CLI", SOURCE_DIR / "build" / "shapectl"))
BAR = SOURCE_DIR / "scenes" / "yumi_bar.json"
FRAME = SOURCE_DIR / "scenes" / "yumi_frame.json"
CLAMPED = SOURCE_DIR / "scenes" / "foam_bar_clamped.json"
YUMI_URDF = SOURCE_DIR / "data" / "robots" / "yumi" / "yumi.urdf"
YUMI_SPHERES = SOURCE_DIR / "data" / "robots" / "yumi" / "yumi_spheres.json"


class CliRun:
    def __init__(self, completed, out):
        self.exit_code = completed.returncode
        self.stderr = completed.stderr
        self.result = json.loads(out.read_text()) if out is not None and out.exists() else None

    def error_message(self):
        """The message after the CLI's "error: " / "solver failure: " prefix."""
        for line in self.stderr.splitlines():
            for prefix in ("error: ", "solver failure: "):
                if line.startswith(prefix):
                    return line[len(prefix):]
        raise AssertionError("no error line in: " + self.stderr)


@pytest.fixture
def cli(tmp_path):
    """cli(*args, out="name.json") runs `shapectl args... --out tmp/name.json`."""
    assert CLI.exists(), f"{CLI} not built"

    def run(*args, out="out.json"):
        out_path = tmp_path / out if out else None
        command = [str(CLI), *map(str, args)] + (["--out", str(out_path)] if out_path else [])
        completed = subprocess.run(command, capture_output=True, text=True, timeout=120)
        return CliRun(completed, out_path)

    return run


@pytest.fixture
def write_json(tmp_path):
    def write(name, value):
        path = tmp_path / name
        path.write_text(json.dumps(value))
        return path

    return write


@pytest.fixture(scope="session")
def bar_scene():
    import shapectl

    return shapectl.Scene.load(BAR)
