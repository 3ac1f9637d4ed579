# SPDX-License-Identifier: Apache-2.0
# Sourced by scripts/sanitize and scripts/arm64 (bash, set -euo pipefail): the GoogleTest programs
# of a build folder, picked by target name from its build.ninja and run one at a time.
#   cpu                   CPU seconds (user + system) of this shell's finished children: on a shared
#                         machine the wall time follows the others' load, the CPU time says what the
#                         work costs on idle cores
#   test_programs TAG DIR REGEX
#                         sets the array `programs`: the target names of DIR's test programs (a
#                         Ninja build folder) that match REGEX, sorted; none is an error
#   test_program_path DIR NAME
#                         the absolute path of test program NAME built in DIR
#   run_test_programs TAG DIR SKIP [COMMAND...]
#                         runs each of `programs` from its own folder (as ctest does: tests find
#                         their data relative to it) as `COMMAND... PROGRAM [ARGS...]`, ARGS being
#                         --gtest_filter=-SKIP (unless SKIP is empty) and the caller's array
#                         `test_args` if set; its output goes to DIR/TAG-NAME.log. A program
#                         still running after FUSEDET_TEST_PROGRAM_TIMEOUT seconds (900) is
#                         killed and fails, so a hang costs minutes, not CI's budget. After each
#                         program it calls the caller's `test_program_checked NAME LOG` if defined,
#                         which may set `status=FAILED` and add to `note`. Prints one line per
#                         program (status, tests, wall and CPU seconds) and sets `failed`, `tests`,
#                         `run_seconds`, `run_cpu_seconds` for the caller's totals. TAG starts
#                         every line it prints.
tick=$(getconf CLK_TCK)
cpu() { awk -v t="$tick" '{ printf "%d", ($16 + $17) / t }' /proc/$$/stat; }

test_programs() {
  local tag=$1 dir=$2 regex=$3
  mapfile -t programs < <(ninja -C "$dir" -t targets all | sed -n 's|^tests/.*/\([a-z0-9_]*\): CXX_EXECUTABLE_LINKER.*|\1|p' |
                          grep -E "$regex" | sort -u)
  [[ ${#programs[@]} -gt 0 ]] || { echo "$tag: no test program matches $regex" >&2; exit 2; }
}

test_program_path() { find "$PWD/$1/tests" -type f -name "$2" -perm -u+x | head -1; }

run_test_programs() {
  local tag=$1 dir=$2 skip=$3
  shift 3
  local start=$SECONDS cpu0 t bin log t0 c0 n rc limit=${FUSEDET_TEST_PROGRAM_TIMEOUT:-900}
  local -a args=()
  [[ -n $skip ]] && args+=("--gtest_filter=-$skip")
  [[ -n ${test_args+set} ]] && args+=("${test_args[@]}")
  cpu0=$(cpu)
  failed=0 tests=0
  for t in "${programs[@]}"; do
    bin=$(test_program_path "$dir" "$t")
    [[ -n $bin ]] || { echo "$tag: $t was not built in $dir" >&2; exit 1; }
    log=$PWD/$dir/$tag-$t.log
    t0=$SECONDS c0=$(cpu)
    rc=0
    (cd "$(dirname "$bin")" && timeout -k 30 "$limit" "$@" "$bin" "${args[@]}") > "$log" 2>&1 || rc=$?
    if [[ $rc -eq 0 ]]; then status=ok; else status=FAILED; fi
    n=$(sed -n 's/^\[==========\] \([0-9]*\) tests\{0,1\} from .* ran\..*/\1/p' "$log" | tail -1)
    tests=$((tests + ${n:-0}))
    note=""
    [[ $rc -ne 124 && $rc -ne 137 ]] || note=" - killed after $limit s"
    if declare -F test_program_checked > /dev/null; then test_program_checked "$t" "$log"; fi
    [[ $status == ok ]] || { failed=$((failed + 1)); note="$note - see $log"; }
    echo "$tag: $t: $status (${n:-?} tests, $((SECONDS - t0)) s, $(($(cpu) - c0)) CPU s)$note"
  done
  run_seconds=$((SECONDS - start)) run_cpu_seconds=$(($(cpu) - cpu0))
}
