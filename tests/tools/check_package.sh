#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The Debian package as cpack builds it from this build tree (docs/packaging.md): the files a
# robot needs in their FHS places and nothing of the development tree, /etc/fusedet/fusedet.yaml
# as the one conffile, dependencies computed by dpkg-shlibdeps, Debian-style maintainer scripts,
# units that point at /usr/bin and /etc, a packaged config the packaged fusedetd accepts, and
# lintian without errors or warnings.
# Usage: check_package.sh BUILD_DIR SOURCE_DIR [RUNNER...]
#   RUNNER: what runs the packaged fusedetd, for a cross build's package (scripts/arm64-package:
#   qemu-aarch64-static -L SYSROOT); FUSEDET_PACKAGE_OUT: a folder to keep the package in.
set -euo pipefail
build=$1 src=$2
shift 2
runner=("$@")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "check_package: $*" >&2; exit 1; }

out=$(mkdir -p "${FUSEDET_PACKAGE_OUT:-$tmp}" && cd "${FUSEDET_PACKAGE_OUT:-$tmp}" && pwd)
(cd "$build" && cpack -G DEB -B "$out" >"$tmp/cpack.log" 2>&1) || { cat "$tmp/cpack.log" >&2; fail "cpack failed"; }
debs=("$out"/fusedet_*.deb)
[[ ${#debs[@]} -eq 1 && -f ${debs[0]} ]] || fail "expected one fusedet_*.deb, got: ${debs[*]}"
deb=${debs[0]}
echo "package: $(basename "$deb") ($(stat -c %s "$deb") bytes)"

# Files: everything a robot needs, at the FHS places.
contents=$(dpkg-deb -c "$deb" | awk '{print $6}')
for f in ./usr/bin/fusedet ./usr/bin/fusedetd \
         ./etc/fusedet/fusedet.yaml ./lib/systemd/system/fusedetd.service ./lib/systemd/system/fusedetd.socket \
         ./lib/systemd/system/fusedet-record.service \
         ./usr/lib/sysusers.d/fusedet.conf ./usr/share/fusedet/models/car.json ./usr/share/fusedet/models/bike.json \
         ./usr/share/fusedet/models/person.json ./usr/share/doc/fusedet/copyright ./usr/share/doc/fusedet/changelog.gz \
         ./usr/share/doc/fusedet/protocol.md ./usr/share/man/man1/fusedet.1.gz ./usr/share/man/man1/fusedetd.1.gz; do
  grep -qxF "$f" <<<"$contents" || fail "missing from the package: $f"
done
# ... and nothing from the development side, the test simulators or the build tree's prefix.
if stray=$(grep -E '^\./usr/(include|local)/|\.a$|\.so$|^\./usr/etc/|^\./usr/lib/systemd/|-sim$' <<<"$contents"); then
  fail "files that do not belong in the package: $stray"
fi
echo "files: $(grep -vc '/$' <<<"$contents") ok"

# Control: conffiles, maintainer scripts, dependencies.
dpkg-deb -e "$deb" "$tmp/control"
[[ $(cat "$tmp/control/conffiles") == "/etc/fusedet/fusedet.yaml" ]] || fail "conffiles: $(cat "$tmp/control/conffiles")"
grep -q 'systemd-sysusers .*fusedet.conf' "$tmp/control/postinst" || fail "postinst does not create the group"
grep -q 'deb-systemd-helper update-state' "$tmp/control/postinst" || fail "postinst does not record the units' state"
if grep -v '^[[:space:]]*#' "$tmp/control/postinst" | grep -qE 'deb-systemd-invoke (start|restart)|systemctl .*(enable|start)'; then
  fail "postinst enables or starts the service on installation"
fi
grep -q 'deb-systemd-helper purge' "$tmp/control/postrm" || fail "postrm does not purge the units' state"
grep -q 'deb-systemd-invoke stop fusedet-record.service fusedetd.service fusedetd.socket' "$tmp/control/prerm" ||
  fail "prerm does not stop the services and the socket"
grep -q 'rm -rf /var/lib/fusedet-recordings /var/lib/private/fusedet-recordings' "$tmp/control/postrm" ||
  fail "postrm purge does not remove fusedet-record.service's recordings"
depends=$(dpkg-deb -f "$deb" Depends)
for d in libc6 libstdc++6 libopencv-core libsystemd0 libusb-1.0-0 libyaml-cpp 'systemd | systemd-standalone-sysusers'; do
  grep -qF "$d" <<<"$depends" || fail "Depends lacks $d: $depends"
done
maintainer=$(dpkg-deb -f "$deb" Maintainer)
configured=$(sed -n 's/^FUSEDET_PACKAGE_MAINTAINER:STRING=//p' "$build/CMakeCache.txt")
[[ $maintainer == "$configured" && $maintainer =~ ^[^\<\>]+\ \<[^\<\>@\ ]+@[^\<\>@\ ]+\>$ ]] ||
  fail "Maintainer '$maintainer' is not the configured 'Name <address>' ('$configured')"
echo "control: conffiles, maintainer scripts, Depends and Maintainer ($maintainer) ok"

# Payload: units, group, config.
dpkg-deb -x "$deb" "$tmp/root"
grep -qx 'ExecStart=/usr/bin/fusedetd --config /etc/fusedet/fusedet.yaml' "$tmp/root/lib/systemd/system/fusedetd.service" ||
  fail "ExecStart: $(grep ExecStart "$tmp/root/lib/systemd/system/fusedetd.service")"
grep -qx 'ExecStart=/usr/bin/fusedet record --config /etc/fusedet/fusedet.yaml --out-dir ${STATE_DIRECTORY}' \
  "$tmp/root/lib/systemd/system/fusedet-record.service" ||
  fail "fusedet-record.service ExecStart: $(grep ExecStart "$tmp/root/lib/systemd/system/fusedet-record.service")"
grep -qx 'StateDirectory=fusedet-recordings' "$tmp/root/lib/systemd/system/fusedet-record.service" ||
  fail "fusedet-record.service does not write into StateDirectory=fusedet-recordings (postrm purges that)"
group=$(awk '$1 == "g" {print $2}' "$tmp/root/usr/lib/sysusers.d/fusedet.conf")
grep -qx "SocketGroup=$group" "$tmp/root/lib/systemd/system/fusedetd.socket" || fail "the socket's group is not the sysusers group '$group'"
cmp -s "$tmp/root/etc/fusedet/fusedet.yaml" "$src/config/fusedet.yaml" || fail "packaged fusedet.yaml differs from config/fusedet.yaml"
"${runner[@]}" "$tmp/root/usr/bin/fusedetd" --config "$tmp/root/etc/fusedet/fusedet.yaml" --check-config >/dev/null ||
  fail "the packaged fusedetd rejects the packaged config"
for m in car bike person; do
  cmp -s "$tmp/root/usr/share/fusedet/models/$m.json" "$src/models/$m.json" || fail "model $m differs from models/$m.json"
done
# The copyright file names the code's licence (LICENSE) and the models' KITTI-derived one.
grep -qx 'License: Apache-2.0' "$tmp/root/usr/share/doc/fusedet/copyright" || fail "copyright: no Apache-2.0 paragraph"
grep -q 'Apache License' "$src/LICENSE" || fail "LICENSE is not the Apache License"
awk '/^Files: models\/\*/{m=1} m && /^License:/{print; exit}' "$tmp/root/usr/share/doc/fusedet/copyright" |
  grep -qx 'License: CC-BY-NC-SA-3.0' || fail "copyright: the models are not CC-BY-NC-SA-3.0"
echo "payload: units, group '$group', config, models and copyright ok"

# lintian: no errors and no warnings (its informational tags are listed in docs/packaging.md).
lintian --tag-display-limit 0 "$deb" >"$tmp/lintian.log" 2>&1 && rc=0 || rc=$?
grep -v 'running with root privileges' "$tmp/lintian.log" || true
if [[ $rc -ne 0 ]] || grep -q '^[EW]: ' "$tmp/lintian.log"; then fail "lintian reports errors or warnings (exit $rc)"; fi
# The manual pages are help2man's from the packaged programs, with the installed config path.
zcat "$tmp/root/usr/share/man/man1/fusedetd.1.gz" | grep -q 'config TEXT=/etc/fusedet/fusedet.yaml' ||
  fail "fusedetd.1 does not name the installed config /etc/fusedet/fusedet.yaml"
echo "lintian: $(grep -c '^E: ' "$tmp/lintian.log") errors, $(grep -c '^W: ' "$tmp/lintian.log") warnings"
