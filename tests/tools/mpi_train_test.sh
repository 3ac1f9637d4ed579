#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# `mpirun fusedet train` end to end on a small synthetic data set (docs/distributed.md).
#   mpi_train_test.sh MODE FUSEDET WRITER MPIRUN WORKDIR
# identity:     1, 2 and 3 ranks write byte-identical models; only rank 0 prints; without mpirun
#               nothing MPI-related is printed.
# failing_rank: rank 1's item is corrupt (only rank 1 reads its pixels): the job ends with rank 1's
#               error instead of rank 0 waiting forever.
# killed_rank:  rank 1 is killed before it starts: the job ends, no hang.
# hung_rank:    rank 1 stops (SIGSTOP) before it starts: rank 0's --mpi-timeout ends the job.
set -euo pipefail
mode=$1 fusedet=$2 writer=$3 mpirun=$4 work=$5
rm -rf "$work" && mkdir -p "$work" && cd "$work"
"$writer" ds 6
# CI runs as root; Open MPI refuses that unless told.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
launch=("$mpirun" --oversubscribe)
train=(train --data ds --class car --layers intensity,hue_distance --grid 6 --window-height 12 --min-height 20
       --scale-factor 1.25 --stages 3 --rounds 12 --max-fa 0.01 --negatives 300 --seed 5 --threads 1 --split 1
       --progress log)
fail() { echo "FAIL: $*" >&2; exit 1; }

case $mode in
  identity)
    "$fusedet" "${train[@]}" --out local.json >local.out 2>local.err
    if grep -Eiq 'mpi|rank|distributed' local.out local.err; then fail "in-process run mentions MPI"; fi
    for np in 1 2 3; do
      timeout 240 "${launch[@]}" -np $np "$fusedet" "${train[@]}" --out np$np.json >np$np.out 2>np$np.err ||
        { cat np$np.err >&2; fail "mpirun -np $np failed"; }
      [[ $(grep -c '^wrote ' np$np.out) == 1 ]] || fail "-np $np: expected one 'wrote' line (rank 0 only)"
      [[ $(grep -c '^loaded ' np$np.err) == 1 ]] || fail "-np $np: expected one 'loaded' line (rank 0 only)"
      grep -q "distributed over $np ranks" np$np.err || fail "-np $np: no 'distributed over' line"
    done
    cmp np1.json np2.json || fail "1 and 2 ranks wrote different models"
    cmp np1.json np3.json || fail "1 and 3 ranks wrote different models"
    grep -q '"stages"' np1.json || fail "no stages in the model"
    echo "identical models for 1, 2, 3 ranks: $(md5sum <np1.json)"
    ;;
  failing_rank)
    # Item 1 belongs to rank 1 of 2; rank 0 reads only its labels.
    img=$(ls ds/items/synthetic/101/intensity.png)
    head -c 100 "$img" >"$img.cut" && mv "$img.cut" "$img"
    start=$SECONDS
    if timeout 120 "${launch[@]}" -np 2 "$fusedet" "${train[@]}" --out m.json >m.out 2>m.err; then
      fail "the job succeeded with a corrupt item"
    fi
    cat m.err
    ((SECONDS - start < 110)) || fail "the job did not end by itself"
    grep -q 'fusedet train: error: rank 1 of 2 .*synthetic/101' m.err || fail "rank 1's error not reported"
    [[ ! -e m.json ]] || fail "a model was written"
    ;;
  killed_rank)
    start=$SECONDS
    if timeout 120 "${launch[@]}" -np 2 bash -c \
        'if [[ $OMPI_COMM_WORLD_RANK == 1 ]]; then kill -9 $$; fi; exec "$0" "$@"' \
        "$fusedet" "${train[@]}" --out m.json >m.out 2>m.err; then
      fail "the job succeeded with a killed rank"
    fi
    cat m.err
    ((SECONDS - start < 110)) || fail "the job did not end by itself"
    [[ ! -e m.json ]] || fail "a model was written"
    ;;
  hung_rank)
    start=$SECONDS
    if timeout 120 "${launch[@]}" -np 2 bash -c \
        'if [[ $OMPI_COMM_WORLD_RANK == 1 ]]; then kill -STOP $$; fi; exec "$0" "$@"' \
        "$fusedet" "${train[@]}" --mpi-timeout 5 --out m.json >m.out 2>m.err; then
      fail "the job succeeded with a stopped rank"
    fi
    cat m.err
    ((SECONDS - start < 110)) || fail "the job did not end by itself"
    grep -q 'fusedet: rank 0 .*waited [0-9]* s in MPI_.* a rank died or hangs' m.err || fail "no timeout message"
    ;;
  *) fail "unknown mode $mode" ;;
esac
echo "PASS $mode"
