// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/calibration/extrinsics_file.h"

#include <yaml-cpp/yaml.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "fusedet/fusion/camera_model.h"

namespace fusedet::fusion {
namespace {

std::array<double, 3> triple(const YAML::Node& block, const char* key, const std::string& what) {
  const YAML::Node v = block[key];
  const std::string name = std::string("fusion.laser_to_camera.") + key;
  if (!v) throw std::runtime_error(what + ": no key " + name);
  if (!v.IsSequence() || v.size() != 3) throw std::runtime_error(what + ": " + name + " must be a list of 3 numbers");
  std::array<double, 3> out{};
  for (std::size_t i = 0; i < 3; ++i) {
    try {
      out[i] = v[i].as<double>();
    } catch (const YAML::Exception&) {
      throw std::runtime_error(what + ": " + name + "[" + std::to_string(i) + "] is not a number");
    }
    if (!std::isfinite(out[i])) throw std::runtime_error(what + ": " + name + "[" + std::to_string(i) + "] is not finite");
  }
  return out;
}

}  // namespace

Eigen::Isometry3d parseLaserToCamera(const std::string& yamlText, const std::string& what) {
  YAML::Node root;
  try {
    root = YAML::Load(yamlText);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(what + ": not valid YAML: " + e.msg);
  }
  if (!root.IsMap() || !root["fusion"] || !root["fusion"].IsMap() || !root["fusion"]["laser_to_camera"] ||
      !root["fusion"]["laser_to_camera"].IsMap())
    throw std::runtime_error(what + ": no fusion.laser_to_camera mapping");
  const YAML::Node block = root["fusion"]["laser_to_camera"];
  return rigidFromRpyDeg(triple(block, "rotation_rpy_deg", what), triple(block, "translation", what));
}

Eigen::Isometry3d readLaserToCamera(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file.string() + ": cannot open extrinsics file");
  std::stringstream text;
  text << in.rdbuf();
  return parseLaserToCamera(text.str(), file.string());
}

std::string formatLaserToCamera(const Eigen::Isometry3d& laserToCamera, const std::string& comment) {
  const std::array<double, 3> rpy = rpyDegFromRotation(laserToCamera.linear());
  const Eigen::Vector3d t = laserToCamera.translation();
  std::ostringstream out;
  std::istringstream lines(comment);
  for (std::string line; std::getline(lines, line);) out << "# " << line << "\n";
  char buf[256];
  out << "fusion:\n  laser_to_camera:\n";
  // 9 decimals: degrees to 1e-9 and metres to a nanometre round-trip far below any calibration error.
  std::snprintf(buf, sizeof buf, "    rotation_rpy_deg: [%.9f, %.9f, %.9f]\n", rpy[0], rpy[1], rpy[2]);
  out << buf;
  std::snprintf(buf, sizeof buf, "    translation: [%.9f, %.9f, %.9f]\n", t.x(), t.y(), t.z());
  out << buf;
  return out.str();
}

void writeLaserToCamera(const std::filesystem::path& file, const Eigen::Isometry3d& laserToCamera,
                        const std::string& comment) {
  std::ofstream out(file);
  if (!out) throw std::runtime_error(file.string() + ": cannot write extrinsics file");
  out << formatLaserToCamera(laserToCamera, comment);
  out.flush();
  if (!out) throw std::runtime_error(file.string() + ": write failed");
}

}  // namespace fusedet::fusion
