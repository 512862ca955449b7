#!/usr/bin/env bash
# Fails when a source file includes, or a CMake target links, across the layers the wrong way.
# The arrows point one way:
#   algo     -> algo only (pure computation)
#   hal      -> hal, and algo/core's vocabulary (lb_core) only
#   sim      -> sim, hal, algo
#   firmware -> firmware, sim, hal, algo
# and no product folder reaches into tests/ (test scaffolding).
#   tests/layering/check_layers.sh ROOT
# Prints one line per crossing and exits 1 if there is any.
set -u
root=${1:?usage: check_layers.sh ROOT}
crossings=0
report() {
  echo "layering: $1"
  crossings=$((crossings + 1))
}

# The folders a top-level folder may depend on.
may_use() {
  case $1 in
    algo) echo "algo" ;;
    hal) echo "hal algo/core" ;;
    sim) echo "sim hal algo" ;;
    firmware) echo "firmware sim hal algo" ;;
  esac
}
allowed() {  # allowed FROM TO_PATH_OR_FOLDER
  local from=$1 to=$2 f
  for f in $(may_use "$from"); do
    case $to in "$f" | "$f"/*) return 0 ;; esac
  done
  return 1
}

# Includes: "algo/...", "hal/...", "sim/...", "firmware/...", "tests/...".
for top in algo hal sim firmware; do
  [ -d "$root/$top" ] || continue
  while IFS= read -r hit; do
    file=${hit%%:*}
    rest=${hit#*:}
    line=${rest%%:*}
    inc=$(sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"\([^"]*\)".*/\1/p' <<<"${rest#*:}")
    case $inc in algo/* | hal/* | sim/* | firmware/* | tests/*) ;; *) continue ;; esac
    allowed "$top" "$inc" || report "${file#"$root"/}:$line includes \"$inc\" ($top may use: $(may_use "$top"))"
  done < <(grep -rnE --include='*.h' --include='*.cc' '^[[:space:]]*#[[:space:]]*include[[:space:]]*"' "$root/$top")
done

# Links: which folder defines each library, then every lb_* a folder's CMake links.
declare -A home
while IFS= read -r hit; do
  file=${hit%%:*}
  lib=$(sed -n 's/.*add_library(\([A-Za-z0-9_]*\).*/\1/p' <<<"${hit#*:}")
  rel=${file#"$root"/}
  [ -n "$lib" ] && home[$lib]=${rel%%/*}
done < <(grep -rn --include=CMakeLists.txt 'add_library(' "$root/algo" "$root/hal" "$root/sim" \
  "$root/firmware" "$root/tests" 2>/dev/null)
[ "${home[lb_core]:-}" = algo ] && home[lb_core]=algo/core  # the vocabulary: hal may link it

for top in algo hal sim firmware; do
  [ -d "$root/$top" ] || continue
  while IFS= read -r file; do
    # target_link_libraries(TARGET ...) calls, joined onto one line each.
    tr '\n' ' ' <"$file" | grep -oE 'target_link_libraries\([^)]*\)' | while IFS= read -r call; do
      target=$(sed -E 's/target_link_libraries\([[:space:]]*([^[:space:])]*).*/\1/' <<<"$call")
      for lib in $(grep -oE '\blb_[A-Za-z0-9_]+' <<<"${call#*"$target"}"); do
        to=${home[$lib]:-}
        [ -n "$to" ] || continue
        allowed "$top" "$to" ||
          echo "layering: ${file#"$root"/}: $target links $lib (from $to; $top may use: $(may_use "$top"))"
      done
    done
  done < <(find "$root/$top" -name CMakeLists.txt)
done >"${TMPDIR:-/tmp}/check_layers.$$"
if [ -s "${TMPDIR:-/tmp}/check_layers.$$" ]; then
  cat "${TMPDIR:-/tmp}/check_layers.$$"
  crossings=$((crossings + $(wc -l <"${TMPDIR:-/tmp}/check_layers.$$")))
fi
rm -f "${TMPDIR:-/tmp}/check_layers.$$"

[ "$crossings" -eq 0 ]
