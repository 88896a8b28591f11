#!/usr/bin/env bash
# CTest's portable_install (a build with SHAPECTL_NATIVE OFF, the default): the installed tree
# runs on an x86-64 CPU without AVX.
#   portable_test.sh BUILD_DIR PYTHON_DIR
# PYTHON_DIR: where the Python package goes under the prefix ("" when it is not built).
# Checks: no -march in the installed CMake package or pkg-config file (nothing forced on
# consumers); no instruction in the installed CLI, libraries or Python module uses an AVX
# register (ymm, zmm, AVX-512 masks) or any VEX encoding; under qemu-x86_64 -cpu Nehalem (SSE4.2,
# no AVX), which is first shown to refuse an AVX2 instruction, the installed CLI and Python
# module compute the host's statics (up to round-off; each other's bit for bit). Needs qemu-user
# (scripts/setup.sh).
set -euo pipefail
build_dir=$1 python_dir=$2
work="$(mktemp -d "${TMPDIR:-/tmp}/shapectl-portable-test.XXXXXX")"
trap 'rm -rf "$work"' EXIT
prefix="$work/prefix"
old_cpu=Nehalem
fail() { echo "portable_test: $*" >&2; exit 1; }

command -v qemu-x86_64 >/dev/null || fail "qemu-x86_64 not found (apt-get install qemu-user)"
command -v objdump >/dev/null || fail "objdump not found (apt-get install binutils)"
cmake --install "$build_dir" --prefix "$prefix" >"$work/install.log" 2>&1 || {
  cat "$work/install.log" >&2; fail "cmake --install failed"; }

# What consumers are given: no instruction-set flag.
if grep -rn -e '-march' -e '-mavx' -e '-mtune' "$prefix/lib/cmake/shapectl" "$prefix/lib/pkgconfig"; then
  fail "the installed package hands consumers the flags above"
fi

# What is installed: no AVX instruction anywhere (objdump reads archives member by member).
binaries=("$prefix/bin/shapectl" "$prefix"/lib/libshapectl_*.a)
if [ -n "$python_dir" ]; then
  binaries+=("$prefix/$python_dir"/shapectl/_shapectl*.so)
fi
for binary in "${binaries[@]}"; do
  [ -f "$binary" ] || fail "$binary not installed"
  objdump -d --no-show-raw-insn "$binary" >"$work/disassembly.txt"
  [ -s "$work/disassembly.txt" ] || fail "objdump printed nothing for $binary"
  registers="$(grep -cE '%(ymm|zmm)[0-9]|%k[0-7]\b' "$work/disassembly.txt" || true)"
  vex="$(grep -cE '^\s+[0-9a-f]+:\s+v[a-z0-9]+\s' "$work/disassembly.txt" || true)"
  [ "$registers" = 0 ] && [ "$vex" = 0 ] ||
    fail "${binary#"$prefix"/}: $registers instructions on AVX registers, $vex VEX-encoded, e.g.
$(grep -m 3 -E '%(ymm|zmm)[0-9]|%k[0-7]\b|^\s+[0-9a-f]+:\s+v[a-z0-9]+\s' "$work/disassembly.txt")"
done

# The emulated CPU is really an old one: it refuses an AVX2 instruction.
cat >"$work/avx2.c" <<'EOF'
int main(void) { __asm__ volatile("vpaddd %%ymm0, %%ymm0, %%ymm0" ::: "xmm0"); return 0; }
EOF
cc "$work/avx2.c" -o "$work/avx2" || fail "cannot compile the AVX2 probe"
if (qemu-x86_64 -cpu "$old_cpu" "$work/avx2") 2>/dev/null; then
  fail "qemu-x86_64 -cpu $old_cpu ran an AVX2 instruction: it proves nothing"
fi

# The installed CLI on that CPU: the host's statics up to round-off (our instructions are the
# same, but OpenBLAS and libm pick other kernels for an older CPU: no FMA).
scene="$prefix/share/shapectl/scenes/yumi_bar.json"
"$prefix/bin/shapectl" statics "$scene" --out "$work/host.json" 2>/dev/null
# OPENBLAS_THREAD_TIMEOUT set: the CLI would otherwise re-exec itself to set it, and qemu-user
# runs an exec'd program natively.
OPENBLAS_THREAD_TIMEOUT=4 qemu-x86_64 -cpu "$old_cpu" "$prefix/bin/shapectl" statics "$scene" --out "$work/old_cpu.json" \
  2>"$work/old_cpu.err" || { cat "$work/old_cpu.err" >&2; fail "the CLI fails on $old_cpu"; }
python3 - "$work/host.json" "$work/old_cpu.json" <<'EOF' || fail "the CLI's statics differ on $old_cpu"
import json, math, sys
host, old = (json.load(open(path)) for path in sys.argv[1:])
for key in ("converged", "iterations"):
    assert host[key] == old[key], (key, host[key], old[key])
assert abs(host["energy"] - old["energy"]) <= 1e-12 * abs(host["energy"]), (host["energy"], old["energy"])
distance = max(math.dist(p, q) for p, q in zip(host["positions"], old["positions"], strict=True))
assert distance < 1e-12, f"nodes {distance:.3g} m apart"
EOF

# The installed Python module on that CPU (Debian's python3, numpy and OpenBLAS pick their
# kernels at run time).
if [ -n "$python_dir" ]; then
  cli_energy="$(python3 -c 'import json, sys; print(repr(json.load(open(sys.argv[1]))["energy"]))' \
                "$work/old_cpu.json")"
  PYTHONPATH="$prefix/$python_dir" qemu-x86_64 -cpu "$old_cpu" /usr/bin/python3 - \
    "$scene" "$prefix" "$cli_energy" <<'EOF' 2>"$work/python.err" ||
import sys
import shapectl
scene_path, prefix, cli_energy = sys.argv[1], sys.argv[2], float(sys.argv[3])
assert shapectl.__file__.startswith(prefix), shapectl.__file__
energy = shapectl.statics(shapectl.Scene.load(scene_path)).energy
assert energy == cli_energy, (energy, cli_energy)  # the CLI's on the same CPU: bit for bit
EOF
    { grep -v "TCG doesn't support" "$work/python.err" >&2; fail "the Python module fails on $old_cpu"; }
fi
echo "portable_test: no -march for consumers, no AVX instruction installed; CLI and Python run on $old_cpu"
