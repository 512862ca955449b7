#!/usr/bin/env bash
# Fails when a source file includes, or a CMake target links, across the layers the wrong way.
# The arrows point one way, between the top folders:
#   algo     -> algo only (pure computation)
#   hal      -> hal, and algo/core's vocabulary (lb_core) only
#   sim      -> sim, hal, algo
#   firmware -> firmware, hal, algo (only through the pipeline, below), and sim only from the two
#               programs, firmware/cli and firmware/daemon, which can select a simulated sensor:
#               shipped libraries never include sim/
# and no product folder reaches into tests/ (test scaffolding).
#
# Inside algo, each stage uses the ones before it, and only the pipeline composes stages:
#   core -> motion -> depth -> render -> pipeline
# A stage folder may include another stage's headers (its types, its geometry) but never another
# stage's `*_stage.h`: running one stage's output into the next is algo/pipeline's job.
#
# Inside firmware, a folder may use the ones on its left, never a neighbour on its own step:
#   storage, platform -> codecs -> refocusable, depth_out -> app -> cli, web
# and daemon uses all but cli: it starts the web server and gives it what it needs through an
# interface web declares, so web never includes daemon, and nothing includes cli or daemon.
# refocusable (the refocusable JPEG's XMP) and depth_out (the disparity files of `refocus depth`)
# sit on the codecs, under app and cli. A new firmware or algo folder fails the check until it
# is placed here.
#
# Firmware reaches the algorithm through the pipeline: it may include algo/core, algo/pipeline,
# a stage's types header (`*_types.h`, and algo/motion/camera.h, the camera model), and
# algo/render/render_stage.h: re-rendering a stored photo runs the render stage alone, and its
# parameters are the product's settings. Any other header of algo/motion, algo/depth or
# algo/render (a stage to wire, its scratch sizes) is a crossing.
#
# Links follow the same arrows: lb_core is algo/core, lb_algo the pipeline (it holds every
# stage), and each firmware library belongs to the folder whose CMakeLists.txt adds it.
#   tests/layering/check_layers.sh ROOT
# Prints one line per crossing and exits 1 if there is any.
set -uf  # no globbing: the rules' header patterns are matched against includes, never expanded
root=${1:?usage: check_layers.sh ROOT}
crossings=0
report() {
  echo "layering: $1"
  crossings=$((crossings + 1))
}

# The folder a path's rules follow, into $key: algo/X and firmware/X, or the top folder.
key_of() {
  local top=${1%%/*} rest=${1#*/}
  key=$top
  case $top in
    algo | firmware) [ "$rest" != "${rest#*/}" ] && key=$top/${rest%%/*} ;;
  esac
}

firmware_algo="algo/core algo/pipeline algo/*/*_types.h algo/motion/camera.h algo/render/render_stage.h"
# What a folder may use: folders (with everything under them) and file patterns. Empty: the
# folder is not placed in the layers.
may_use() {
  local sub
  case $1 in
    algo/core) echo "algo/core" ;;
    algo/motion) echo "algo/motion algo/core" ;;
    algo/depth) echo "algo/depth algo/motion algo/core" ;;
    algo/render) echo "algo/render algo/depth algo/motion algo/core" ;;
    algo/pipeline | algo) echo "algo" ;;
    hal) echo "hal algo/core" ;;
    sim) echo "sim hal algo" ;;
    firmware) echo "firmware sim hal algo" ;;  # its CMakeLists.txt only adds the folders
    firmware/*)
      case ${1#firmware/} in
        storage | platform) sub="${1#firmware/}" ;;
        codecs) sub="codecs storage platform" ;;
        refocusable | depth_out) sub="${1#firmware/} codecs storage platform" ;;
        app) sub="app refocusable depth_out codecs storage platform" ;;
        cli) sub="cli app refocusable depth_out codecs storage platform sim" ;;
        web) sub="web app refocusable depth_out codecs storage platform" ;;
        daemon) sub="daemon web app refocusable depth_out codecs storage platform sim" ;;
        *) return ;;
      esac
      local s out=""
      for s in $sub; do
        [ "$s" = sim ] && out="$out sim" || out="$out firmware/$s"
      done
      echo "${out# } hal $firmware_algo"
      ;;
  esac
}
declare -A rules_of  # may_use's answers, read once per folder
allowed() {  # allowed FROM_KEY TO_PATH [folder]: TO_PATH a header, or a library's folder
  local to=$2 f
  [ -n "${rules_of[$1]+set}" ] || rules_of[$1]=$(may_use "$1")
  for f in ${rules_of[$1]}; do
    if [[ $f == *'*'* || $f == *.h ]]; then
      # A header pattern: a library's folder is never one header.
      # shellcheck disable=SC2053 # the pattern is meant to glob
      [ $# -lt 3 ] && [[ $to == $f ]] && return 0
    elif [[ $to == "$f" || $to == "$f"/* ]]; then
      return 0
    fi
  done
  return 1
}
uses() {  # the rules of a folder, for a report
  local rules
  rules=$(may_use "$1")
  echo "${rules/"$firmware_algo"/algo through the pipeline}"
}
declare -A unplaced
placed() {  # placed KEY WHERE: reports a folder without rules once
  [ -n "${rules_of[$1]+set}" ] || rules_of[$1]=$(may_use "$1")
  [ -n "${rules_of[$1]}" ] && return 0
  [ -n "${unplaced[$1]:-}" ] && return 1
  unplaced[$1]=1
  report "$2: $1 is not placed in the layers (tests/layering/check_layers.sh's header)"
  return 1
}

# Includes: "algo/...", "hal/...", "sim/...", "firmware/...", "tests/...".
for top in algo hal sim firmware; do
  [ -d "$root/$top" ] || continue
  while IFS= read -r hit; do
    file=${hit%%:*}
    rest=${hit#*:}
    line=${rest%%:*}
    [[ ${rest#*:} =~ include[[:space:]]*\"([^\"]*)\" ]] || continue
    inc=${BASH_REMATCH[1]}
    case $inc in algo/* | hal/* | sim/* | firmware/* | tests/*) ;; *) continue ;; esac
    rel=${file#"$root"/}
    key_of "$rel"
    from=$key
    placed "$from" "$rel" || continue
    key_of "$inc"
    if ! allowed "$from" "$inc"; then
      report "$rel:$line includes \"$inc\" ($from may use: $(uses "$from"))"
    elif [ "$top" = algo ] && [ "$from" != algo/pipeline ] && [ "$key" != "$from" ] &&
      [[ $inc == algo/*/*_stage.h ]]; then
      report "$rel:$line includes \"$inc\" (only algo/pipeline composes stages)"
    fi
  done < <(grep -rnE --include='*.h' --include='*.cc' '^[[:space:]]*#[[:space:]]*include[[:space:]]*"' "$root/$top")
done

# Links: which folder defines each library, then every lb_* a folder's CMake links.
declare -A home
while IFS= read -r hit; do
  file=${hit%%:*}
  lib=$(sed -n 's/.*add_library(\([A-Za-z0-9_]*\).*/\1/p' <<<"${hit#*:}")
  key_of "${file#"$root"/}"
  [ -n "$lib" ] && home[$lib]=$key
done < <(grep -rn --include=CMakeLists.txt 'add_library(' "$root/algo" "$root/hal" "$root/sim" \
  "$root/firmware" "$root/tests" 2>/dev/null)
# Both are added in algo/CMakeLists.txt: the vocabulary, which hal may link, and the stages with
# the pipeline that composes them.
[ "${home[lb_core]:-}" = algo ] && home[lb_core]=algo/core
[ "${home[lb_algo]:-}" = algo ] && home[lb_algo]=algo/pipeline

for top in algo hal sim firmware; do
  [ -d "$root/$top" ] || continue
  while IFS= read -r file; do
    rel=${file#"$root"/}
    key_of "$rel"
    dir=$key
    placed "$dir" "$rel" || continue
    # target_link_libraries(TARGET ...) calls, joined onto one line each.
    while IFS= read -r call; do
      target=$(sed -E 's/target_link_libraries\([[:space:]]*([^[:space:])]*).*/\1/' <<<"$call")
      from=${home[$target]:-$dir}  # a library's own folder, else the file's (a program)
      for lib in $(grep -oE '\blb_[A-Za-z0-9_]+' <<<"${call#*"$target"}"); do
        to=${home[$lib]:-}
        [ -n "$to" ] || continue
        allowed "$from" "$to" folder ||
          report "$rel: $target links $lib (from $to; $from may use: $(uses "$from"))"
      done
    done < <(tr '\n' ' ' <"$file" | grep -oE 'target_link_libraries\([^)]*\)')
  done < <(find "$root/$top" -name CMakeLists.txt)
done

[ "$crossings" -eq 0 ]
