// SPDX-License-Identifier: Apache-2.0
#pragma once
// ByteSource: a fuzz input consumed front to back as the numbers a target needs (a device's
// answers, frame fields, choices). Past the end every read yields zeros and exhausted() is true,
// so a target's loop that stops on exhausted() always ends.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

namespace fusedet::fuzz {

class ByteSource {
 public:
  ByteSource(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  bool exhausted() const { return at_ >= size_; }
  std::size_t left() const { return exhausted() ? 0 : size_ - at_; }

  // Copies up to out.size() bytes (zero-filled past the end).
  void fill(std::span<std::uint8_t> out) {
    const std::size_t n = out.size() < left() ? out.size() : left();
    if (n > 0) std::memcpy(out.data(), data_ + at_, n);
    if (n < out.size()) std::memset(out.data() + n, 0, out.size() - n);
    at_ += out.size();
  }
  template <typename T>
  T get() {
    std::uint8_t bytes[sizeof(T)];
    fill(bytes);
    T v;
    std::memcpy(&v, bytes, sizeof v);
    return v;
  }
  std::uint8_t byte() { return get<std::uint8_t>(); }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t at_ = 0;
};

}  // namespace fusedet::fuzz
