// SPDX-License-Identifier: Apache-2.0
#pragma once
// The laser->camera extrinsics as the config's `fusion.laser_to_camera` block: a YAML file that
// is also a valid fusedetd config (every other key at its default), so `fusedet calibrate` output
// can be pasted into /etc/fusedet/fusedet.yaml or read back as `--init`.
//
//   fusion:
//     laser_to_camera:
//       rotation_rpy_deg: [roll, pitch, yaw]   # R = Rz(yaw) Ry(pitch) Rx(roll)
//       translation: [x, y, z]                 # p_camera = R p_laser + t, metres

#include <Eigen/Geometry>
#include <filesystem>
#include <string>

namespace fusedet::fusion {

// Reads fusion.laser_to_camera from a YAML document (a full config or just that block). Throws
// std::runtime_error naming `what` on unparsable YAML, a missing block or key, or a value that
// is not a list of 3 finite numbers.
Eigen::Isometry3d parseLaserToCamera(const std::string& yamlText, const std::string& what = "extrinsics YAML");
Eigen::Isometry3d readLaserToCamera(const std::filesystem::path& file);

// The block as YAML text; `comment` (may be several lines) is written as '#' lines above it.
std::string formatLaserToCamera(const Eigen::Isometry3d& laserToCamera, const std::string& comment = "");
// Writes formatLaserToCamera to file; throws std::runtime_error naming the file if that fails.
void writeLaserToCamera(const std::filesystem::path& file, const Eigen::Isometry3d& laserToCamera,
                        const std::string& comment = "");

}  // namespace fusedet::fusion
