#!/usr/bin/env bash
# The structure check on a small tree: within the limits it must pass (a file of 600 lines, a
# class over two .cc files, calls and declarations that only look like definitions); with one
# file too long and one class over three files it must fail and name both, and nothing else.
# Given ROOT, a copy of its sources gets a new file too long and a new class over three files,
# and the check must name both and nothing else new, whatever ROOT holds today. ROOT itself is
# checked by the ctest structure_tree (check_structure.sh ROOT).
#   tests/layering/check_structure_test.sh [ROOT]
set -u
root=${1:-}
check=$(dirname "$0")/check_structure.sh
tree=$(mktemp -d)
copy=$(mktemp -d)
trap 'rm -rf "$tree" "$copy"' EXIT
fail() {
  echo "check_structure_test: $1"
  exit 1
}
mkdir -p "$tree"/{algo/depth,firmware/cli,hal,sim}

# 600 lines, the most a file may have.
for i in $(seq 600); do echo "// $i"; done >"$tree/algo/depth/grid_maxflow.cc"
# Stage's members in two files; the others only call them or name them.
printf '%s\n' '#include "algo/depth/stage.h"' 'namespace lb {' \
  'Status Stage::Configure(const Config& c, Arena& arena) {' '  return Stage::Check(c);' '}' \
  'Stage::Stage() = default;' '}  // namespace lb' >"$tree/algo/depth/stage.cc"
printf '%s\n' 'namespace lb {' 'LB_CLONES_AVX2 void Stage::Expand(int32_t label,' \
  '                                 Arena& arena) {}' 'Stage::Rect::Rect(int32_t x) : x_(x) {}' \
  '}  // namespace lb' >"$tree/algo/depth/expansion.cc"
printf '%s\n' 'int32_t MaxWeight() { return Stage::MaxSmoothWeight(7); }' \
  'const size_t kBytes = Stage::RequiredBytes(Config{});' \
  'static_assert(Stage::kMaxLabels > 0, "labels");' '  Stage::Expand(1, arena);' \
  'void Free(int32_t x);' >"$tree/firmware/cli/depth_command.cc"
printf '%s\n' 'Status Stage::Rect::Split(int32_t x) { return Stage::Check(x); }' >"$tree/hal/rect.cc"
printf '%s\n' '#pragma once' 'class Stage {' ' public:' '  Status Configure();' '};' \
  >"$tree/sim/stage.h"
out=$(bash "$check" "$tree") || fail "a tree within the limits fails: $out"

# One line more, and a third file defining Stage's members.
echo '// 601' >>"$tree/algo/depth/grid_maxflow.cc"
printf '%s\n' 'namespace lb {' 'int32_t Stage::MoveRects(int32_t label) const {' \
  '  return 0;' '}' '}  // namespace lb' >"$tree/sim/coarse.cc"
if out=$(bash "$check" "$tree"); then fail "two violations pass"; fi
for what in 'structure: algo/depth/grid_maxflow.cc has 601 lines (at most 600)' \
  'structure: class Stage has member functions defined in 3 .cc files (at most 2): algo/depth/expansion.cc algo/depth/stage.cc sim/coarse.cc'; do
  grep -qF "$what" <<<"$out" || fail "not reported: $what (got: $out)"
done
[ "$(grep -c '^structure:' <<<"$out")" -eq 2 ] || fail "not two lines: $out"
[ -n "$root" ] || {
  echo "check_structure_test: ok"
  exit 0
}

cp -r "$root"/{algo,firmware,hal,sim} "$copy"/
before=$(bash "$check" "$copy")
for i in $(seq 601); do echo "// $i"; done >"$copy/firmware/app/long_injected.cc"
n=0
for f in algo/depth/knot_a.cc firmware/app/knot_b.cc sim/knot_c.cc; do
  printf '%s\n' 'namespace lb {' "void InjectedKnot::Part$((++n))() {}" '}  // namespace lb' >"$copy/$f"
done
after=$(bash "$check" "$copy") && fail "two violations pass in a copy of $root"
expected='structure: class InjectedKnot has member functions defined in 3 .cc files (at most 2): algo/depth/knot_a.cc firmware/app/knot_b.cc sim/knot_c.cc
structure: firmware/app/long_injected.cc has 601 lines (at most 600)'
new=$(comm -13 <(sort <<<"$before") <(sort <<<"$after"))
[ "$new" = "$expected" ] || fail "in a copy of $root, reported: $new (expected: $expected)"
echo "check_structure_test: ok (in a small tree and in a copy of $root)"
