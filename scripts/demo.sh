#!/usr/bin/env bash
# The main job on the simulated sensor: set up, build (Release), refocus the synthetic burst and
# print where the JPEG went. Extra arguments go to `refocus run` (e.g. --f-number 1.4).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset host >/dev/null
cmake --build --preset host --target refocus
mkdir -p out
build/host/firmware/refocus run --synthetic --focus 640,480 --f-number 2.0 --out out/refocused.jpg "$@"
echo "refocused JPEG: $(pwd)/out/refocused.jpg"
