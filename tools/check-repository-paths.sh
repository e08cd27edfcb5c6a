#!/usr/bin/env bash
# Fails if a tracked file refers to a location outside the repository: a user's
# clone has nothing beside it, and another machine has none of this one's paths.
#
#   tools/check-repository-paths.sh [REPO]   (default: the repository holding this script)
#
# It reads every tracked text file (git ls-files) and reports, as FILE:LINE:
#   1. absolute paths of a particular machine: those under the root folders
#      work, home, root, tmp, var/tmp, mnt, media, Users, srv, scratch and opt
#      (the list below), and the folder that holds this checkout (whatever it
#      is called);
#   2. relative paths that climb out of the tree: every run of ../ segments,
#      resolved from the file's own folder, must stay inside the repository;
#   3. a repository-root variable (PROJECT_SOURCE_DIR, CMAKE_SOURCE_DIR,
#      VKRT_TEST_SOURCE_DIR, $root) joined with "..".
# Deliberate examples (a default chroot location, a documented install
# prefix) are listed in tools/repository-paths-allowed.txt as
# "FILE<TAB>TEXT": a hit in FILE whose line contains TEXT is not reported
# (TEXT "*": no hit in FILE is, for files that name such paths on purpose).
# Exit status: 0 clean, 1 hits were found, 2 usage, 77 not a git checkout.
set -euo pipefail

script_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=${1:-$script_dir/..}
repo=$(cd "$repo" && pwd -P)
[[ -d $repo ]] || { echo "check-repository-paths: $repo is not a folder" >&2; exit 2; }
top=$(git -C "$repo" rev-parse --show-toplevel 2>/dev/null) || {
  echo "check-repository-paths: $repo is not a git checkout (nothing to read the tracked files from)" >&2
  exit 77
}
top=$(cd "$top" && pwd -P)
allowed_file=$top/tools/repository-paths-allowed.txt
parent=$(dirname "$top")
parent_pattern=$(printf '%s' "$parent" | sed 's/[][\.*^$+?(){}|/]/\\&/g')

declare -A allowed=()
if [[ -f $allowed_file ]]; then
  while IFS=$'\t' read -r file text; do
    [[ -z $file || $file == \#* ]] && continue
    allowed[$file]+="$text"$'\n'
  done <"$allowed_file"
fi

# A hit is reported unless its file's allow-list names text on its line.
hits=0
report() { # FILE LINE CONTENT WHY
  local file=$1 line=$2 content=$3 why=$4 text
  if [[ -n ${allowed[$file]:-} ]]; then
    while IFS= read -r text; do
      [[ $text == '*' || (-n $text && $content == *"$text"*) ]] && return 0
    done <<<"${allowed[$file]}"
  fi
  printf '%s:%s: %s: %s\n' "$file" "$line" "$why" "$(printf '%s' "$content" | cut -c1-160)"
  hits=$((hits + 1))
}

cd "$top"
mapfile -d '' files < <(git ls-files -z)
machine='(^|[^A-Za-z0-9_.~$"-])/(work|home|root|tmp|var/tmp|mnt|media|Users|srv|scratch|opt)/'
root_vars='(PROJECT_SOURCE_DIR|CMAKE_SOURCE_DIR|VKRT_TEST_SOURCE_DIR|\$\{?root\}?)'

for file in "${files[@]}"; do
  [[ -f $file && ! -L $file ]] || continue
  grep -Iq . "$file" 2>/dev/null || continue # binary or empty
  [[ $file == tools/repository-paths-allowed.txt ]] && continue
  dir=$(dirname "$file")
  while IFS= read -r hit; do
    line=${hit%%:*}
    report "$file" "$line" "${hit#*:}" "absolute path of a machine"
  done < <(grep -nE "$machine" "$file" || true)
  if [[ $parent != / ]]; then
    # As an absolute path only: "$dir/root/usr" is no mention of a /root parent.
    while IFS= read -r hit; do
      report "$file" "${hit%%:*}" "${hit#*:}" "the folder that holds this checkout"
    done < <(grep -nE "(^|[^A-Za-z0-9_.~\$\"/-])$parent_pattern/" "$file" || true)
  fi
  while IFS= read -r hit; do
    line=${hit%%:*}
    climb=${hit#*:}
    resolved=$(realpath -m "$top/$dir/$climb")
    [[ $resolved == "$top" || $resolved == "$top"/* ]] && continue
    report "$file" "$line" "$(sed -n "${line}p" "$file")" "'$climb' climbs out of the repository"
  done < <(grep -noE '(\.\./)+[A-Za-z0-9_.*-]*' "$file" || true)
  while IFS= read -r hit; do
    report "$file" "${hit%%:*}" "${hit#*:}" "the repository root joined with '..'"
  done < <(grep -nE "$root_vars"'.*("\.\."|/\.\.([/"]|$))' "$file" || true)
done

if ((hits > 0)); then
  echo "check-repository-paths: $hits reference(s) to locations outside the repository (a clone has nothing beside" \
    "it); copy what is needed into the repository, or list a deliberate example in tools/repository-paths-allowed.txt" >&2
  exit 1
fi
echo "check-repository-paths: ${#files[@]} tracked files refer only to the repository"
