# SPDX-License-Identifier: Apache-2.0
# Distributed training (docs/distributed.md). bench_mpi_round: one boosting round of the sharded
# trainer under mpirun -np 1 vs -np 2 (one thread per rank) and the bytes per round; the ctest
# smoke run uses a small pool on 3 frames per drive.
if(FUSEDET_MPI)
  fusedet_bench(bench_mpi_round SOURCES mpi_round_bench.cpp
                DEPS fusedet_boost_train fusedet_datasets fusedet_mpi_loader opencv_imgproc opencv_core CLI11::CLI11
                SMOKE_ARGS --smoke)
  target_compile_definitions(bench_mpi_round PRIVATE FUSEDET_MPIRUN="${FUSEDET_MPIRUN}"
                             FUSEDET_MPI_MODULE_PATH="$<TARGET_FILE:fusedet_mpi>")
endif()
