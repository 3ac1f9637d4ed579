// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/datasets/kitti_drives.h"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <regex>
#include <sstream>
#include <vector>

namespace fusedet::fusion {
namespace {

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

// Cells of a markdown table row "| a | b |"; empty when the line is not a row.
std::vector<std::string> cells(const std::string& line) {
  const std::string t = trim(line);
  if (t.size() < 2 || t.front() != '|') return {};
  std::vector<std::string> out;
  std::stringstream ss(t.substr(1));
  std::string c;
  while (std::getline(ss, c, '|')) out.push_back(trim(c));
  if (!out.empty() && out.back().empty() && t.back() == '|') out.pop_back();
  return out;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

}  // namespace

std::string KittiDriveMap::driveOf(const std::string& frameId, const std::string& fallback) const {
  if (const auto it = frames.find(frameId); it != frames.end()) return it->second;
  return directoryDrive.empty() ? fallback : directoryDrive;
}

KittiDriveMap parseKittiDriveMap(const std::string& markdown) {
  static const std::regex drive(R"(\d{4}_\d{2}_\d{2}_drive_\d{4})");
  KittiDriveMap m;
  std::stringstream in(markdown);
  std::string line;
  long idColumn = -1, driveColumn = -1;  // of the current table, -1 = not a drive table
  while (std::getline(in, line)) {
    const std::vector<std::string> row = cells(line);
    if (row.empty()) {
      idColumn = driveColumn = -1;
      std::smatch found;
      if (m.directoryDrive.empty() && trim(line).rfind('#', 0) == 0 && std::regex_search(line, found, drive))
        m.directoryDrive = found.str();
      continue;
    }
    if (idColumn < 0) {  // a header row?
      for (std::size_t i = 0; i < row.size(); ++i) {
        if (lower(row[i]) == "id") idColumn = static_cast<long>(i);
        if (lower(row[i]) == "raw drive") driveColumn = static_cast<long>(i);
      }
      if (driveColumn < 0) idColumn = -1;
      continue;
    }
    const auto id = static_cast<std::size_t>(idColumn), dr = static_cast<std::size_t>(driveColumn);
    if (id >= row.size() || dr >= row.size() || !std::regex_match(row[dr], drive)) continue;  // e.g. |---|
    m.frames[row[id]] = row[dr];
  }
  return m;
}

KittiDriveMap readKittiDriveMap(const std::filesystem::path& root) {
  std::ifstream f(root / "SOURCE.md");
  if (!f) return {};
  std::stringstream s;
  s << f.rdbuf();
  return parseKittiDriveMap(s.str());
}

}  // namespace fusedet::fusion
