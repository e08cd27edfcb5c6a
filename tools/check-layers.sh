#!/usr/bin/env bash
# Fails if a source file of src/ includes a layer its row of the layers table
# (docs/architecture.md, "## Layers") does not allow, or if the table and the
# folders of src/ disagree (a folder without a row, a row without a folder).
#
#   tools/check-layers.sh [REPO]   (default: the repository holding this script)
#
# A row is "| `src/NAME` | what | `a`, `b`, ... |": the third column lists, in
# backticks, the layers NAME may include ("shared" is shaders/shared/, the
# headers C++ and GLSL share); the word "everything" allows every layer. A
# layer may always include itself. Only includes in quotes whose first path
# segment is a layer ("render/Renderer.h") are checked: system headers and
# the layer's own relative includes are not layers.
# Prints each violation as FILE:LINE: and exits 1 if there is one; 2 on a
# table that cannot be read.
set -euo pipefail

script_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "${1:-$script_dir/..}" && pwd -P)
doc=$repo/docs/architecture.md
[[ -f $doc ]] || { echo "check-layers: $doc not found" >&2; exit 2; }

# The table: the lines after "## Layers" up to the next heading.
declare -A allowed=()
while IFS= read -r line; do
  [[ $line =~ ^\|\ \`src/([a-z]+)\`\ \|[^|]*\|(.*)\|$ ]] || continue
  layer=${BASH_REMATCH[1]}
  column=${BASH_REMATCH[2]}
  if [[ $column == *everything* ]]; then
    allowed[$layer]='*'
    continue
  fi
  list=' '
  while [[ $column =~ \`([a-z]+)\`(.*) ]]; do
    list+="${BASH_REMATCH[1]} "
    column=${BASH_REMATCH[2]}
  done
  allowed[$layer]=$list
done < <(sed -n '/^## Layers$/,/^## /p' "$doc")
((${#allowed[@]} > 0)) || { echo "check-layers: $doc: no layers table under \"## Layers\"" >&2; exit 2; }

status=0
layers=' shared '
for dir in "$repo"/src/*/; do
  layer=$(basename "$dir")
  layers+="$layer "
  [[ -n ${allowed[$layer]:-} ]] || {
    echo "docs/architecture.md: the layers table has no row for src/$layer"
    status=1
  }
done
for layer in "${!allowed[@]}"; do
  [[ -d $repo/src/$layer ]] || {
    echo "docs/architecture.md: the layers table has a row for src/$layer, which does not exist"
    status=1
  }
done

while IFS=: read -r file number text; do
  [[ $text =~ ^[[:space:]]*#[[:space:]]*include[[:space:]]+\"([a-z]+)/ ]] || continue
  target=${BASH_REMATCH[1]}
  layer=${file#src/}
  layer=${layer%%/*}
  [[ $layers == *" $target "* && $target != "$layer" ]] || continue
  rule=${allowed[$layer]:-}
  [[ $rule == '*' || $rule == *" $target "* ]] && continue
  echo "$file:$number: src/$layer includes $target/, which its row of the layers table (docs/architecture.md) does not allow"
  status=1
done < <(cd "$repo" && grep -rnE '^[[:space:]]*#[[:space:]]*include[[:space:]]+"' src --include='*.h' --include='*.cpp' | sort)
exit "$status"
