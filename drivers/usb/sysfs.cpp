// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/usb/sysfs.h"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <set>

namespace fusedet::drivers::usb {
namespace {

constexpr int kMaxDepth = 4;  // interface/ttyUSB0/tty/ttyUSB0 is the deepest layout

// Collects node names below `dir` without following symlinks (sysfs links point all over the tree).
void collect(const std::filesystem::path& dir, int depth, std::set<std::string>& out) {
  std::error_code ec;
  for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->is_symlink(ec) || !it->is_directory(ec)) continue;
    const std::string name = it->path().filename().string();
    if (isDeviceNodeName(name)) out.insert(name);
    if (depth + 1 < kMaxDepth) collect(it->path(), depth + 1, out);
  }
}

// Orders ttyACM/ttyUSB/video by kind, then by number (video10 after video2).
std::pair<std::string, unsigned long> sortKey(const std::string& name) {
  const auto digits = name.find_first_of("0123456789");
  return {name.substr(0, digits), std::stoul(name.substr(digits))};
}

}  // namespace

bool isDeviceNodeName(const std::string& name) {
  for (const char* prefix : {"ttyUSB", "ttyACM", "video"}) {
    const std::size_t n = std::char_traits<char>::length(prefix);
    if (name.size() > n && name.compare(0, n, prefix) == 0 &&
        std::all_of(name.begin() + static_cast<std::ptrdiff_t>(n), name.end(), [](unsigned char c) { return std::isdigit(c); }))
      return true;
  }
  return false;
}

std::string UsbSysfs::deviceName(std::uint8_t bus, std::span<const std::uint8_t> ports) {
  // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on `const char* + std::string&&`.
  std::string s;
  if (ports.empty()) s += "usb";
  s += std::to_string(bus);
  for (std::size_t i = 0; i < ports.size(); ++i) {
    s += i == 0 ? '-' : '.';
    s += std::to_string(ports[i]);
  }
  return s;
}

std::optional<std::string> UsbSysfs::attribute(const std::string& device, const std::string& name) const {
  std::ifstream in(sysRoot_ / "bus/usb/devices" / device / name);
  std::string line;
  if (!in || !std::getline(in, line)) return std::nullopt;
  while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
  return line;
}

std::vector<std::string> UsbSysfs::nodes(const std::string& device) const {
  const std::filesystem::path dir = sysRoot_ / "bus/usb/devices" / device;
  std::set<std::string> names;
  std::error_code ec;
  // Only the device's interfaces ("<device>:<config>.<interface>"): child devices of a hub sit
  // beside them and have nodes of their own.
  for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind(device + ":", 0) == 0 && it->is_directory(ec)) collect(it->path(), 0, names);
  }
  std::vector<std::string> sorted(names.begin(), names.end());
  std::sort(sorted.begin(), sorted.end(), [](const std::string& a, const std::string& b) { return sortKey(a) < sortKey(b); });
  std::vector<std::string> out;
  for (const std::string& n : sorted) out.push_back((devRoot_ / n).string());
  return out;
}

}  // namespace fusedet::drivers::usb
