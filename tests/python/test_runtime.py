"""Importing shapectl applies the CLI's process-wide tuning (docs/runtime.md), seen from the
libraries it sets, each time in a fresh interpreter: OpenBLAS's idle timeout, glibc's heap
thresholds, TBB's thread limit."""

import json
import os
import subprocess
import sys

import pytest

import shapectl

# Before and after `import shapectl`: OpenBLAS's idle timeout, whether a 48 MiB block is mapped
# on its own (glibc's default) rather than taken from the heap (the policy's 64 MiB threshold).
PROBE = r"""
import ctypes, json, sys
blas = ctypes.CDLL("libopenblas.so.0")
libc = ctypes.CDLL(None)
class Mallinfo2(ctypes.Structure):
    _fields_ = [(name, ctypes.c_size_t) for name in ("arena", "ordblks", "smblks", "hblks",
                "hblkhd", "usmblks", "fsmblks", "uordblks", "fordblks", "keepcost")]
libc.mallinfo2.restype = Mallinfo2
libc.malloc.restype, libc.malloc.argtypes = ctypes.c_void_p, [ctypes.c_size_t]
libc.free.argtypes = [ctypes.c_void_p]

def block_mapped():
    size = 48 << 20
    before = libc.mallinfo2().hblkhd
    block = libc.malloc(size)
    ctypes.memset(block + size - 1, 1, 1)
    mapped = libc.mallinfo2().hblkhd >= before + size
    libc.free(block)
    return mapped

out = {"timeout_before": blas.openblas_thread_timeout(), "mapped_before": block_mapped()}
import shapectl
if len(sys.argv) > 1:
    shapectl.configure_runtime(**json.loads(sys.argv[1]))
out.update(timeout_after=blas.openblas_thread_timeout(), mapped_after=block_mapped(),
           settings=shapectl.runtime_settings())
print(json.dumps(out))
"""

TUNING_VARIABLES = ("OPENBLAS_THREAD_TIMEOUT", "OPENBLAS_NUM_THREADS", "SHAPECTL_THREADS",
                    "MALLOC_MMAP_THRESHOLD_", "MALLOC_TRIM_THRESHOLD_")


def probe(configure=None, **variables):
    env = {k: v for k, v in os.environ.items() if k not in TUNING_VARIABLES}
    env.update(variables)
    args = [sys.executable, "-c", PROBE] + ([json.dumps(configure)] if configure else [])
    run = subprocess.run(args, env=env, capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    return json.loads(run.stdout)


def test_importing_the_module_applies_the_clis_tuning():
    out = probe()
    assert out["timeout_before"] == 0 and out["timeout_after"] == 4
    assert out["mapped_before"] and not out["mapped_after"]
    settings = out["settings"]
    assert settings["threads"] == 0 and settings["blas_idle_timeout"] == 4
    assert settings["tbb_thread_limit"] == len(os.sched_getaffinity(0))
    assert settings["openblas_idle_timeout"] == 4


def test_the_environments_variables_win():
    out = probe(SHAPECTL_THREADS="1", OPENBLAS_THREAD_TIMEOUT="10",
                MALLOC_MMAP_THRESHOLD_=str(1 << 20))
    assert out["timeout_after"] == 10 and out["settings"]["blas_idle_timeout"] == 10
    assert out["mapped_after"]
    assert out["settings"]["threads"] == 1 and out["settings"]["tbb_thread_limit"] == 1


def test_configure_runtime_changes_what_it_is_given():
    settings = probe({"threads": 1, "blas_threads": 1})["settings"]
    assert settings["tbb_thread_limit"] == 1 and settings["openblas_threads"] == 1
    assert settings["blas_idle_timeout"] == 4 and settings["keep_freed_heap"]


def test_configure_runtime_refuses_bad_values():
    with pytest.raises(ValueError, match="configure_runtime: threads: expected an int >= 0, got -1"):
        shapectl.configure_runtime(threads=-1)
    with pytest.raises(ValueError, match="blas_idle_timeout: expected an int from 0 to 30, got 31"):
        shapectl.configure_runtime(blas_idle_timeout=31)
    with pytest.raises(TypeError):
        shapectl.configure_runtime(threads=True)
    assert shapectl.runtime_settings()["threads"] == 0  # nothing applied
