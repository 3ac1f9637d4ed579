#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The live view's systemd drop-in (systemd/examples/fusedetd-live.conf) on the installed unit:
# without it the unit allows no IP socket (RestrictAddressFamilies without AF_INET/AF_INET6,
# IPAddressDeny=any); with it, in fusedetd.service.d/, `systemd-analyze verify` stays silent, the
# drop-in is in effect (Internet sockets allowed, only localhost in the allow list, bind() only
# to its one TCP port) and `systemd-analyze security --offline=true` rates exposure <= 2.5.
# Usage: check_dropin.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
src=$2
. "$(dirname "$0")/../staged_units.sh"
stage_units "$1" "$2"
families=$(sed -n 's/^RestrictAddressFamilies=//p' "$units/fusedetd.service")
grep -qw 'AF_INET\|AF_INET6' <<<"$families" && { echo "the unit itself allows IP sockets: $families" >&2; exit 1; }
grep -q '^IPAddressDeny=any$' "$units/fusedetd.service"
echo "unit alone: RestrictAddressFamilies=$families, IPAddressDeny=any"
security() { SYSTEMD_UNIT_PATH=$units: systemd-analyze security --offline=true --no-pager fusedetd.service 2>&1 || true; }
before=$(security)
grep -q 'RestrictAddressFamilies=~AF_(INET|INET6) *Service cannot allocate Internet sockets' <<<"$before" || { echo "$before" >&2; exit 1; }
mkdir "$units/fusedetd.service.d"
cp "$src/systemd/examples/fusedetd-live.conf" "$units/fusedetd.service.d/live.conf"
port=$(sed -n 's/^SocketBindAllow=tcp:\([0-9]*\)$/\1/p' "$units/fusedetd.service.d/live.conf")
[[ -n $port ]] && grep -q '^SocketBindDeny=any$' "$units/fusedetd.service.d/live.conf" && echo "drop-in: bind() only to tcp:$port"
out=$(SYSTEMD_UNIT_PATH=$units: systemd-analyze verify --man=no fusedetd.socket fusedetd.service 2>&1) || { echo "$out" >&2; exit 1; }
if [[ -n $out ]]; then echo "systemd-analyze verify is not silent:" >&2; echo "$out" >&2; exit 1; fi
echo "verify with the drop-in: clean"
after=$(security)
grep -q 'RestrictAddressFamilies=~AF_(INET|INET6) *Service may allocate Internet sockets' <<<"$after" || { echo "$after" >&2; echo "the drop-in is not in effect" >&2; exit 1; }
grep -q 'IPAddressDeny=.*allow list with only localhost entries' <<<"$after" || { echo "$after" >&2; exit 1; }
level=$(exposure_level "$after")
was=$(exposure_level "$before")
[[ -n $level ]] || { echo "$after" >&2; exit 1; }
echo "security: exposure $was without the drop-in, $level with it (limit 2.5)"
awk -v l="$level" 'BEGIN { exit !(l <= 2.5) }'
