#!/usr/bin/env bash
# Every check CI runs: set-up, format, host tests under ASan+UBSan, the Middlebury accuracy tests
# in Release, short fuzz runs, clang-tidy on algo/, the ARM builds with their unit tests under
# qemu-user, the board packages for Debian 12 and 13, and the libcamera backend against the
# newest libcamera. Ends with one line "tests: N passed, M failed".
set -uo pipefail
cd "$(dirname "$0")/.."
top=$(pwd)
jobs=${JOBS:-$(nproc)}
passed=0
failed=0
skipped=0
failures=()
log=$(mktemp -d)

step() { printf '\n=== %s\n' "$*"; }
die() { echo "test: $*" >&2; echo "tests: $passed passed, $((failed + 1)) failed, $skipped skipped"; exit 1; }
# Runs ctest and adds its counts to the totals.
run_ctest() {
  local name=$1; shift
  ctest "$@" --output-on-failure -j "$jobs" 2>&1 | tee "$log/$name.log" | grep -vE '^\s+(Start|[0-9]+/[0-9]+ Test)' || true
  local line
  line=$(grep -E 'tests passed, [0-9]+ tests failed out of [0-9]+' "$log/$name.log" | tail -1)
  if [ -z "$line" ]; then
    grep -q 'No tests were found' "$log/$name.log" && return 0
    failed=$((failed + 1)); echo "test: $name: ctest gave no summary"; return 0
  fi
  local total fails skips
  total=$(sed -E 's/.*out of ([0-9]+).*/\1/' <<<"$line")
  fails=$(sed -E 's/.*passed, ([0-9]+) tests failed.*/\1/' <<<"$line")
  # ctest counts a skipped test (GTEST_SKIP, exit 77) as not failed: report it apart.
  skips=$(grep -cE '\(Skipped\)$' "$log/$name.log" || true)
  passed=$((passed + total - fails - skips)); failed=$((failed + fails)); skipped=$((skipped + skips))
  # CI shows only the tail of this output: the names of what failed are repeated at the end.
  local t
  while read -r t; do failures+=("$name: $t"); done < <(
    sed -n '/^The following tests FAILED:/,/^$/{s/^[[:space:]]*[0-9]* - //p}' "$log/$name.log")
}

step "set-up"
bash scripts/setup.sh || die "set-up failed"
bash scripts/cross-sysroot.sh arm64 || die "arm64 sysroot failed"
bash scripts/cross-sysroot.sh armhf || die "armhf sysroot failed"
# The Debian roots of the last steps download while the first ones compile.
prefetch=$log/prefetch.log
{ bash scripts/package.sh --root-only bookworm arm64 && bash scripts/package.sh --root-only trixie arm64 &&
  bash scripts/libcamera-compat.sh --root-only trixie-backports; } >"$prefetch" 2>&1 &
prefetch_pid=$!

step "format (clang-format)"
mapfile -t sources < <(git ls-files '*.h' '*.cc')
if ! clang-format --dry-run --Werror "${sources[@]}" 2>"$log/format.txt"; then
  head -20 "$log/format.txt"; die "files are not clang-formatted (run: clang-format -i FILE)"
fi

step "host-asan: build and all tests but data and vm (AddressSanitizer + UBSan)"
cmake --preset host-asan >/dev/null || die "configure host-asan"
cmake --build --preset host-asan -j "$jobs" || die "build host-asan"
run_ctest host-asan --preset host-asan -LE 'data|vm|accuracy'

step "host (Release): Middlebury and motion accuracy, the refocusd and web soaks, the page in Chromium"
cmake --preset host >/dev/null || die "configure host"
cmake --build --preset host -j "$jobs" || die "build host"
run_ctest host-data --preset host -L 'data|soak|accuracy|browser'

if [ -d tests/vm ]; then
  step "kernel drivers in a VM (vivid, uinput, vimc)"
  run_ctest host-vm --preset host -L vm
fi

step "fuzz: short runs of every file-reader fuzzer (clang-14, ASan + UBSan)"
cmake --preset fuzz >/dev/null || die "configure fuzz"
cmake --build --preset fuzz -j "$jobs" || die "build fuzz"
if [ -x tests/fuzz/run_fuzzers.sh ]; then
  if bash tests/fuzz/run_fuzzers.sh "${FUZZ_SECONDS:-20}" build/fuzz; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1)); echo "test: a fuzzer found a crash"
  fi
fi

step "clang-tidy on algo/"
if ! clang-tidy -p build/host-asan --quiet $(git ls-files 'algo/*.cc') >"$log/tidy.txt" 2>&1; then
  grep -E 'warning:|error:' "$log/tidy.txt" | head -30; die "clang-tidy found problems in algo/"
fi

for arch in aarch64 armhf; do
  step "$arch: cross build (-Werror) and unit tests under qemu-user"
  cmake --preset "$arch" >/dev/null || die "configure $arch"
  cmake --build --preset "$arch" -j "$jobs" || die "build $arch"
  run_ctest "$arch" --preset "$arch"
done

wait "$prefetch_pid" || { cat "$prefetch"; die "making the Debian roots failed"; }
for suite in bookworm trixie; do
  step "$suite arm64: the board's package built in the release's root, and checked"
  if deb=$(bash scripts/package.sh "$suite" arm64 | tee "$log/package-$suite.log" | tail -n1) &&
     bash tests/firmware/daemon/check_deb.sh "$deb" "build/roots/$suite-cross-arm64"; then
    passed=$((passed + 1))
  else
    # The build's own output (a compiler's error) went to the log, not the screen.
    grep -E -A8 'FAILED|error' "$log/package-$suite.log" | head -n 40
    failed=$((failed + 1)); echo "test: the $suite arm64 package failed"
  fi
done

step "libcamera 0.7.1 (trixie-backports): the backend built with -Werror, its unit tests"
bash scripts/libcamera-compat.sh trixie-backports 2>&1 | tee "$log/compat.log" | tail -n 30
if ! grep -q '^libcamera-compat: 1 passed, 0 failed$' "$log/compat.log"; then
  failed=$((failed + 1)); echo "test: the libcamera backend failed against libcamera 0.7.1"
else
  passed=$((passed + $(sed -n 's/^\[  PASSED  \] \([0-9]*\) tests\?\..*/\1/p' "$log/compat.log" | tail -n1)))
fi

echo
for f in "${failures[@]}"; do echo "failed: $f"; done
echo "tests: $passed passed, $failed failed, $skipped skipped"
[ "$failed" -eq 0 ]
