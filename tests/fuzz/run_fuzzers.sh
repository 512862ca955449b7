#!/usr/bin/env bash
# Runs every libFuzzer target of a fuzz build for SECONDS each, starting from generated seeds.
#   tests/fuzz/run_fuzzers.sh SECONDS [BUILD_DIR]     (BUILD_DIR: default build/fuzz)
# Configures (preset `fuzz`) and builds the `fuzzers` target if needed. Prints one summary line
# per fuzzer; exits 1 if any fuzzer crashed, leaked, timed out or ran out of memory.
# Work files go to BUILD_DIR/fuzz-run: seeds/, corpus/<fuzzer>/ (kept between runs, so coverage
# accumulates), artifacts/ (the inputs that failed) and logs/.
set -u

usage() { echo "usage: $0 SECONDS [BUILD_DIR]" >&2; exit 2; }
[ $# -ge 1 ] && [ $# -le 2 ] || usage
seconds=$1
case $seconds in '' | *[!0-9]*) usage ;; esac

root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(realpath -m "${2:-$root/build/fuzz}")

mkdir -p "$build"
build_log=$build/fuzz-build.log
if [ ! -f "$build/CMakeCache.txt" ]; then
  if ! (cd "$root" && cmake --preset fuzz -B "$build") >"$build_log" 2>&1; then
    tail -n 20 "$build_log" >&2; echo "fuzz: configure failed" >&2; exit 1
  fi
fi
if ! cmake --build "$build" --target fuzzers >"$build_log" 2>&1; then
  grep -m 10 -E 'error|FAILED' "$build_log" >&2; echo "fuzz: build failed (log $build_log)" >&2; exit 1
fi

bin_dir=$build/tests/fuzz
work=$build/fuzz-run
mkdir -p "$work/corpus" "$work/artifacts" "$work/logs"
rm -rf "$work/seeds"
"$bin_dir/make_fuzz_seeds" "$work/seeds" || { echo "fuzz: cannot write seeds" >&2; exit 1; }

failed=0
found=0
for bin in "$bin_dir"/fuzz_*; do
  [ -x "$bin" ] && [ -f "$bin" ] || continue
  found=$((found + 1))
  name=$(basename "$bin")
  format=${name#fuzz_}
  # A fuzzer without seeds of its own (fuzz_xmp reads JPEGs) starts from every seed.
  if [ -d "$work/seeds/$format" ]; then
    seeds=("$work/seeds/$format")
  else
    seeds=("$work/seeds"/*/)
  fi
  corpus=$work/corpus/$name
  log=$work/logs/$name.log
  mkdir -p "$corpus"
  "$bin" -max_total_time="$seconds" -timeout=30 -rss_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="$work/artifacts/$name-" "$corpus" "${seeds[@]}" >"$log" 2>&1
  rc=$?
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -n 1 | cut -d' ' -f2)
  ft=$(grep -o 'ft: [0-9]*' "$log" | tail -n 1 | cut -d' ' -f2)
  files=$(find "$corpus" -type f | wc -l)
  if [ "$rc" -eq 0 ]; then
    echo "$name: ok, ${runs:-?} runs in ${seconds} s, coverage ${cov:-?} edges, ${ft:-?} features, corpus $files files"
  else
    failed=$((failed + 1))
    artifact=$(sed -n 's/.*Test unit written to //p' "$log" | tail -n 1)
    what=$(grep -m 1 -E '^SUMMARY:|ERROR: libFuzzer|broken invariant' "$log")
    echo "$name: FAILED (exit $rc) after ${runs:-?} runs: ${what:-see log}; input ${artifact:-none}; log $log"
  fi
done

if [ "$found" -eq 0 ]; then
  echo "fuzz: no fuzz_* binaries in $bin_dir" >&2
  exit 1
fi
[ "$failed" -eq 0 ]
