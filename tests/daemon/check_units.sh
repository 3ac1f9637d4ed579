#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The systemd units as configured for installation: `systemd-analyze verify` must be silent and
# `systemd-analyze security --offline=true` must rate fusedetd.service and fusedet-record.service
# at exposure <= 2.5 each.
# Usage: check_units.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
. "$(dirname "$0")/staged_units.sh"
stage_units "$1" "$2"
grep -q '^Type=notify' "$units/fusedetd.service"
grep -q '^WatchdogSec=' "$units/fusedetd.service"
if grep -q '^RuntimeDirectory=' "$units/fusedetd.service" && ! grep -q '^RuntimeDirectoryPreserve=yes' "$units/fusedetd.service"; then
  echo "fusedetd.service removes /run/fusedet on stop, under the socket unit's feet" >&2; exit 1
fi
grep -q '^SocketGroup=fusedet' "$units/fusedetd.socket"
grep -q '^StateDirectory=' "$units/fusedet-record.service"
out=$(systemd-analyze verify --man=no "$units/fusedetd.socket" "$units/fusedetd.service" "$units/fusedet-record.service" 2>&1) ||
  { echo "$out" >&2; exit 1; }
if [[ -n $out ]]; then echo "systemd-analyze verify is not silent:" >&2; echo "$out" >&2; exit 1; fi
echo "verify: clean"
for unit in fusedetd.service fusedet-record.service; do
  sec=$(systemd-analyze security --offline=true --no-pager "$units/$unit" 2>&1) || true
  level=$(exposure_level "$sec" "$unit")
  [[ -n $level ]] || { echo "$sec" >&2; echo "no exposure level for $unit in the output" >&2; exit 1; }
  echo "security: $unit exposure $level (limit 2.5)"
  awk -v l="$level" 'BEGIN { exit !(l <= 2.5) }' || { echo "$unit: exposure $level > 2.5" >&2; exit 1; }
done
