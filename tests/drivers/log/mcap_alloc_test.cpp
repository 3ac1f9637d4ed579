// SPDX-License-Identifier: Apache-2.0
// The MCAP reader's memory on a corrupt log (issue 37): a chunk header may claim any
// uncompressed size up to the reader's 1 GiB plausibility limit. The reader used to allocate
// the claimed size before decompressing; a 2 kB file could cost 1 GiB. This binary replaces
// the global operator new to record the largest single allocation while such a file is read:
// every non-aligned form (plain, array, nothrow), so that each new and each delete are ours and
// pair up (ASan reports a nothrow new it allocated but our delete freed as a mismatch).

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <new>

#include "fusedet/drivers/log/mcap_reader.h"
#include "fusedet/drivers/log/mcap_writer.h"

namespace {
std::atomic<std::size_t> largest{0};

void* recordedAlloc(std::size_t n) noexcept {
  std::size_t seen = largest.load();
  while (n > seen && !largest.compare_exchange_weak(seen, n)) {
  }
  return std::malloc(n ? n : 1);
}
}  // namespace

void* operator new(std::size_t n) {
  if (void* p = recordedAlloc(n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
  if (void* p = recordedAlloc(n)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t n, const std::nothrow_t&) noexcept { return recordedAlloc(n); }
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return recordedAlloc(n); }
// GCC at -O1 inlines these into gtest's `delete` and warns that free() meets operator new's
// pointer; here operator new is ours and returns malloc's memory, so the pair matches.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
#pragma GCC diagnostic pop

namespace fs = std::filesystem;
using namespace fusedet::drivers::mcap;

TEST(McapMemory, AChunkClaimingAHugeSizeCostsWhatItDecompressesTo) {
  const fs::path dir = fs::temp_directory_path() / ("fusedet_mcap_alloc_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path log = dir / "claims.mcap";
  {
    McapWriter w(log);
    const std::vector<std::uint8_t> schema{'{', '}'};
    const auto ch = w.addChannel(w.addSchema("s", "jsonschema", schema), "/t", "json");
    const std::vector<std::uint8_t> data{'{', '}'};
    for (std::uint64_t i = 0; i < 20; ++i) w.write(ch, i, i, data);
    w.close();
  }
  std::uint64_t chunkOffset = 0, claimed = 0;
  {
    McapReader r(log);
    ASSERT_EQ(r.index().chunks.size(), 1u);
    ASSERT_EQ(r.index().chunks[0].compression, "zstd");
    chunkOffset = r.index().chunks[0].offset;
    claimed = r.index().chunks[0].uncompressedSize;
  }
  ASSERT_LT(fs::file_size(log), 4096u);
  // Chunk record: opcode (1), length (8), start time (8), end time (8), uncompressed size (8).
  const std::uint64_t huge = (1ull << 30) - 1;
  {
    std::fstream f(log, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(chunkOffset + 1 + 8 + 16));
    for (int i = 0; i < 8; ++i) f.put(static_cast<char>((huge >> (8 * i)) & 0xff));
  }
  largest = 0;
  McapReader r(log);
  const std::size_t peak = largest.load();
  ASSERT_EQ(r.index().chunks.size(), 1u);
  EXPECT_FALSE(r.index().chunks[0].ok);
  EXPECT_NE(r.index().chunks[0].problem.find("header says " + std::to_string(huge)), std::string::npos)
      << r.index().chunks[0].problem;
  // The real content is `claimed` bytes (a few hundred): nothing near the claim is allocated.
  EXPECT_LT(peak, std::size_t{1} << 20) << "largest allocation " << peak << " bytes for a chunk of " << claimed;
  fs::remove_all(dir);
}
