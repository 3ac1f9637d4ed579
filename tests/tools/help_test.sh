#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# `fusedet --help` lists each subcommand in exactly one line (name + one-line description), and each
# listed subcommand's own --help works and explains more than that line. Usage: help_test.sh FUSEDET
set -u
fusedet=$1
help=$("$fusedet" --help) || { echo "fusedet --help failed"; exit 1; }
section=$(printf '%s\n' "$help" | sed -n '/^[Ss][Uu][Bb][Cc][Oo][Mm][Mm][Aa][Nn][Dd][Ss]:$/,$p' | tail -n +2 | grep -v '^$')
[ -n "$section" ] || { echo "no Subcommands section in fusedet --help"; exit 1; }
status=0
count=0
while IFS= read -r line; do
  if ! [[ $line =~ ^\ \ ([a-z][a-z0-9-]*)\ +[^\ ] ]]; then
    echo "not one line per subcommand: '$line'"; status=1; continue
  fi
  name=${BASH_REMATCH[1]}
  count=$((count + 1))
  own=$("$fusedet" "$name" --help) || { echo "fusedet $name --help failed"; status=1; continue; }
  [ "$(printf '%s\n' "$own" | wc -l)" -gt 3 ] || { echo "fusedet $name --help says almost nothing"; status=1; }
done <<< "$section"
[ "$count" -ge 10 ] || { echo "only $count subcommands listed"; status=1; }
# The long explanation of calibrate lives in its own --help, not in the list.
"$fusedet" calibrate --help | grep -q "Targetless laser->camera calibration" || { echo "calibrate --help lost its explanation"; status=1; }
printf '%s\n' "$section" | grep -q "Targetless laser->camera calibration" && { echo "the list carries calibrate's long text"; status=1; }
[ $status = 0 ] && echo "help: $count subcommands, one line each"
exit $status
