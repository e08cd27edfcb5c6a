#!/usr/bin/env bash
# Checks tools/check-repository-paths.sh on a throw-away repository: it must
# report a machine path, a relative path that climbs out of the tree and a
# root variable joined with "..", each by file and line, accept paths that stay
# inside and allow-listed examples, and pass once the leaks are gone.
#   tests/tools/repository_paths_test.sh REPO_ROOT
set -euo pipefail
source_root=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
repo=$work/clone
mkdir -p "$repo/tools" "$repo/scenes/sub" "$repo/assets"
cp "$source_root/tools/check-repository-paths.sh" "$repo/tools/"
fail() { echo "FAIL: $*" >&2; exit 1; }

# The parent-folder segments are assembled here, so that this test file itself
# names no path that climbs out of the tree.
up=..
cat >"$repo/scenes/sub/leaky.toml" <<TOML
inside = "$up/$up/assets/mesh.ply"
outside = "$up/$up/$up/shared/assets/mesh.ply"
TOML
printf 'see /home/someone/vkrt/scenes for the scene\n' >"$repo/notes.md"
printf 'assets=${root}/%s/shared/assets\n' "$up" >"$repo/tools/bench.sh"
printf 'cache in /var/tmp/example by default\n' >"$repo/example.md"
printf 'example.md\t/var/tmp/example\ntools/check-repository-paths.sh\t*\n' >"$repo/tools/repository-paths-allowed.txt"
printf 'mesh\n' >"$repo/assets/mesh.ply"
git -C "$repo" init -q
git -C "$repo" add -A

status=0
output=$("$repo/tools/check-repository-paths.sh" "$repo" 2>&1) || status=$?
echo "$output"
((status == 1)) || fail "expected exit 1 with three leaks, got $status"
grep -q '^scenes/sub/leaky.toml:2: ' <<<"$output" || fail "the climbing path (leaky.toml:2) was not reported"
grep -q '^notes.md:1: absolute path' <<<"$output" || fail "the machine path (notes.md:1) was not reported"
grep -q '^tools/bench.sh:1: the repository root' <<<"$output" || fail "\${root}/.. (bench.sh:1) was not reported"
! grep -q 'leaky.toml:1:' <<<"$output" || fail "a path inside the repository was reported"
! grep -q '^example.md' <<<"$output" || fail "an allow-listed example was reported"
[[ $(grep -c '^[^ ]*:[0-9]*: ' <<<"$output") -eq 3 ]] || fail "expected exactly three hits"

# The checkout's own parent folder is a machine path whatever its name.
printf 'built in %s/elsewhere\n' "$work" >"$repo/notes.md"
git -C "$repo" add -A
status=0
output=$("$repo/tools/check-repository-paths.sh" "$repo" 2>&1) || status=$?
grep -q '^notes.md:1: ' <<<"$output" || fail "the folder holding the checkout ($work) was not reported"
# ... but only as an absolute path: inside a longer path it names nothing of this machine
# (a clone in /root, and a script's "$dir/root/usr").
printf 'library=$dir%s/usr\n' "$work" >"$repo/unpack.sh"
git -C "$repo" add -A
output=$("$repo/tools/check-repository-paths.sh" "$repo" 2>&1) || true
! grep -q '^unpack.sh' <<<"$output" || fail "a path that only contains the checkout's folder was reported: $output"
rm "$repo/unpack.sh"

printf 'no paths here\n' >"$repo/notes.md"
printf 'assets=$root/assets\n' >"$repo/tools/bench.sh"
sed -i '2d' "$repo/scenes/sub/leaky.toml"
git -C "$repo" add -A
"$repo/tools/check-repository-paths.sh" "$repo" || fail "a clean repository was refused"
echo "repository_paths_test: passed"
