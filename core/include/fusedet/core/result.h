// SPDX-License-Identifier: Apache-2.0
#pragma once
// Result<T>: value or Error, for routine failures (timeouts, CRC errors, ENODEV) that a
// reconnecting driver handles without unwinding. Member names follow std::expected so the alias
// can switch to it once the toolchain has C++23. Exceptions stay at boundaries (config and model
// loading, CLIs).

#include <cassert>
#include <string>
#include <system_error>
#include <utility>
#include <variant>

namespace fusedet {

struct Error {
  std::error_code code;
  std::string context;  // what was being done, e.g. "open /dev/ttyUSB0"

  std::string message() const {
    if (!code) return context;
    return context.empty() ? code.message() : context + ": " + code.message();
  }
};

inline Error makeError(std::errc code, std::string context) {
  return Error{std::make_error_code(code), std::move(context)};
}
inline Error errnoError(int err, std::string context) {
  return Error{std::error_code(err, std::generic_category()), std::move(context)};
}

template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}        // NOLINT(google-explicit-constructor)
  Result(Error error) : v_(std::move(error)) {}    // NOLINT(google-explicit-constructor)

  bool has_value() const { return v_.index() == 0; }
  explicit operator bool() const { return has_value(); }
  T& value() & { assert(has_value()); return std::get<0>(v_); }
  const T& value() const& { assert(has_value()); return std::get<0>(v_); }
  T&& value() && { assert(has_value()); return std::get<0>(std::move(v_)); }
  const Error& error() const { assert(!has_value()); return std::get<1>(v_); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  template <class U>
  T value_or(U&& fallback) const { return has_value() ? value() : T(std::forward<U>(fallback)); }

 private:
  std::variant<T, Error> v_;
};

template <>
class [[nodiscard]] Result<void> {
 public:
  Result() = default;
  Result(Error error) : error_(std::move(error)), ok_(false) {}  // NOLINT(google-explicit-constructor)
  bool has_value() const { return ok_; }
  explicit operator bool() const { return ok_; }
  const Error& error() const { assert(!ok_); return error_; }

 private:
  Error error_;
  bool ok_ = true;
};

}  // namespace fusedet
