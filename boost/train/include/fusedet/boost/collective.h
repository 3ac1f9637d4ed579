// SPDX-License-Identifier: Apache-2.0
#pragma once
// The collective operations distributed training needs (ranks 0..size-1 of one job), as an
// abstract interface so that boost/ stays free of MPI: the MPI implementation lives in tools/mpi/
// (a module fusedet loads only when started by mpirun); LocalCollective is the one-rank job.
//
// Every rank must call the same operations in the same order with the same sizes (SPMD). All
// operations are exact (integers or raw bytes), so the results do not depend on how many ranks
// there are or in which order the transport adds them.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <type_traits>
#include <vector>

namespace fusedet::boosting {

class Collective {
 public:
  virtual ~Collective() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;

  // data := element-wise sum of data over all ranks, on every rank.
  virtual void allReduceSum(std::span<std::int64_t> data) = 0;
  // Element-wise sum of `data` (same length on every rank) over all ranks; rank r receives the
  // sums of its block: blockSizes[r] elements starting at sum(blockSizes[0..r)), into `mine`.
  virtual void reduceScatterSum(std::span<const std::int32_t> data, std::span<const int> blockSizes,
                                std::span<std::int32_t> mine) = 0;
  // Concatenation of every rank's `mine` in rank order, on every rank.
  virtual std::vector<std::byte> allGather(std::span<const std::byte> mine) = 0;

  // Payload bytes this rank has handed to the transport so far (benchmarks report it).
  virtual std::uint64_t bytesSent() const = 0;
};

// A job of one rank: every operation is the identity.
class LocalCollective final : public Collective {
 public:
  int rank() const override { return 0; }
  int size() const override { return 1; }
  void allReduceSum(std::span<std::int64_t>) override {}
  void reduceScatterSum(std::span<const std::int32_t> data, std::span<const int>,
                        std::span<std::int32_t> mine) override {
    if (!mine.empty()) std::memcpy(mine.data(), data.data(), mine.size_bytes());  // no null pointer to memcpy
  }
  std::vector<std::byte> allGather(std::span<const std::byte> mine) override {
    return {mine.begin(), mine.end()};
  }
  std::uint64_t bytesSent() const override { return 0; }
};

// allGather of trivially copyable values.
template <class T>
std::vector<T> allGatherValues(Collective& c, std::span<const T> mine) {
  static_assert(std::is_trivially_copyable_v<T>);
  const std::vector<std::byte> bytes = c.allGather(std::as_bytes(mine));
  std::vector<T> out(bytes.size() / sizeof(T));
  // Nothing gathered: out.data() may be null, which memcpy must not get even for 0 bytes (UBSan).
  if (!out.empty()) std::memcpy(out.data(), bytes.data(), out.size() * sizeof(T));
  return out;
}

}  // namespace fusedet::boosting
