#!/usr/bin/env bash
# CTest's install_consumer: install the build into a temporary prefix, then use that tree only.
#   install_test.sh BUILD_DIR NATIVE_CFLAGS PYTHON_DIR
# NATIVE_CFLAGS: "-march=native" when SHAPECTL_NATIVE is on, else ""; PYTHON_DIR: where the
# Python package goes under the prefix ("" when it is not built).
# Checks: consumer/ (find_package(shapectl)) configures, builds and prints the statics the
# installed CLI computes; -march=native reaches its compile line; the same object file links
# with `pkg-config --libs shapectl`; the installed Python package imports and agrees; every
# module the installed web page imports is installed.
set -euo pipefail
build_dir=$1 native_cflags=$2 python_dir=$3
here="$(cd "$(dirname "$0")" && pwd)"
work="$(mktemp -d "${TMPDIR:-/tmp}/shapectl-install-test.XXXXXX")"
trap 'rm -rf "$work"' EXIT
prefix="$work/prefix"
fail() { echo "install_test: $*" >&2; exit 1; }

cmake --install "$build_dir" --prefix "$prefix" >"$work/install.log" 2>&1 || {
  cat "$work/install.log" >&2; fail "cmake --install failed"; }
data="$prefix/share/shapectl"
scene="$data/scenes/yumi_bar.json"
[ -f "$scene" ] || fail "$scene not installed"

# The installed CLI's statics: the numbers to compare with.
"$prefix/bin/shapectl" statics "$scene" --out "$work/statics.json" 2>/dev/null
read -r cli_iterations cli_energy < <(python3 -c '
import json, sys
r = json.load(open(sys.argv[1]))
print(r["iterations"], "%.17g" % r["energy"])' "$work/statics.json")  # the consumer's printf format
expected="nodes 425
converged 1
iterations $cli_iterations
energy $cli_energy"

# The out-of-tree project, by find_package(shapectl) from the prefix alone.
cmake -S "$here/consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$prefix" \
      -DCMAKE_EXPORT_COMPILE_COMMANDS=ON >"$work/configure.log" 2>&1 || {
  cat "$work/configure.log" >&2; fail "the consumer does not configure"; }
cmake --build "$work/consumer" -j2 >"$work/build.log" 2>&1 || {
  cat "$work/build.log" >&2; fail "the consumer does not build"; }
out="$("$work/consumer/consumer" "$scene")"
[ "$out" = "$expected" ] || fail "consumer printed
$out
expected (the installed CLI's statics)
$expected"
if [ -n "$native_cflags" ]; then
  grep -q -- "$native_cflags" "$work/consumer/compile_commands.json" ||
    fail "the consumer is compiled without $native_cflags (the libraries' Eigen ABI)"
fi

# pkg-config: its flags are the ones the CMake package gives, its libraries link the program.
export PKG_CONFIG_PATH="$prefix/lib/pkgconfig"
cflags="$(pkg-config --cflags shapectl)"
includes_prefix=no
for flag in $cflags; do
  [[ "$flag" == -I* ]] && [ "$(realpath -m "${flag#-I}")" = "$(realpath -m "$prefix/include")" ] && includes_prefix=yes
done
[ "$includes_prefix" = yes ] || fail "pkg-config --cflags shapectl: $cflags (no -I$prefix/include)"
[ -z "$native_cflags" ] || [[ " $cflags " == *" $native_cflags "* ]] ||
  fail "pkg-config --cflags shapectl: $cflags (no $native_cflags)"
object="$(find "$work/consumer" -name 'main.cpp.o' | head -n 1)"
# shellcheck disable=SC2046 # the flags are words
c++ "$object" -o "$work/consumer_pc" $(pkg-config --libs shapectl) ||
  fail "the consumer does not link with pkg-config --libs shapectl"
[ "$("$work/consumer_pc" "$scene")" = "$expected" ] || fail "the pkg-config build differs"

# The Python package, from the prefix's site directory (no build tree on the path).
if [ -n "$python_dir" ]; then
  PYTHONPATH="$prefix/$python_dir" /usr/bin/python3 - "$scene" "$prefix" "$cli_energy" <<'EOF' ||
import sys
import shapectl
scene_path, prefix, cli_energy = sys.argv[1], sys.argv[2], float(sys.argv[3])
assert shapectl.__file__.startswith(prefix), shapectl.__file__
energy = shapectl.statics(shapectl.Scene.load(scene_path)).energy
assert energy == cli_energy, (energy, cli_energy)
EOF
    fail "the installed Python package does not import or differs from the CLI"
fi

# The web client: every module the installed page imports, relative or through its import map
# ("three" and "three/addons/" in index.html), is installed.
web="$data/web"
[ -f "$web/index.html" ] || fail "web/index.html not installed"
missing=""
while IFS= read -r js; do
  while IFS= read -r spec; do
    case "$spec" in
      three) target="$web/node_modules/three/build/three.module.js" ;;
      three/addons/*) target="$web/node_modules/three/examples/jsm/${spec#three/addons/}" ;;
      ./* | ../*) target="$(dirname "$js")/$spec" ;;
      *) target="$web/$spec" ;;
    esac
    [ -f "$target" ] || missing+=" ${js#"$web"/} imports $spec;"
  done < <(grep -ohE "(from|import) +['\"][^'\"]+['\"]" "$js" | sed -E "s/.*['\"](.+)['\"]/\1/")
done < <(find "$web" -name '*.js')
[ -z "$missing" ] || fail "not installed:$missing"
for asset in js/main.js css/style.css; do
  grep -q "$asset" "$web/index.html" && [ -f "$web/$asset" ] || fail "$asset not installed"
done

# The installed `serve` finds its page and scenes in the prefix, with no --web-root: it answers
# GET / with the installed index.html (marked, so that the source tree's copy cannot pass).
echo "<!-- the installed copy -->" >>"$web/index.html"
"$prefix/bin/shapectl" serve --port 0 >"$work/serve.out" 2>"$work/serve.err" &
serve_pid=$!
url=""
for _ in $(seq 200); do
  url="$(grep -oE 'http://[^ ]+/' "$work/serve.out" || true)"
  [ -n "$url" ] && break
  sleep 0.05
done
[ -n "$url" ] || { kill "$serve_pid"; cat "$work/serve.err" >&2; fail "installed serve printed no URL"; }
if ! python3 - "$url" "$web/index.html" <<'EOF'
import sys, urllib.request
page = urllib.request.urlopen(sys.argv[1], timeout=10).read()
assert page == open(sys.argv[2], "rb").read()
EOF
then
  kill "$serve_pid"; fail "installed serve does not serve the installed page"
fi
kill "$serve_pid"
wait "$serve_pid" 2>/dev/null || true
echo "install_test: installed tree builds, links and runs a consumer; Python, web and serve complete"
