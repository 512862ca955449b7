#!/usr/bin/env bash
# The layering check on a small tree laid out like this repository: without crossings it must
# pass; with one crossing of each rule it must fail and name every one of them, and nothing else.
# Given ROOT, the same crossings go into a copy of ROOT's sources too, as new files and appended
# lines, and the check must name each of them and nothing else new: the rules fit the real
# layout, whatever crossings ROOT has today. ROOT itself is checked by the ctest layers_tree.
#   tests/layering/check_layers_test.sh [ROOT]
set -u
root=${1:-}
check=$(dirname "$0")/check_layers.sh
tree=$(mktemp -d)
copy=$(mktemp -d)
trap 'rm -rf "$tree" "$copy"' EXIT
fail() {
  echo "check_layers_test: $1"
  exit 1
}
put() {  # put FILE LINE...: appends the lines to FILE, making its folder
  mkdir -p "$(dirname "$tree/$1")"
  local f=$1
  shift
  printf '%s\n' "$@" >>"$tree/$f"
}

# A tree without crossings, with each folder using what it may.
put algo/CMakeLists.txt 'add_library(lb_core STATIC)' 'add_library(lb_algo STATIC)' \
  'target_link_libraries(lb_algo PUBLIC lb_core)'
put algo/core/status.cc '#include "algo/core/status.h"'
put algo/motion/motion_stage.cc '#include "algo/motion/motion_stage.h"' '#include "algo/core/arena.h"'
put algo/depth/depth_stage.h '#include "algo/depth/depth_types.h"' \
  '#include "algo/motion/plane_homography.h"' '#include "algo/motion/camera.h"'
put algo/render/render_stage.cc '#include "algo/render/render_stage.h"' \
  '#include "algo/depth/depth_types.h"'
put algo/pipeline/pipeline.cc '#include "algo/motion/motion_stage.h"' \
  '#include "algo/depth/depth_stage.h"' '#include "algo/render/render_stage.h"'
put hal/CMakeLists.txt 'add_library(lb_hal STATIC)' 'target_link_libraries(lb_hal PUBLIC' '  lb_core)'
put hal/v4l2.cc '#include "algo/core/status.h"' '#include <linux/videodev2.h>'
put sim/CMakeLists.txt 'add_library(lb_sim STATIC)' 'target_link_libraries(lb_sim PUBLIC lb_hal lb_algo)'
put sim/sensor.cc '#include "hal/sensor.h"' '#include "algo/pipeline/pipeline.h"'
put firmware/CMakeLists.txt 'foreach(dir platform storage codecs app cli daemon web)' 'endforeach()'
put firmware/platform/CMakeLists.txt 'add_library(lb_platform STATIC)' \
  'target_link_libraries(lb_platform PUBLIC lb_core)'
put firmware/platform/log.cc '#include "firmware/platform/log.h"'
put firmware/storage/CMakeLists.txt 'add_library(lb_storage STATIC)' \
  'target_link_libraries(lb_storage PUBLIC lb_algo)'
put firmware/storage/atomic_file.cc '#include "algo/core/status.h"'
put firmware/codecs/CMakeLists.txt 'add_library(lb_codecs STATIC)' \
  'target_link_libraries(lb_codecs PUBLIC lb_storage lb_hal)'
put firmware/codecs/exif.cc '#include "firmware/storage/input_file.h"' '#include "hal/image_decoder.h"' \
  '#include "algo/motion/camera.h"'
put firmware/refocusable/CMakeLists.txt 'add_library(lb_refocusable STATIC)' \
  'target_link_libraries(lb_refocusable PUBLIC lb_algo lb_codecs)'
put firmware/refocusable/xmp_writer.cc '#include "firmware/codecs/jpeg_writer.h"'
put firmware/depth_out/CMakeLists.txt 'add_library(lb_depth_out STATIC)' \
  'target_link_libraries(lb_depth_out PRIVATE lb_codecs)'
put firmware/depth_out/depth_out.cc '#include "firmware/codecs/png_writer.h"'
put firmware/app/CMakeLists.txt 'add_library(lb_app STATIC)' \
  'target_link_libraries(lb_app PUBLIC lb_algo lb_hal lb_refocusable lb_codecs lb_platform)'
put firmware/app/job.cc '#include "algo/pipeline/pipeline.h"' '#include "algo/render/render_stage.h"' \
  '#include "algo/depth/depth_types.h"' '#include "firmware/refocusable/xmp_writer.h"' \
  '#include "firmware/platform/worker_pool.h"'
put firmware/cli/CMakeLists.txt 'add_executable(refocus main.cc)' \
  'target_link_libraries(refocus PRIVATE lb_app lb_sim lb_depth_out)'
put firmware/cli/depth_command.cc '#include "firmware/app/job.h"' '#include "firmware/depth_out/depth_out.h"' \
  '#include "sim/files/file_sensor.h"' '#include "algo/pipeline/pipeline.h"'
put firmware/web/CMakeLists.txt 'add_library(lb_web STATIC)' \
  'target_link_libraries(lb_web PUBLIC lb_app PRIVATE lb_codecs)'
put firmware/web/web_server.h '#include "firmware/app/refocus_engine.h"' \
  '#include "firmware/platform/log.h"'
put firmware/daemon/CMakeLists.txt 'add_library(lb_daemon STATIC)' \
  'target_link_libraries(lb_daemon PUBLIC lb_app)' 'add_executable(refocusd main.cc)' \
  'target_link_libraries(refocusd PRIVATE lb_daemon lb_web lb_sim)'
put firmware/daemon/main.cc '#include "firmware/web/web_server.h"' '#include "sim/synthetic/scene.h"'
put tests/CMakeLists.txt 'add_library(lb_test_images STATIC)'
out=$(bash "$check" "$tree") || fail "a tree without crossings fails: $out"

# One crossing of each rule: file:line or CMake file, and what it reaches.
inject() {  # inject FILE LINE: appends the line and expects FILE:N to be named with it
  put "$1" "$2"
  if [ "${1##*/}" = CMakeLists.txt ]; then
    expected+=("$1: $(sed -E 's/target_link_libraries\(([^ ]*) [A-Z]* ([^ )]*)\)/\1 links \2/' <<<"$2")")
  else
    expected+=("$1:$(wc -l <"$tree/$1") includes $(sed -n 's/#include //p' <<<"$2")")
  fi
}
# One crossing of each rule, into $tree.
inject_all() {
  expected=()
  # Between the top folders.
  inject algo/core/status.cc '#include "firmware/app/job.h"'
  inject hal/v4l2.cc '#include "algo/pipeline/pipeline.h"'
  inject firmware/app/job.cc '#include "tests/sim/files/test_images.h"'
  inject hal/CMakeLists.txt 'target_link_libraries(lb_hal PUBLIC lb_algo)'
  inject firmware/app/CMakeLists.txt 'target_link_libraries(lb_app PRIVATE lb_test_images)'
  # Inside algo: a stage using a later one, a stage composing another, the vocabulary linking the
  # stages.
  inject algo/motion/motion_stage.cc '#include "algo/depth/warp_cost.h"'
  inject algo/render/render_stage.cc '#include "algo/depth/depth_stage.h"'
  inject algo/CMakeLists.txt 'target_link_libraries(lb_core PUBLIC lb_algo)'
  # Inside firmware: against the order, web into daemon, between the programs, between storage
  # and platform, links.
  inject firmware/codecs/exif.cc '#include "firmware/app/settings.h"'
  inject firmware/web/web_server.h '#include "firmware/daemon/config.h"'
  inject firmware/cli/depth_command.cc '#include "firmware/web/thumbnail.h"'
  inject firmware/storage/atomic_file.cc '#include "firmware/platform/worker_pool.h"'
  inject firmware/web/CMakeLists.txt 'target_link_libraries(lb_web PUBLIC lb_daemon)'
  inject firmware/codecs/CMakeLists.txt 'target_link_libraries(lb_codecs PRIVATE lb_app)'
  # Firmware wiring stages instead of going through the pipeline.
  inject firmware/cli/depth_command.cc '#include "algo/depth/depth_stage.h"'
  inject firmware/app/job.cc '#include "algo/depth/depth_order.h"'
  # Shipped code using the simulator.
  inject firmware/codecs/exif.cc '#include "sim/files/image_decoder.h"'
  inject firmware/app/CMakeLists.txt 'target_link_libraries(lb_app PRIVATE lb_sim)'
  # A folder nobody placed.
  put firmware/extras/extra.cc '#include "firmware/app/job.h"'
  expected+=("firmware/extras/extra.cc: firmware/extras is not placed in the layers")
}
inject_all
if out=$(bash "$check" "$tree"); then fail "${#expected[@]} crossings pass"; fi
for what in "${expected[@]}"; do
  grep -qF "$what" <<<"$out" || fail "not reported: $what (got: $out)"
done
[ "$(grep -c '^layering:' <<<"$out")" -eq "${#expected[@]}" ] ||
  fail "not ${#expected[@]} lines: $out"

[ -n "$root" ] || {
  echo "check_layers_test: ok (${#expected[@]} crossings named)"
  exit 0
}

# The same on a copy of ROOT's sources, with its CMake files for the libraries' homes.
cp -r "$root"/{algo,hal,sim,firmware} "$copy"/
(cd "$root" && find tests -name CMakeLists.txt -exec cp --parents {} "$copy" \;)
before=$(bash "$check" "$copy")
tree=$copy
inject_all
after=$(bash "$check" "$copy") && fail "${#expected[@]} crossings pass in a copy of $root"
for what in "${expected[@]}"; do
  grep -qF "$what" <<<"$after" || fail "not reported in a copy of $root: $what (got: $after)"
done
while IFS= read -r line; do
  for what in "${expected[@]}"; do
    [[ $line == *"$what"* ]] && continue 2
  done
  fail "reported in a copy of $root, not injected: $line"
done < <(comm -13 <(sort <<<"$before") <(sort <<<"$after"))
echo "check_layers_test: ok (${#expected[@]} crossings named, in a small tree and in a copy of $root)"
