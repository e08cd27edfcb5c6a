#!/usr/bin/env bash
# Runs tools/check-layers.sh on the repository (its includes must follow the
# layers table of docs/architecture.md), then on a throw-away tree with the
# same table, where it must report an include the table forbids (by file and
# line), a folder of src/ without a row and a row without a folder, and accept
# allowed includes, a layer's own headers and system headers.
#   tests/tools/layers_test.sh REPO_ROOT
set -euo pipefail
source_root=$1
fail() { echo "FAIL: $*" >&2; exit 1; }

"$source_root/tools/check-layers.sh" "$source_root" || fail "the repository's includes break the layers table (above)"

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/tools" "$work/docs"
cp "$source_root/tools/check-layers.sh" "$work/tools/"
cp "$source_root/docs/architecture.md" "$work/docs/"
# One file per row, including its own layer and a system header.
rows=$(sed -n '/^## Layers$/,/^## /p' "$work/docs/architecture.md" | grep -oE '^\| `src/[a-z]+`' | sed -E 's/.*src\/([a-z]+)`/\1/')
[[ $(wc -w <<<"$rows") -ge 10 ]] || fail "expected the table's rows, got: $rows"
for layer in $rows; do
  mkdir -p "$work/src/$layer"
  printf '#include "%s/Other.h"\n#include <vector>\n' "$layer" >"$work/src/$layer/Good.cpp"
done
# A few includes the table allows, across layers.
printf '#include "io/Image.h"\n#include "shared/Kinds.h"\n' >"$work/src/scene/Scene.cpp"
printf '#include "scene/Scene.h"\n#include "util/Error.h"\n' >"$work/src/render/Renderer.cpp"
printf '#include "render/Outcome.h"\n#include "view/Viewer.h"\n' >"$work/src/app/main.cpp"
"$work/tools/check-layers.sh" "$work" || fail "allowed includes were reported"

printf '// the limits\n#include "scene/Scene.h"\n' >"$work/src/io/Header.cpp"
mkdir -p "$work/src/newlayer"
rmdir "$work/src/material" 2>/dev/null || rm -r "$work/src/material"
status=0
output=$("$work/tools/check-layers.sh" "$work" 2>&1) || status=$?
echo "$output"
((status == 1)) || fail "expected exit 1, got $status"
grep -q '^src/io/Header.cpp:2: src/io includes scene/' <<<"$output" || fail "io including scene/ was not reported"
grep -q 'no row for src/newlayer' <<<"$output" || fail "a folder without a row was not reported"
grep -q 'row for src/material, which does not exist' <<<"$output" || fail "a row without a folder was not reported"
[[ $(wc -l <<<"$output") -eq 3 ]] || fail "expected exactly three reports"
echo "layers: the repository follows the table, and the checker reports what breaks it"
