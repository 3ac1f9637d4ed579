// SPDX-License-Identifier: Apache-2.0
// libfusedet_mpi.so: the Collective of fusedet/boost/collective.h over MPI (MPI_COMM_WORLD), loaded by
// openMpiJob() (mpi_job.h) only under an MPI launcher. Failure policy: an MPI error or a
// collective that waits longer than the timeout ends the whole job with a message naming the
// rank - a rank that died must never leave the others hanging.
#include <mpi.h>

#include <atomic>
#include <chrono>
#include <climits>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

#include "mpi_job.h"

namespace fusedet::tools {
namespace {

std::string mpiError(int code) {
  char text[MPI_MAX_ERROR_STRING];
  int len = 0;
  MPI_Error_string(code, text, &len);
  return std::string(text, static_cast<std::size_t>(len));
}

class MpiCollective final : public MpiJob {
 public:
  explicit MpiCollective(double timeoutSeconds) : timeout_(timeoutSeconds) {
    // MPI_Init waits for every rank too, so the watchdog covers it (rank from the launcher).
    for (const char* v : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"})
      if (const char* r = std::getenv(v)) {
        rank_ = std::atoi(r);
        break;
      }
    if (timeout_ > 0) watchdog_ = std::thread([this] { watch(); });
    int provided = 0;
    {
      const Timed t(*this, "MPI_Init");
      check(MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
    }
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
    int rank = 0, size = 1, len = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    char name[MPI_MAX_PROCESSOR_NAME];
    MPI_Get_processor_name(name, &len);
    std::lock_guard lock(mutex_);  // the watchdog reads them
    rank_ = rank;
    size_ = size;
    host_.assign(name, static_cast<std::size_t>(len));
  }

  ~MpiCollective() override {
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    if (watchdog_.joinable()) watchdog_.join();
    MPI_Finalize();
  }

  int rank() const override { return rank_; }
  int size() const override { return size_; }
  std::string hostName() const override { return host_; }
  std::uint64_t bytesSent() const override { return bytes_; }

  void allReduceSum(std::span<std::int64_t> data) override {
    const Timed t(*this, "MPI_Allreduce");
    check(MPI_Allreduce(MPI_IN_PLACE, data.data(), count(data.size()), MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD),
          "MPI_Allreduce");
    bytes_ += data.size_bytes();
  }

  void reduceScatterSum(std::span<const std::int32_t> data, std::span<const int> blockSizes,
                        std::span<std::int32_t> mine) override {
    const Timed t(*this, "MPI_Reduce_scatter");
    if (blockSizes.size() != static_cast<std::size_t>(size_) ||
        mine.size() != static_cast<std::size_t>(blockSizes[static_cast<std::size_t>(rank_)]))
      throw std::invalid_argument("reduceScatterSum: block sizes do not match the job");
    check(MPI_Reduce_scatter(data.data(), mine.data(), blockSizes.data(), MPI_INT32_T, MPI_SUM, MPI_COMM_WORLD),
          "MPI_Reduce_scatter");
    bytes_ += data.size_bytes();
  }

  std::vector<std::byte> allGather(std::span<const std::byte> mine) override {
    const Timed t(*this, "MPI_Allgatherv");
    const auto n = static_cast<std::size_t>(size_);
    std::uint64_t myBytes = mine.size();
    std::vector<std::uint64_t> sizes(n);
    check(MPI_Allgather(&myBytes, 1, MPI_UINT64_T, sizes.data(), 1, MPI_UINT64_T, MPI_COMM_WORLD), "MPI_Allgather");
    std::vector<int> counts(n), displs(n);
    std::uint64_t total = 0;
    for (std::size_t r = 0; r < n; ++r) {
      displs[r] = count(total);
      counts[r] = count(sizes[r]);
      total += sizes[r];
    }
    count(total);  // the receive buffer is addressed with int displacements too
    std::vector<std::byte> out(total);
    check(MPI_Allgatherv(mine.data(), counts[static_cast<std::size_t>(rank_)], MPI_BYTE, out.data(), counts.data(),
                         displs.data(), MPI_BYTE, MPI_COMM_WORLD),
          "MPI_Allgatherv");
    bytes_ += sizeof myBytes + mine.size();
    return out;
  }

  [[noreturn]] void abort(int exitCode) override {
    std::fflush(stdout);
    std::fflush(stderr);
    MPI_Abort(MPI_COMM_WORLD, exitCode);
    std::_Exit(exitCode);  // MPI_Abort does not return; this keeps [[noreturn]] honest
  }

 private:
  // Marks the time spent inside one collective for the watchdog.
  class Timed {
   public:
    Timed(MpiCollective& c, const char* what) : c_(c) {
      c_.what_.store(what);
      c_.since_.store(std::chrono::steady_clock::now().time_since_epoch().count());
    }
    ~Timed() { c_.since_.store(0); }
    Timed(const Timed&) = delete;
    Timed& operator=(const Timed&) = delete;

   private:
    MpiCollective& c_;
  };

  static int count(std::uint64_t n) {
    if (n > static_cast<std::uint64_t>(INT_MAX))
      throw std::length_error("MPI message of " + std::to_string(n) + " elements exceeds the int count limit");
    return static_cast<int>(n);
  }

  void check(int code, const char* call) {
    if (code == MPI_SUCCESS) return;
    std::fprintf(stderr, "fusedet: rank %d (%s): %s failed: %s; aborting the job\n", rank_, host_.c_str(), call,
                 mpiError(code).c_str());
    abort(3);
  }

  // Ends the job when one collective has waited longer than the timeout: a peer hangs or died
  // without the launcher noticing. Exiting non-zero makes mpirun terminate every rank.
  void watch() {
    std::unique_lock lock(mutex_);
    while (!wake_.wait_for(lock, std::chrono::milliseconds(500), [this] { return stop_; })) {
      const auto since = since_.load();
      if (since == 0) continue;
      const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch() -
                                                          std::chrono::steady_clock::duration(since))
                                .count();
      if (waited < timeout_) continue;
      std::fprintf(stderr,
                   "fusedet: rank %d (%s): waited %.0f s in %s for the other ranks (--mpi-timeout %.0f): a rank "
                   "died or hangs; ending the job\n",
                   rank_, host_.empty() ? "?" : host_.c_str(), waited, what_.load(), timeout_);
      std::fflush(stderr);
      std::_Exit(4);
    }
  }

  double timeout_;
  int rank_ = 0, size_ = 1;
  std::string host_;
  std::uint64_t bytes_ = 0;
  std::atomic<const char*> what_{""};
  std::atomic<std::chrono::steady_clock::rep> since_{0};
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread watchdog_;
};

}  // namespace
}  // namespace fusedet::tools

extern "C" fusedet::tools::MpiJob* fusedet_mpi_open(double timeoutSeconds, char* error, unsigned long errorSize) {
  try {
    return new fusedet::tools::MpiCollective(timeoutSeconds);
  } catch (const std::exception& e) {
    std::snprintf(error, errorSize, "%s", e.what());
    return nullptr;
  }
}
