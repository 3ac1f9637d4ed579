#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Installs @mcap/core and fzstd (a pure-JS zstd decoder) from npm into CACHE once, writes the
# sample log and lets the independent reader check it. Usage: mcap_core_reader.sh WRITER CACHE WORKDIR
set -euo pipefail
writer=$1 cache=$2 work=$3
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$cache" "$work"
cache=$(cd "$cache" && pwd) work=$(cd "$work" && pwd)
if [[ ! -f $cache/node_modules/@mcap/core/package.json || ! -f $cache/node_modules/fzstd/package.json ]]; then
  (cd "$cache" && flock "$cache/.lock" npm install --prefix "$cache" --no-audit --no-fund --silent @mcap/core fzstd)
fi
echo "@mcap/core $(node -p "require('$cache/node_modules/@mcap/core/package.json').version"), node $(node --version)"
"$writer" "$work/sample.mcap" > "$work/expected.json"
node "$here/mcap_core_reader.cjs" "$cache" "$work/sample.mcap" "$work/expected.json"
