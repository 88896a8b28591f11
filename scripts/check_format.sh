#!/usr/bin/env bash
# Lists the C++ files (src apps bench tests python/src, *.hpp *.cpp) that clang-format would change under
# the repository's .clang-format; exits 1 if there are any, 0 if none. Changes nothing.
# Fix one file: clang-format -i FILE. Written for Debian 12's clang-format 14; other versions
# may format some constructs differently.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v clang-format > /dev/null; then
  echo "check_format: clang-format not found (Debian: sudo apt-get install -y clang-format)" >&2
  exit 2
fi
version=$(clang-format --version | sed -n 's/.*version \([0-9]*\).*/\1/p')
if [ "$version" != "14" ]; then
  echo "check_format: clang-format $version, not 14: results may differ from CI's" >&2
fi
unformatted=()
while IFS= read -r -d '' file; do
  if ! clang-format --style=file "$file" | cmp -s - "$file"; then unformatted+=("$file"); fi
done < <(find src apps bench tests python/src -type f \( -name '*.hpp' -o -name '*.cpp' \) -print0 | sort -z)
if [ ${#unformatted[@]} -gt 0 ]; then
  echo "check_format: ${#unformatted[@]} file(s) not formatted (fix: clang-format -i FILE):" >&2
  printf '%s\n' "${unformatted[@]}"
  exit 1
fi
echo "check_format: all files formatted"
