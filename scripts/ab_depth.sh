#!/bin/bash
# The depth stage of this working tree against another revision's, one compute of each by turns
# in one process (tests/bench/depth/ab/ab_main.cc): teddy and a synthetic handheld burst (plane
# sweep and rectified shifts), each side's median time, the median of the per-turn ratios and
# whether the maps are the same.
#   scripts/ab_depth.sh REV [TURNS [SCENE]]   e.g. scripts/ab_depth.sh HEAD~1 150 handheld
# Builds REV's algo/ in build/ab-ref (its symbols renamed by -Dlb=lbref) and ab_depth in
# build/ab (Release). Run it on a quiet host; it asks for a real-time priority when allowed.
set -euo pipefail
rev=${1:?usage: scripts/ab_depth.sh REV [TURNS [SCENE]]}
turns=${2:-100}
scene=${3:-}
root=$(git rev-parse --show-toplevel)
cd "$root"
ref=$root/build/ab-ref
rm -rf "$ref"
mkdir -p "$ref/src"
git archive "$rev" | tar -x -m -C "$ref/src"
cmake -S "$ref/src" -B "$ref/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS=-Dlb=lbref \
  -DLB_TESTS=OFF -DLB_BENCHMARKS=OFF >/dev/null
cmake --build "$ref/build" --target lb_algo lb_core >/dev/null
cmake -S . -B build/ab -G Ninja -DCMAKE_BUILD_TYPE=Release -DLB_AB_REF="$ref/src" \
  -DLB_AB_REF_LIBS="$ref/build/algo/liblb_algo.a;$ref/build/algo/liblb_core.a" >/dev/null
cmake --build build/ab --target ab_depth >/dev/null
echo "current: the working tree; reference: $rev ($(git rev-parse --short "$rev"))"
if chrt -f 10 true 2>/dev/null; then
  exec chrt -f 10 build/ab/tests/bench/depth/ab_depth "$turns" $scene
fi
exec build/ab/tests/bench/depth/ab_depth "$turns" $scene
