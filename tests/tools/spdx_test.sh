#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# Every file of the project's own code names its licence in its first two lines
# ("SPDX-License-Identifier: Apache-2.0", the LICENSE file's): C++ sources and headers, CMake files,
# shell, Python and Node scripts. Data, models (their own licence: cmake/deb/copyright) and
# fuzzing corpora are not code. Usage: spdx_test.sh SOURCE_DIR
set -u
src=$1
grep -q "Apache License" "$src/LICENSE" && grep -q "Version 2.0" "$src/LICENSE" || { echo "$src/LICENSE is not the Apache License 2.0"; exit 1; }
missing=0 checked=0
while IFS= read -r -d '' f; do
  case $f in
    *.cpp|*.h|*.inc|*.cjs|*.py|*/CMakeLists.txt|*.cmake) ;;
    *) [[ $(head -c 2 "$f") == '#!' ]] || continue ;;  # scripts without an extension
  esac
  checked=$((checked + 1))
  head -n 2 "$f" | grep -q 'SPDX-License-Identifier: Apache-2.0' || { echo "no SPDX line: ${f#$src/}"; missing=$((missing + 1)); }
done < <(find "$src" \( -name .git -o -name 'build*' -o -name corpus -o -name node_modules -o -name data -o -name models \) -prune \
           -o -type f ! -name '*.md' ! -name '*.json' ! -name '*.yaml' ! -name '*.png' ! -name '*.mcap' ! -name '*.bin' -print0)
echo "spdx: $checked files of code checked, $missing without the SPDX line"
[[ $checked -gt 400 && $missing -eq 0 ]]
