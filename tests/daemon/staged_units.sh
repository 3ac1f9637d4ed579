# SPDX-License-Identifier: Apache-2.0
# Sourced by the unit checks (check_units.sh, live/check_dropin.sh): the units as configured for
# installation, staged in a temporary folder, and the exposure level systemd-analyze rates.
# stage_units BUILD_DIR SOURCE_DIR: sets $units to a folder (removed on exit) holding
# fusedetd.service and fusedet-record.service, their ExecStart pointed at the build tree's
# fusedetd and fusedet so that verify can check the binaries, and fusedetd.socket.
stage_units() {
  units=$(mktemp -d)
  trap 'rm -rf "$units"' EXIT
  sed "s#^ExecStart=[^ ]*#ExecStart=$1/tools/fusedetd#" "$1/systemd/fusedetd.service" > "$units/fusedetd.service"
  sed "s#^ExecStart=[^ ]*#ExecStart=$1/tools/fusedet#" "$1/systemd/fusedet-record.service" > "$units/fusedet-record.service"
  cp "$2/systemd/fusedetd.socket" "$units/fusedetd.socket"
}
# exposure_level TEXT [UNIT]: the "Overall exposure level" of UNIT (default fusedetd.service) in
# systemd-analyze security's output, or nothing.
exposure_level() { sed -n "s/.*Overall exposure level for ${2:-fusedetd.service}: \([0-9.]*\).*/\1/p" <<<"$1"; }
