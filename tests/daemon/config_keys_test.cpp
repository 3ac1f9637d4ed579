// SPDX-License-Identifier: Apache-2.0
// Each daemon config key is declared once in effect: the keys parseConfig() reads (configKeys()),
// the keys dumpConfig() writes and the keys config/fusedet.yaml documents are one set, the
// documented values are the defaults, and the reload list (reloadableConfigKeys()) is the one the
// YAML's header names and the one withReloaded() applies - key by key.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "fusedet/daemon/config.h"
#include "fusedet/daemon/config_keys.h"

namespace fusedet::daemon {
namespace {

const std::filesystem::path kShipped = std::filesystem::path(FUSEDET_SOURCE_DIR) / "config" / "fusedet.yaml";

std::string readFile(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Key paths of the scalars and sequences of a YAML tree; "detection.classes" is one key (its
// entries are class names, not keys).
void leafKeys(const YAML::Node& node, const std::string& path, std::set<std::string>& out) {
  if (!node.IsMap() || path == "detection.classes") {
    out.insert(path);
    return;
  }
  for (const auto& kv : node) {
    const std::string key = kv.first.as<std::string>();
    leafKeys(kv.second, path.empty() ? key : path + "." + key, out);
  }
}

std::set<std::string> keysOf(const std::string& yaml) {
  std::set<std::string> out;
  leafKeys(YAML::Load(yaml), "", out);
  return out;
}

std::string listed(const std::set<std::string>& keys) {
  std::string s;
  for (const std::string& k : keys) s += "\n  " + k;
  return s;
}

std::set<std::string> minus(const std::set<std::string>& a, const std::set<std::string>& b) {
  std::set<std::string> out;
  std::set_difference(a.begin(), a.end(), b.begin(), b.end(), std::inserter(out, out.end()));
  return out;
}

TEST(ConfigKeys, ParseDumpAndDocumentedYamlHaveTheSameKeys) {
  const std::vector<std::string> readList = configKeys();
  const std::set<std::string> read(readList.begin(), readList.end());
  EXPECT_EQ(read.size(), readList.size()) << "parseConfig() reads a key twice";
  EXPECT_GT(read.size(), 50u);
  EXPECT_TRUE(read.count("laser.baud") && read.count("detection.classes") && read.count("fusion.laser_to_camera.translation"));
  const std::set<std::string> dumped = keysOf(dumpConfig(Config{}));
  const std::set<std::string> documented = keysOf(readFile(kShipped));
  EXPECT_TRUE(minus(read, dumped).empty()) << "read but not dumped:" << listed(minus(read, dumped));
  EXPECT_TRUE(minus(dumped, read).empty()) << "dumped but not read:" << listed(minus(dumped, read));
  EXPECT_TRUE(minus(read, documented).empty()) << "read but not in " << kShipped << ":" << listed(minus(read, documented));
  EXPECT_TRUE(minus(documented, read).empty()) << "in " << kShipped << " but not read:" << listed(minus(documented, read));
}

TEST(ConfigKeys, DocumentedValuesAreTheDefaultsAndDumpRoundTrips) {
  EXPECT_EQ(dumpConfig(loadConfig(kShipped)), dumpConfig(Config{}));
  EXPECT_EQ(dumpConfig(parseConfig(dumpConfig(Config{}), "dump.yaml")), dumpConfig(Config{}));
}

// A config that differs from the defaults in every key: each scalar / sequence changed to another
// valid value. Checked to cover every key, so a new key must be added here (with a valid value).
std::string everyKeyChanged() {
  return R"(version: 1
log: {level: debug}
socket: {path: /tmp/other.sock, max_clients: 3, max_request_bytes: 512, client_queue: 7, client_send_buffer: 65536,
         mode: "0600", group: root, allow_groups: [root]}
laser: {device: /dev/ttyS3, baud: 9600, angle_deg: 100, resolution_deg: 0.25, remission: true, range_unit: cm,
        remission_full_scale: 500.0, reconnect_max_s: 2.0}
tilt: {interface: can1, node_id: 9, min_deg: -20.0, max_deg: 25.0, speed_deg_s: 10.0, counts_per_rev: 2048,
       gear_ratio: 20.0, zero_offset_counts: 12, heartbeat_ms: 50}
camera: {device: /dev/video2, usb: "046d:0825", format: mjpeg, width: 320, height: 240, fps: 30, buffers: 8,
         exposure: "800", gain: "4", stall_ms: 1000, reconnect_max_s: 3.0, calibration: cam.yaml}
fusion:
  laser_to_camera: {rotation_rpy_deg: [-89.0, 1.0, -91.0], translation: [0.01, -0.2, 0.03]}
  tilt_axis_offset: [0.0, 0.01, 0.04]
  laser_layer_scale: 0.25
  hole_fill_radius: 1
  max_pair_skew_ms: 100
  tilt_window_ms: 40
  close_on_tilt: false
neural: {enabled: true, kind: yolov5-onnx, files: [net.onnx], directory: nets, input: "1248x384", scale: 0.25, threads: 2}
detection: {models: [a.json], scale_factor: 1.2, min_size: [10, 20], max_size: [400, 300], step: 3,
            min_neighbors: 2, laser_extent: true, threads: 2,
            classes: {person: {min_neighbors: 5, laser_extent: false}}}
tracking: {acceleration_sigma: 1.0, measurement_sigma: 0.3, initial_velocity_sigma: 4.0, gate: 9.0, birth_hits: 3,
           birth_window: 4, max_misses: 2, max_coast_s: 2.0}
live: {listen: "127.0.0.1:8766", layers: [intensity], max_viewers: 2, viewer_queue_bytes: 1048576}
replay: {file: x.mcap, realtime: false, speed: 2.0, restamp: false, at_end: exit}
)";
}

// Keys whose values differ between two dumps.
std::set<std::string> changedKeys(const Config& a, const Config& b) {
  const YAML::Node x = YAML::Load(dumpConfig(a)), y = YAML::Load(dumpConfig(b));
  std::set<std::string> out;
  for (const std::string& key : keysOf(dumpConfig(a))) {
    YAML::Node u = YAML::Clone(x), v = YAML::Clone(y);
    std::stringstream path(key);
    for (std::string part; std::getline(path, part, '.');) {
      u.reset(u[part]);
      v.reset(v[part]);
    }
    if (YAML::Dump(u) != YAML::Dump(v)) out.insert(key);
  }
  return out;
}

bool isReloadable(const std::string& key) {
  for (const std::string& r : reloadableConfigKeys())
    if (key == r || key.rfind(r + ".", 0) == 0) return true;
  return false;
}

TEST(ConfigKeys, ReloadTakesExactlyTheReloadableKeys) {
  const Config defaults;
  const Config next = parseConfig(everyKeyChanged(), "every-key.yaml");
  const std::set<std::string> all = keysOf(dumpConfig(defaults));
  const std::set<std::string> changeable = minus(all, {"version"});  // one valid value
  ASSERT_EQ(changedKeys(defaults, next), changeable) << "everyKeyChanged() leaves keys unchanged:"
                                                     << listed(minus(changeable, changedKeys(defaults, next)));
  const Config applied = withReloaded(defaults, next);
  for (const std::string& key : all) {
    const bool tookNext = !changedKeys(applied, next).count(key);
    const bool keptRunning = !changedKeys(applied, defaults).count(key);
    if (isReloadable(key))
      EXPECT_TRUE(tookNext) << key << " is reloadable but kept its running value";
    else
      EXPECT_TRUE(keptRunning) << key << " is not reloadable but took the new value";
  }
}

TEST(ConfigKeys, DocumentedReloadListIsTheReloadableKeys) {
  const std::string text = readFile(kShipped);
  const std::string marker = "# Reloaded on SIGHUP (systemctl reload fusedetd):";
  const auto at = text.find(marker);
  ASSERT_NE(at, std::string::npos) << kShipped << " does not say which keys reload";
  const auto end = text.find(". Other keys", at);
  ASSERT_NE(end, std::string::npos);
  std::string list = text.substr(at + marker.size(), end - at - marker.size());
  std::replace(list.begin(), list.end(), '#', ' ');
  std::replace(list.begin(), list.end(), ',', ' ');
  std::stringstream words(list);
  std::set<std::string> documented;
  for (std::string w; words >> w;) documented.insert(w);
  const std::set<std::string> code(reloadableConfigKeys().begin(), reloadableConfigKeys().end());
  EXPECT_EQ(documented, code) << "documented:" << listed(documented) << "\nreloadableConfigKeys():" << listed(code);
  const std::vector<std::string> known = configKeys();
  for (const std::string& k : code)
    EXPECT_TRUE(std::any_of(known.begin(), known.end(), [&](const std::string& key) {
      return key == k || key.rfind(k + ".", 0) == 0;
    })) << k << " names no config key";
}

}  // namespace
}  // namespace fusedet::daemon
