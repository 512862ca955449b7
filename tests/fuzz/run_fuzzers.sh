#!/usr/bin/env bash
# Runs every libFuzzer target of a fuzz build for SECONDS each, one after the other, starting
# from the generated seeds and the corpus committed in tests/fuzz/corpus/<reader>/.
#   tests/fuzz/run_fuzzers.sh [--merge-into DIR] [--only NAME] SECONDS [BUILD_DIR]
#     BUILD_DIR: default build/fuzz. Configures (preset `fuzz`) and builds `fuzzers` if needed.
#     --merge-into DIR: after each run, minimise the working corpus into DIR/<reader>/
#       (libFuzzer -merge=1: only inputs that add coverage to what DIR/<reader>/ already has are
#       copied; nothing is removed).
#     --only NAME: run one fuzzer (fuzz_jpeg, ...).
# CI (scripts/test.sh, ctest -L fuzz) runs `run_fuzzers.sh 20 build/fuzz`. The long runs that
# grow the committed corpus are the `fuzz-long` target (600 s each, LB_FUZZ_LONG_SECONDS, then
# --merge-into tests/fuzz/corpus), by hand:
#   cmake --preset fuzz && cmake --build --preset fuzz --target fuzz-long
# or one reader: nice -n 10 bash tests/fuzz/run_fuzzers.sh --only fuzz_conf 600 build/fuzz
# To refresh the committed corpus from scratch, empty tests/fuzz/corpus/<reader>/ before merging.
#
# Prints one summary line per fuzzer; exits 1 if any fuzzer crashed, leaked, timed out, ran out of
# memory or hit undefined behaviour (UBSan halts on its first report here). Work files go to
# BUILD_DIR/fuzz-run: seeds/, corpus/<fuzzer>/ (kept between runs, so coverage accumulates; the
# committed corpus is only read, but by --merge-into), artifacts/ (the inputs that failed), logs/.
# tests/fuzz/<reader>.dict, when there is one, is passed as the fuzzer's -dict.
set -u

usage() {
  echo "usage: $0 [--merge-into DIR] [--only NAME] SECONDS [BUILD_DIR]" >&2
  exit 2
}
merge_into=
only=
while [ $# -gt 0 ]; do
  case $1 in
    --merge-into) [ $# -ge 2 ] || usage; merge_into=$(realpath -m "$2"); shift 2 ;;
    --only) [ $# -ge 2 ] || usage; only=$2; shift 2 ;;
    -*) usage ;;
    *) break ;;
  esac
done
[ $# -ge 1 ] && [ $# -le 2 ] || usage
seconds=$1
case $seconds in '' | *[!0-9]*) usage ;; esac

here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
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

# Undefined behaviour is a failure too (the fuzz build's UBSan would otherwise print and go on).
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}

failed=0
found=0
for bin in "$bin_dir"/fuzz_*; do
  [ -x "$bin" ] && [ -f "$bin" ] || continue
  name=$(basename "$bin")
  [ -z "$only" ] || [ "$name" = "$only" ] || continue
  found=$((found + 1))
  format=${name#fuzz_}
  # Read-only seeds: the generated ones and the committed corpus. A fuzzer without seeds of its
  # own starts from every generated seed.
  if [ -d "$work/seeds/$format" ]; then
    seeds=("$work/seeds/$format")
  else
    seeds=("$work/seeds"/*/)
  fi
  [ -d "$here/corpus/$format" ] && seeds+=("$here/corpus/$format")
  dict=()
  [ -f "$here/$format.dict" ] && dict=(-dict="$here/$format.dict")
  corpus=$work/corpus/$name
  log=$work/logs/$name.log
  mkdir -p "$corpus"
  "$bin" -max_total_time="$seconds" -timeout=30 -rss_limit_mb=2048 -print_final_stats=1 \
    "${dict[@]}" -artifact_prefix="$work/artifacts/$name-" "$corpus" "${seeds[@]}" >"$log" 2>&1
  rc=$?
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  took=$(sed -n 's/^Done [0-9]* runs in \([0-9]*\) second.*/\1/p' "$log" | tail -n 1)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -n 1 | cut -d' ' -f2)
  ft=$(grep -o 'ft: [0-9]*' "$log" | tail -n 1 | cut -d' ' -f2)
  rss=$(sed -n 's/^stat::peak_rss_mb: *//p' "$log" | tail -n 1)
  files=$(find "$corpus" -type f | wc -l)
  if [ "$rc" -ne 0 ]; then
    failed=$((failed + 1))
    artifact=$(sed -n 's/.*Test unit written to //p' "$log" | tail -n 1)
    what=$(grep -m 1 -E '^SUMMARY:|ERROR: libFuzzer|broken invariant' "$log")
    echo "$name: FAILED (exit $rc) after ${runs:-?} runs: ${what:-see log}; input ${artifact:-none}; log $log"
    continue
  fi
  line="$name: ok, ${runs:-?} runs in ${took:-$seconds} s, coverage ${cov:-?} edges, ${ft:-?} features, peak RSS ${rss:-?} MB, corpus $files files"
  if [ -n "$merge_into" ]; then
    dest=$merge_into/$format
    mkdir -p "$dest"
    if "$bin" -merge=1 -timeout=30 -rss_limit_mb=2048 "$dest" "$corpus" \
      >"$work/logs/$name-merge.log" 2>&1; then
      bytes=$(find "$dest" -type f -printf '%s\n' | awk '{s += $1} END {print s + 0}')
      line="$line; merged into $dest: $(find "$dest" -type f | wc -l) files, $bytes bytes"
    else
      failed=$((failed + 1))
      line="$line; merge FAILED (log $work/logs/$name-merge.log)"
    fi
  fi
  echo "$line"
done

if [ "$found" -eq 0 ]; then
  echo "fuzz: no ${only:-fuzz_*} binaries in $bin_dir" >&2
  exit 1
fi
[ "$failed" -eq 0 ]
