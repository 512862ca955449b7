#!/usr/bin/env bash
# The main job on the simulated sensor: set up, build (Release), refocus the synthetic burst and
# print where the JPEG went. Extra arguments go to `refocus run` (e.g. --f-number 1.4); the focus
# and f-number below, and the output out/refocused.jpg, are defaults that a given one replaces.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset host >/dev/null
cmake --build --preset host --target refocus
mkdir -p out
defaults=()
[[ " $* " == *" --focus"[\ =]* ]] || defaults+=(--focus 640,480)
[[ " $* " == *" --f-number"[\ =]* ]] || defaults+=(--f-number 2.0)
out=$(pwd)/out/refocused.jpg
if [[ " $* " == *" --out"[\ =]* ]]; then out=""; else defaults+=(--out "$out"); fi
build/host/firmware/refocus run --synthetic "${defaults[@]}" "$@"
[[ -z $out ]] || echo "refocused JPEG: $out"
