"""Shared helpers: the bundled scenes, and running the built CLI to compare against.

CTest sets PYTHONPATH (build/python), SHAPECTL_CLI and SHAPECTL_SOURCE_DIR; by hand:
PYTHONPATH=build/python /usr/bin/python3 -m pytest tests/python
"""

import json
import os
import subprocess
import sys
import threading
import time
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


def counted_during(call, attempts=10):
    """Runs call() in a thread (again, up to `attempts` times, until it is seen) while another
    thread counts, with no forced GIL switches: the counter can advance during a call only if the
    call released the GIL; it sleeps between counts, so the caller's thread gets the GIL back.
    Returns how far it advanced during each call."""
    counter = {"n": 0, "stop": False}

    def count():
        while not counter["stop"]:
            counter["n"] += 1
            time.sleep(0.0002)

    advanced = []

    def call_until_counted():
        for _ in range(attempts):
            before = counter["n"]
            call()
            advanced.append(counter["n"] - before)
            if advanced[-1] > 0:
                return

    interval = sys.getswitchinterval()
    sys.setswitchinterval(100.0)
    try:
        counter_thread = threading.Thread(target=count)
        counter_thread.start()
        caller = threading.Thread(target=call_until_counted)
        caller.start()
        caller.join()
        counter["stop"] = True
        counter_thread.join()
    finally:
        sys.setswitchinterval(interval)
    return advanced
