// SPDX-License-Identifier: Apache-2.0
// Finds and loads libfusedet_mpi.so (mpi_job.h): only here does fusedet touch the dynamic loader.
#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include "mpi_job.h"

namespace fusedet::tools {

bool launchedByMpiLauncher() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE"})
    if (std::getenv(v)) return true;
  return false;
}

std::unique_ptr<MpiJob> openMpiJob(double timeoutSeconds) {
#ifndef FUSEDET_MPI_MODULE_NAME
  (void)timeoutSeconds;
  throw std::runtime_error(
      "started by an MPI launcher, but this fusedet was built without MPI support (configure with "
      "-DFUSEDET_MPI=ON and libopenmpi-dev installed)");
#else
  std::vector<std::filesystem::path> candidates;
  if (const char* p = std::getenv("FUSEDET_MPI_MODULE")) candidates.emplace_back(p);
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) candidates.push_back(exe.parent_path() / FUSEDET_MPI_MODULE_NAME);
  candidates.emplace_back(FUSEDET_MPI_MODULE_INSTALLED);
  std::string tried;
  for (const auto& path : candidates) {
    if (!std::filesystem::exists(path)) {
      tried += "\n  " + path.string() + ": not found";
      continue;
    }
    // RTLD_GLOBAL: Open MPI's own plugins resolve symbols of libmpi, which comes in with the module.
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_GLOBAL);
    if (!handle) {
      tried += "\n  " + path.string() + ": " + dlerror();
      continue;
    }
    auto* open = reinterpret_cast<decltype(&fusedet_mpi_open)>(dlsym(handle, "fusedet_mpi_open"));
    if (!open) throw std::runtime_error(path.string() + ": no fusedet_mpi_open (not a fusedet MPI module)");
    char error[512] = {};
    MpiJob* job = open(timeoutSeconds, error, sizeof error);
    if (!job) throw std::runtime_error(std::string("MPI initialisation failed: ") + error);
    return std::unique_ptr<MpiJob>(job);  // the module stays loaded for the life of the process
  }
  throw std::runtime_error("started by an MPI launcher, but the MPI module could not be loaded (is Open MPI "
                           "installed? Debian: openmpi-bin libopenmpi3):" + tried);
#endif
}

}  // namespace fusedet::tools
