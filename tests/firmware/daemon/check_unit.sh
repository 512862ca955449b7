#!/bin/bash
# Checks the systemd unit as systemd would read it: `systemd-analyze verify` (syntax, known
# settings, the programs it starts exist) and `systemd-analyze security --offline` (the hardening
# keeps the exposure score at or below 2.0, "OK" on systemd's 0-10 scale).
#   check_unit.sh UNIT_FILE REFOCUSD_BINARY
# Exit 77 (skip) without systemd-analyze.
set -euo pipefail
unit=${1:?usage: check_unit.sh UNIT_FILE REFOCUSD_BINARY}
binary=${2:?usage: check_unit.sh UNIT_FILE REFOCUSD_BINARY}
command -v systemd-analyze >/dev/null || { echo "SKIP: systemd-analyze not installed"; exit 77; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# The unit names the installed path; point it at the program just built.
sed "s|/usr/bin/refocusd|$binary|g" "$unit" >"$work/refocusd.service"
# verify warns and carries on about bad values: any message is a failure here.
messages=$(systemd-analyze verify "$work/refocusd.service" 2>&1) || true
[[ -z $messages ]] || { echo "$messages"; echo "check_unit: systemd-analyze verify complained"; exit 1; }
systemd-analyze security --offline=yes --threshold=20 "$work/refocusd.service" | tail -n 1
