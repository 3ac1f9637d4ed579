#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The systemd units as configured for installation: `systemd-analyze verify` must be silent and
# `systemd-analyze security --offline=true` must rate fusedetd.service at exposure <= 2.5.
# ExecStart points at the build tree's fusedetd so that verify can check the binary.
# Usage: check_units.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1 src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
sed "s#^ExecStart=[^ ]*#ExecStart=$build/tools/fusedetd#" "$build/systemd/fusedetd.service" > "$tmp/fusedetd.service"
cp "$src/systemd/fusedetd.socket" "$tmp/fusedetd.socket"
grep -q '^Type=notify' "$tmp/fusedetd.service"
grep -q '^WatchdogSec=' "$tmp/fusedetd.service"
if grep -q '^RuntimeDirectory=' "$tmp/fusedetd.service" && ! grep -q '^RuntimeDirectoryPreserve=yes' "$tmp/fusedetd.service"; then
  echo "fusedetd.service removes /run/fusedet on stop, under the socket unit's feet" >&2; exit 1
fi
grep -q '^SocketGroup=fusedet' "$tmp/fusedetd.socket"
out=$(systemd-analyze verify --man=no "$tmp/fusedetd.socket" "$tmp/fusedetd.service" 2>&1) || { echo "$out" >&2; exit 1; }
if [[ -n $out ]]; then echo "systemd-analyze verify is not silent:" >&2; echo "$out" >&2; exit 1; fi
echo "verify: clean"
sec=$(systemd-analyze security --offline=true --no-pager "$tmp/fusedetd.service" 2>&1) || true
level=$(sed -n 's/.*Overall exposure level for fusedetd.service: \([0-9.]*\).*/\1/p' <<<"$sec")
[[ -n $level ]] || { echo "$sec" >&2; echo "no exposure level in the output" >&2; exit 1; }
echo "security: exposure $level (limit 2.5)"
awk -v l="$level" 'BEGIN { exit !(l <= 2.5) }'
