#!/usr/bin/env bash
# The layering check on a small tree with one crossing of each kind (it must name all five and
# fail), on the same tree without them (it must pass), then on this repository (it must pass).
#   tests/layering/check_layers_test.sh ROOT
set -u
root=${1:?usage: check_layers_test.sh ROOT}
check=$(dirname "$0")/check_layers.sh
tree=$(mktemp -d)
trap 'rm -rf "$tree"' EXIT
fail() {
  echo "check_layers_test: $1"
  exit 1
}

mkdir -p "$tree"/{algo/core,algo/pipeline,hal,sim,firmware,tests}
echo 'add_library(lb_core STATIC)
add_library(lb_algo STATIC)
target_link_libraries(lb_algo PUBLIC lb_core)' >"$tree/algo/CMakeLists.txt"
echo 'add_library(lb_hal STATIC)
target_link_libraries(lb_hal PUBLIC
  lb_core)' >"$tree/hal/CMakeLists.txt"
echo 'add_library(lb_app STATIC)
target_link_libraries(lb_app PUBLIC lb_hal lb_algo)' >"$tree/firmware/CMakeLists.txt"
echo 'add_library(lb_test_images STATIC)' >"$tree/tests/CMakeLists.txt"
echo '#include "algo/core/status.h"' >"$tree/algo/core/status.cc"
echo '#include "algo/core/status.h"
#include <linux/videodev2.h>' >"$tree/hal/v4l2.cc"
echo '#include "hal/sensor.h"
#include "algo/pipeline/pipeline.h"' >"$tree/sim/sensor.cc"
echo '#include "sim/sensor.h"' >"$tree/firmware/job.cc"
out=$(bash "$check" "$tree") || fail "a tree without crossings fails: $out"

echo '#include "firmware/job.h"' >>"$tree/algo/core/status.cc"
echo '#include "algo/pipeline/pipeline.h"' >>"$tree/hal/v4l2.cc"
echo '#include "tests/sim/files/test_images.h"' >>"$tree/firmware/job.cc"
sed -i 's/  lb_core)/  lb_core lb_algo)/' "$tree/hal/CMakeLists.txt"
echo 'target_link_libraries(lb_app PRIVATE lb_test_images)' >>"$tree/firmware/CMakeLists.txt"
if out=$(bash "$check" "$tree"); then fail "five crossings pass"; fi
for what in 'algo/core/status.cc:2 includes "firmware/job.h"' \
  'hal/v4l2.cc:3 includes "algo/pipeline/pipeline.h"' \
  'firmware/job.cc:2 includes "tests/sim/files/test_images.h"' \
  'hal/CMakeLists.txt: lb_hal links lb_algo' 'firmware/CMakeLists.txt: lb_app links lb_test_images'; do
  grep -qF "$what" <<<"$out" || fail "not reported: $what (got: $out)"
done
[ "$(grep -c '^layering:' <<<"$out")" -eq 5 ] || fail "not five lines: $out"

bash "$check" "$root" || fail "this repository crosses its layers (above)"
echo "check_layers_test: ok"
