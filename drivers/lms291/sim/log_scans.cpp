// SPDX-License-Identifier: Apache-2.0
#include "log_scans.h"

#include <yaml-cpp/yaml.h>

#include <cmath>

#include "fusedet/drivers/log/replay.h"

namespace fusedet::drivers::lms291::sim {

namespace {

// The `laser` keys of the log's fusedet.yaml that decide the telegrams' content. The sim lives
// in drivers/ and cannot use the daemon's config parser; defaults are config/fusedet.yaml's.
Result<Lms291Config> laserConfigOfRig(const std::string& configYaml, const std::string& where) {
  Lms291Config c;
  try {
    const YAML::Node laser = YAML::Load(configYaml)["laser"];
    const int angle = laser["angle_deg"] ? laser["angle_deg"].as<int>() : 180;
    const double resolution = laser["resolution_deg"] ? laser["resolution_deg"].as<double>() : 0.5;
    c.variant = Variant{angle, static_cast<int>(std::lround(resolution * 100))};
    c.remission = laser["remission"] && laser["remission"].as<bool>();
    const std::string unit = laser["range_unit"] ? laser["range_unit"].as<std::string>() : "mm";
    if (unit != "mm" && unit != "cm") return makeError(std::errc::invalid_argument, where + ": laser.range_unit " + unit);
    c.unit = unit == "cm" ? Unit::kCm : Unit::kMm;
    if (c.remission) c.measuringMode = kMeasuringRemission;  // as Lms291 configures it
  } catch (const YAML::Exception& e) {
    return makeError(std::errc::invalid_argument, where + ": " + e.what());
  }
  if (!c.variant.valid()) return makeError(std::errc::invalid_argument, where + ": laser angle/resolution is no LMS variant");
  return c;
}

}  // namespace

Result<LoggedScans> loadLoggedScans(const std::filesystem::path& log) {
  try {
    const auto rig = logs::LogSource(log).rig();
    if (!rig) return makeError(std::errc::invalid_argument, log.string() + ": no fusedet.config metadata (scan mode unknown)");
    auto laser = laserConfigOfRig(rig->configYaml, log.string() + ":fusedet.config");
    if (!laser) return laser.error();
    LoggedScans out;
    out.variant = laser->variant;
    out.unit = laser->unit;
    out.remission = laser->remission;
    logs::SensorReplay replay(log, logs::SensorReplayConfig{*laser, {}});
    logs::SensorReplay::Handlers h;
    h.scan = [&](const LaserScan& s) { out.scans.push_back(s); };
    replay.run(h);
    const auto beams = static_cast<std::size_t>(out.variant.beams());
    for (const LaserScan& s : out.scans)
      if (s.ranges.size() != beams || (out.remission && s.remissions.size() != beams))
        return makeError(std::errc::invalid_argument, log.string() + ": a scan of " + std::to_string(s.ranges.size()) +
                                                          " beams in a log of " + std::to_string(beams) + "-beam scans");
    if (out.scans.empty()) return makeError(std::errc::invalid_argument, log.string() + ": no laser scans in the log");
    return out;
  } catch (const std::exception& e) {  // mcap::McapError: missing file, not MCAP
    return makeError(std::errc::invalid_argument, e.what());
  }
}

}  // namespace fusedet::drivers::lms291::sim
