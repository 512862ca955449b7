#!/bin/bash
# Google Benchmark programs of this working tree against another revision's, run by turns in one
# command so that both sides see the same machine: per benchmark, each side's median time over the
# turns and the median of the per-turn ratios (current / reference; below 1: faster).
#   scripts/ab_bench.sh REV [TURNS [BENCH...]]   e.g. scripts/ab_bench.sh HEAD~3 5 render_bench job_bench
# Builds REV in build/abb-ref and this tree in build/abb (Release, benchmarks on). Run it on a
# quiet host.
set -euo pipefail
rev=${1:?usage: scripts/ab_bench.sh REV [TURNS [BENCH...]]}
turns=${2:-5}
shift $(($# < 2 ? $# : 2))
benches=("$@")
[ ${#benches[@]} -gt 0 ] || benches=(render_bench job_bench)
root=$(git rev-parse --show-toplevel)
cd "$root"
ref=$root/build/abb-ref
rm -rf "$ref/src"
mkdir -p "$ref/src"
git archive "$rev" | tar -x -m -C "$ref/src"
for side in "$ref/src:$ref/build" ".:build/abb"; do
  src=${side%%:*} bin=${side#*:}
  cmake -S "$src" -B "$bin" -G Ninja -DCMAKE_BUILD_TYPE=Release -DLB_TESTS=ON -DLB_BENCHMARKS=ON \
    >/dev/null
  cmake --build "$bin" --target "${benches[@]}" >/dev/null
done
find_bench() { find "$1" -name "$2" -type f -perm -u+x | head -n1; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "current: the working tree; reference: $rev ($(git rev-parse --short "$rev")); $turns turns"
for ((t = 0; t < turns; t++)); do
  for b in "${benches[@]}"; do
    for side in ref cur; do
      dir=$ref/build
      [ $side = cur ] && dir=build/abb
      "$(find_bench "$dir" "$b")" --benchmark_format=json >"$out/$b.$side.$t.json" 2>/dev/null
    done
  done
done
python3 - "$out" "$turns" "${benches[@]}" <<'EOF'
import json, statistics, sys
out, turns, benches = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
for b in benches:
    times = {}
    for t in range(turns):
        for side in ("ref", "cur"):
            for r in json.load(open(f"{out}/{b}.{side}.{t}.json"))["benchmarks"]:
                times.setdefault(r["name"], {"ref": [], "cur": []})[side].append(r["real_time"])
    for name, s in times.items():
        ratios = [c / r for c, r in zip(s["cur"], s["ref"])]
        print(f"{name}: reference {statistics.median(s['ref']):.1f} ms, current "
              f"{statistics.median(s['cur']):.1f} ms, ratio {statistics.median(ratios):.3f}")
EOF
