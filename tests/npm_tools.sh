#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Installs npm test tools into CACHE once (network: the npm registry; test tools only, never
# product code): nothing when every PACKAGE is there already; under a lock so that tests sharing
# CACHE do not install at the same time. Prints "PACKAGE VERSION, ..." of what is installed.
# Usage: npm_tools.sh CACHE PACKAGE...
set -euo pipefail
cache=$1
shift
mkdir -p "$cache"
cache=$(cd "$cache" && pwd)
(
  flock 9
  for p in "$@"; do
    if [[ ! -f $cache/node_modules/$p/package.json ]]; then
      (cd "$cache" && npm install --prefix "$cache" --no-audit --no-fund --silent "$@")
      break
    fi
  done
) 9> "$cache/.lock"
versions=()
for p in "$@"; do versions+=("$p $(node -p "require('$cache/node_modules/$p/package.json').version")"); done
(IFS=,; echo "${versions[*]}" | sed 's/,/, /g')
