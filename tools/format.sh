#!/usr/bin/env bash
# Formats vkrt's C++ sources with clang-format and the repository's .clang-format:
# src/, tests/, tools/*.cpp and the C++/GLSL headers in shaders/shared.
#
#   tools/format.sh            rewrite the files in place
#   tools/format.sh --check    change nothing; list the files that would change
#                              and exit 1 if there is any (for CI)
#   tools/format.sh [--check] FILE...   only these files
#
# CLANG_FORMAT picks the binary (default: clang-format; Debian package
# clang-format). Debian 12's clang-format 14 and Debian 13's 19 disagree on a
# few constructs (a lambda that is not the last argument, `T C::* member`), so
# a check must use the same major version as the one that formatted the tree.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
clang_format=${CLANG_FORMAT:-clang-format}
command -v "$clang_format" >/dev/null || {
  echo "format: '$clang_format' not found (apt-get install clang-format, or set CLANG_FORMAT)" >&2
  exit 2
}

check=0
if [[ ${1:-} == --check ]]; then check=1; shift; fi
case ${1:-} in -*) echo "usage: tools/format.sh [--check] [FILE...]" >&2; exit 2 ;; esac

if (($# > 0)); then
  files=("$@")
else
  # Tracked files only, so build folders and generated files are never touched.
  mapfile -t files < <(git ls-files -- 'src/*.cpp' 'src/*.h' 'tests/*.cpp' 'tests/*.h' 'tools/*.cpp' 'shaders/shared/*.h')
fi

if ((!check)); then
  "$clang_format" -i --style=file "${files[@]}"
  exit 0
fi

unformatted=0
for file in "${files[@]}"; do
  if ! "$clang_format" --style=file "$file" | cmp -s - "$file"; then
    changed=$("$clang_format" --style=file "$file" | diff "$file" - | grep -c '^<' || true)
    echo "format: $file: $changed lines would change"
    unformatted=$((unformatted + 1))
  fi
done
if ((unformatted > 0)); then
  echo "format: $unformatted of ${#files[@]} files are not formatted (run tools/format.sh)"
  exit 1
fi
echo "format: all ${#files[@]} files are formatted"
