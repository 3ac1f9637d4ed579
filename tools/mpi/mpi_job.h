// SPDX-License-Identifier: Apache-2.0
#pragma once
// A training job's ranks over MPI, for tools that train (fusedet train, bench_mpi_round).
//
// fusedet never links libmpi: the MPI implementation (mpi_collective.cpp) is a module,
// libfusedet_mpi.so, that openMpiJob() loads only when the process was started by a launcher
// (mpirun, srun). Without one nothing MPI-related is loaded or printed, and the binary runs on
// machines without Open MPI.

#include <memory>
#include <string>

#include "fusedet/boost/collective.h"

namespace fusedet::tools {

class MpiJob : public boosting::Collective {
 public:
  // Ends the whole job at once (MPI_Abort): a rank that cannot go on must not leave the others
  // waiting in a collective. Does not return.
  [[noreturn]] virtual void abort(int exitCode) = 0;
  virtual std::string hostName() const = 0;
};

// Environment variables a launcher sets: Open MPI's mpirun (OMPI_COMM_WORLD_SIZE), PMIx (srun
// --mpi=pmix, PMIX_RANK) or PMI-1/2 (PMI_SIZE).
bool launchedByMpiLauncher();

// Loads the module (FUSEDET_MPI_MODULE, else beside the executable, else the installed copy) and
// initialises MPI. A collective operation that waits longer than `timeoutSeconds` (0 = never) for
// the other ranks ends the job with a message naming the rank. Throws std::runtime_error with the
// reason when MPI support is missing (built without FUSEDET_MPI, module or libmpi not found).
std::unique_ptr<MpiJob> openMpiJob(double timeoutSeconds);

}  // namespace fusedet::tools

// The module's entry point (C linkage for dlsym): a new job, or nullptr with the reason in `error`.
extern "C" fusedet::tools::MpiJob* fusedet_mpi_open(double timeoutSeconds, char* error, unsigned long errorSize);
