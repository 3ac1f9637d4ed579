#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The live view's systemd drop-in (systemd/examples/fusedetd-live.conf) on the installed unit:
# without it the unit allows no IP socket (RestrictAddressFamilies without AF_INET/AF_INET6,
# IPAddressDeny=any); with it, in fusedetd.service.d/, `systemd-analyze verify` stays silent, the
# drop-in is in effect (Internet sockets allowed, only localhost in the allow list, bind() only
# to its one TCP port) and `systemd-analyze security --offline=true` rates exposure <= 2.5.
# Usage: check_dropin.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1 src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
sed "s#^ExecStart=[^ ]*#ExecStart=$build/tools/fusedetd#" "$build/systemd/fusedetd.service" > "$tmp/fusedetd.service"
cp "$src/systemd/fusedetd.socket" "$tmp/fusedetd.socket"
families=$(sed -n 's/^RestrictAddressFamilies=//p' "$tmp/fusedetd.service")
grep -qw 'AF_INET\|AF_INET6' <<<"$families" && { echo "the unit itself allows IP sockets: $families" >&2; exit 1; }
grep -q '^IPAddressDeny=any$' "$tmp/fusedetd.service"
echo "unit alone: RestrictAddressFamilies=$families, IPAddressDeny=any"
security() { SYSTEMD_UNIT_PATH=$tmp: systemd-analyze security --offline=true --no-pager fusedetd.service 2>&1 || true; }
before=$(security)
grep -q 'RestrictAddressFamilies=~AF_(INET|INET6) *Service cannot allocate Internet sockets' <<<"$before" || { echo "$before" >&2; exit 1; }
mkdir "$tmp/fusedetd.service.d"
cp "$src/systemd/examples/fusedetd-live.conf" "$tmp/fusedetd.service.d/live.conf"
port=$(sed -n 's/^SocketBindAllow=tcp:\([0-9]*\)$/\1/p' "$tmp/fusedetd.service.d/live.conf")
[[ -n $port ]] && grep -q '^SocketBindDeny=any$' "$tmp/fusedetd.service.d/live.conf" && echo "drop-in: bind() only to tcp:$port"
out=$(SYSTEMD_UNIT_PATH=$tmp: systemd-analyze verify --man=no fusedetd.socket fusedetd.service 2>&1) || { echo "$out" >&2; exit 1; }
if [[ -n $out ]]; then echo "systemd-analyze verify is not silent:" >&2; echo "$out" >&2; exit 1; fi
echo "verify with the drop-in: clean"
after=$(security)
grep -q 'RestrictAddressFamilies=~AF_(INET|INET6) *Service may allocate Internet sockets' <<<"$after" || { echo "$after" >&2; echo "the drop-in is not in effect" >&2; exit 1; }
grep -q 'IPAddressDeny=.*allow list with only localhost entries' <<<"$after" || { echo "$after" >&2; exit 1; }
level=$(sed -n 's/.*Overall exposure level for fusedetd.service: \([0-9.]*\).*/\1/p' <<<"$after")
was=$(sed -n 's/.*Overall exposure level for fusedetd.service: \([0-9.]*\).*/\1/p' <<<"$before")
[[ -n $level ]] || { echo "$after" >&2; exit 1; }
echo "security: exposure $was without the drop-in, $level with it (limit 2.5)"
awk -v l="$level" 'BEGIN { exit !(l <= 2.5) }'
