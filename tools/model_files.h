// SPDX-License-Identifier: Apache-2.0
#pragma once
// Model arguments of the commands: files, or folders whose *.json files are models (sorted).

#include <algorithm>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace fusedet::tools {

inline std::vector<std::filesystem::path> modelFiles(const std::vector<std::string>& args) {
  std::vector<std::filesystem::path> files;
  for (const std::string& a : args) {
    const std::filesystem::path p(a);
    if (!std::filesystem::is_directory(p)) {
      if (!std::filesystem::is_regular_file(p)) throw std::runtime_error(a + ": no such model file or folder");
      files.push_back(p);
      continue;
    }
    std::vector<std::filesystem::path> in;
    for (const auto& e : std::filesystem::directory_iterator(p))
      if (e.path().extension() == ".json") in.push_back(e.path());
    if (in.empty()) throw std::runtime_error(a + ": no model files (*.json)");
    std::sort(in.begin(), in.end());
    files.insert(files.end(), in.begin(), in.end());
  }
  return files;
}

}  // namespace fusedet::tools
