# SPDX-License-Identifier: Apache-2.0
# Sourced by the systemd tier's checks: output lines and timing. Every line a check prints that
# the host shows starts with "st: <check>:"; the check's exit status is its verdict.
export PATH=/usr/sbin:/usr/bin:/sbin:/bin
export DEBIAN_FRONTEND=noninteractive
run=/tier/run          # state shared between checks (before-install snapshot, ...)
mkdir -p "$run"
say() { echo "st: $check: $*"; }
bad() { echo "st: $check: FAIL: $*"; failures=$((failures + 1)); }
failures=0
now() { cut -d' ' -f1 /proc/uptime; }
since() { awk -v a="$1" -v b="$(now)" 'BEGIN{printf "%.2f", b - a}'; }
# wait_until SECONDS COMMAND...: polls COMMAND every 0.2 s; 0 once it succeeds, 1 after SECONDS.
wait_until() {
  local limit=$1 start
  shift
  start=$(now)
  until "$@" > /dev/null 2>&1; do
    awk -v a="$start" -v b="$(now)" -v l="$limit" 'BEGIN{exit !(b - a > l)}' && return 1
    sleep 0.2
  done
}
main_pid() { systemctl show -P MainPID "${1:-fusedetd.service}"; }
# try_write PID DIR [UID GID]: writes DIR/st-probe inside PID's mount namespace (the unit's
# ProtectSystem=, ProtectHome=, PrivateTmp=, StateDirectory= view), as UID:GID without groups when
# given, else as root; exit status of the write, its error on stdout.
try_write() {
  if [ $# -ge 4 ]; then
    nsenter -t "$1" -m -- setpriv --reuid="$3" --regid="$4" --clear-groups -- sh -c "echo probe > $2/st-probe" 2>&1
  else
    nsenter -t "$1" -m -- sh -c "echo probe > $2/st-probe" 2>&1
  fi
}
# The path list a purge must restore (as docs/packaging.md's snapshot): everything under the
# system's directories but what apt/dpkg, the journal and systemd's own run-time records keep, and
# /var/lib/private itself (systemd makes it, 0700, for any DynamicUser= unit's StateDirectory=;
# what the package's unit put in it must be gone).
snapshot() {
  find /etc /usr /var /opt /srv -xdev 2> /dev/null | grep -Ev \
    '^/var/(log|cache/(apt|debconf|man|ldconfig)|lib/(dpkg|apt|systemd/(catalog|random-seed|timers|coredump)|dbus)|tmp)(/|$)|^/etc/(ld\.so\.cache|machine-id)$|^/var/lib/private$' |
    LC_ALL=C sort
}
finish() {
  [ "$failures" -eq 0 ]
}
