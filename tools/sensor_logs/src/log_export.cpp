// SPDX-License-Identifier: Apache-2.0
#include "fusedet/sensor_logs/log_export.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "fusedet/drivers/log/mcap_reader.h"
#include "fusedet/fusion/frame_decode.h"

namespace fusedet::sensor_logs {

using fusion::Sweep;
using fusion::SweepPoint;

namespace fs = std::filesystem;
namespace logs = drivers::logs;

std::uint64_t exportFramesPng(const fs::path& log, const fs::path& dir) {
  fs::create_directories(dir);
  logs::LogSource source(log);
  std::uint64_t n = 0;
  logs::LogSource::Handlers h;
  h.camera = [&](const drivers::CameraFrame& f) {
    auto bgr = fusion::decodeCameraFrame(f);
    if (!bgr) throw std::runtime_error(log.string() + ": " + bgr.error().message());
    const fs::path file = dir / ("frame_" + std::to_string(f.sequence) + "_" + std::to_string(f.stamp.ns) + ".png");
    if (!cv::imwrite(file.string(), *bgr)) throw std::runtime_error(file.string() + ": cannot write PNG");
    ++n;
  };
  while (source.step(h)) {
  }
  return n;
}

void writePly(const Sweep& sweep, const fs::path& file) {
  std::ofstream out(file);
  if (!out) throw std::runtime_error(file.string() + ": cannot create: " + std::strerror(errno));
  out << "ply\nformat ascii 1.0\ncomment fusedet sweep " << sweep.id << ", stamps " << sweep.start.toString() << " .. "
      << sweep.end.toString() << "\nelement vertex " << sweep.points.size()
      << "\nproperty float x\nproperty float y\nproperty float z\nproperty float remission\nend_header\n";
  for (const SweepPoint& p : sweep.points) out << p.x << ' ' << p.y << ' ' << p.z << ' ' << p.remission << '\n';
  if (!out) throw std::runtime_error(file.string() + ": write error");
}

std::uint64_t exportSweepsPly(const fs::path& log, const logs::SensorReplayConfig& replayConfig, const fusion::SweepConfig& sweepConfig,
                              const fs::path& dir) {
  fs::create_directories(dir);
  std::uint64_t n = 0;
  auto save = [&](const Sweep& s) {
    writePly(s, dir / ("sweep_" + std::to_string(n) + "_" + std::to_string(s.start.ns) + ".ply"));
    ++n;
  };
  // Recorded sweeps, if the log has them.
  const drivers::mcap::McapReader reader(log);
  if (const drivers::mcap::Channel* ch = reader.index().channel(logs::topic::kSweep)) {
    auto cursor = reader.messages();
    while (auto m = cursor.next()) {
      if (m->channelId != ch->id) continue;
      auto cloud = logs::decodePointCloud(m->data);
      if (!cloud) throw std::runtime_error(log.string() + ": " + cloud.error().message());
      Sweep s;
      s.id = n;
      s.start = s.end = cloud->stamp;
      for (const auto& p : cloud->points) s.points.push_back(SweepPoint{p[0], p[1], p[2], p[3], 0});
      save(s);
    }
    return n;
  }
  // Otherwise: assemble them from the raw streams, as live.
  logs::SensorReplay replay(log, replayConfig);
  fusion::SweepAssembler assembler(sweepConfig);
  logs::SensorReplay::Handlers h;
  h.scan = [&](const drivers::LaserScan& s) { assembler.addScan(s); };
  h.tilt = [&](const drivers::TiltSample& t) { assembler.addTilt(t); };
  while (replay.step(h))
    for (const Sweep& s : assembler.takeSweeps()) save(s);
  assembler.flush();
  for (const Sweep& s : assembler.takeSweeps()) save(s);
  return n;
}

}  // namespace fusedet::sensor_logs
