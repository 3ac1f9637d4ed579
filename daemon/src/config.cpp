// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/config.h"
#include "fusedet/daemon/config_keys.h"
#include "fusedet/fusion/neural/network.h"
#include "fusedet/daemon/live/listen_address.h"

#include <yaml-cpp/yaml.h>

#include "fusedet/boost/class_detection.h"
#include "fusedet/drivers/usb/usb_match.h"
#include "fusedet/drivers/v4l2/controls.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <type_traits>

namespace fusedet::daemon {
namespace {

// Keys a former release read, with what to do instead: a config written for it fails with this
// hint rather than a bare "unknown key". Matched on the key's last part within its section.
struct RemovedKey {
  const char* section;
  const char* key;
  const char* why;
};
constexpr RemovedKey kRemovedKeys[] = {
    {"detection", "grouping",
     "was removed (commit c0a1fa7): NMS grouping lost to OpenCV's rule on every drive, which fusedetd now always "
     "uses (detection.min_neighbors); delete the key (docs/results/README.md, Options)"},
    {"detection", "nms_iou", "was removed with NMS grouping (commit c0a1fa7); delete the key (docs/results/README.md, Options)"},
};

// Walks one YAML mapping, reads known keys into fields and rejects unknown ones, so a typo in a
// key never silently falls back to a default.
class Section {
 public:
  // keys: when set, every key path read is appended (configKeys()).
  Section(const YAML::Node& node, std::string path, const std::string& source,
          std::vector<std::string>* keys = nullptr)
      : node_(node), path_(std::move(path)), source_(source), keys_(keys) {
    if (node_ && !node_.IsNull() && !node_.IsMap()) fail(node_, "expected a mapping");
  }

  template <class T>
  void read(const char* key, T& out) {
    seen_.insert(key);
    if (keys_) keys_->push_back(keyPath(key));
    if (!node_ || node_.IsNull()) return;
    const YAML::Node v = node_[key];
    if (!v) return;
    try {
      out = v.as<T>();
    } catch (const YAML::Exception&) {
      fail(v, std::string("key ") + keyPath(key) + ": wrong type");
    }
    // yaml-cpp reads .nan and .inf as numbers; no key of this file means either, and a NaN
    // passes every range check (a NaN scale_factor made every stack fail silently).
    if (!finite(out)) fail(v, std::string("key ") + keyPath(key) + ": not a finite number");
  }

  template <class T>
  void readRange(const char* key, T& out, T lo, T hi) {
    read(key, out);
    if (out < lo || out > hi) {
      std::ostringstream msg;
      msg << "key " << keyPath(key) << ": " << out << " is outside [" << lo << ", " << hi << "]";
      fail(node_ ? node_[key] : node_, msg.str());
    }
  }

  template <class T>
  void readOneOf(const char* key, T& out, std::initializer_list<T> allowed) {
    read(key, out);
    for (const T& a : allowed)
      if (a == out) return;
    std::ostringstream msg;
    msg << "key " << keyPath(key) << ": '" << out << "' is not one of:";
    for (const T& a : allowed) msg << ' ' << a;
    fail(node_ ? node_[key] : node_, msg.str());
  }

  // Undefined (false) when the section or key is absent; YAML::Node() would be a defined null
  // (true), and an absent detection section would then clear the built-in detection.classes.
  YAML::Node at(const char* key) const { return node_ && node_.IsMap() ? node_[key] : YAML::Node(YAML::NodeType::Undefined); }

  // The entries of the mapping under `key` (name, its section), in file order; marks `key` read.
  std::vector<std::pair<std::string, Section>> entries(const char* key) {
    seen_.insert(key);
    if (keys_) keys_->push_back(keyPath(key));
    std::vector<std::pair<std::string, Section>> out;
    const YAML::Node n = at(key);
    if (!n || n.IsNull()) return out;
    if (!n.IsMap()) fail(n, "key " + keyPath(key) + ": expected a mapping");
    for (const auto& kv : n) {
      const std::string name = keyName(kv.first, keyPath(key));
      out.emplace_back(name, Section(kv.second, keyPath(key) + "." + name, source_));
    }
    return out;
  }

  Section child(const char* key) {
    seen_.insert(key);
    return Section(node_ && !node_.IsNull() ? node_[key] : YAML::Node(), keyPath(key), source_, keys_);
  }

  // Call after all reads: any key not read is unknown.
  void finish() const {
    if (!node_ || !node_.IsMap()) return;
    for (const auto& kv : node_) {
      const std::string key = keyName(kv.first, path_);
      if (seen_.count(key)) continue;
      for (const RemovedKey& r : kRemovedKeys)
        if (key == r.key && path_.rfind(r.section, 0) == 0) fail(kv.first, "key " + keyPath(key.c_str()) + " " + r.why);
      fail(kv.first, "unknown key " + keyPath(key.c_str()));
    }
  }

  [[noreturn]] void fail(const YAML::Node& at, const std::string& what) const {
    std::ostringstream msg;
    msg << source_;
    if (at && at.Mark().line >= 0) msg << ':' << at.Mark().line + 1;
    msg << ": " << what;
    throw ConfigError(msg.str());
  }

 private:
  std::string keyPath(const char* key) const { return path_.empty() ? key : path_ + "." + key; }

  // A mapping key as a name. YAML allows sequences, mappings and null as keys (`? [a]: 1`);
  // converting one to a string throws a yaml-cpp error, so it is refused here by name.
  std::string keyName(const YAML::Node& key, const std::string& in) const {
    if (!key.IsScalar()) {
      const char* what = key.IsSequence() ? "a sequence" : key.IsMap() ? "a mapping" : "null";
      fail(key, std::string("a key must be a plain name, not ") + what + (in.empty() ? "" : " (in " + in + ")"));
    }
    return key.Scalar();
  }

  template <class T>
  static bool finite(const T& v) {
    if constexpr (std::is_floating_point_v<T>) {
      return std::isfinite(v);
    } else if constexpr (requires { v.begin(); v.end(); } && !std::is_same_v<T, std::string>) {
      for (const auto& e : v)
        if (!finite(e)) return false;
      return true;
    } else {
      return true;
    }
  }

  YAML::Node node_;
  std::string path_;
  const std::string& source_;
  std::vector<std::string>* keys_ = nullptr;
  std::set<std::string> seen_;
};

}  // namespace

std::vector<Config::Detection::ClassSettings> Config::Detection::builtInClasses() {
  std::vector<ClassSettings> out;
  for (const boosting::ClassGrouping& g : boosting::classGroupings(boosting::classesWithOwnDetection()))
    out.push_back({g.className, g.minNeighbors, g.laserExtent});
  return out;
}

namespace {

Config parseTree(const YAML::Node& root, const std::string& source, std::vector<std::string>* keys) {
  Config c;
  Section top(root, "", source, keys);
  top.readRange("version", c.version, 1, 1);
  {
    Section s = top.child("log");
    s.readOneOf<std::string>("level", c.logLevel, {"trace", "debug", "info", "warn", "error"});
    s.finish();
  }
  {
    Section s = top.child("socket");
    s.read("path", c.socket.path);
    s.readRange("max_clients", c.socket.maxClients, 1, 1024);
    s.readRange("max_request_bytes", c.socket.maxRequestBytes, 64, 1 << 20);
    s.readRange("client_queue", c.socket.clientQueue, 1, 1 << 16);
    s.readRange("client_send_buffer", c.socket.clientSendBuffer, 0, 1 << 24);
    s.read("mode", c.socket.mode);
    if (!parseSocketMode(c.socket.mode))
      s.fail(s.at("mode"), "key socket.mode: '" + c.socket.mode + "' is not an octal mode from 0000 to 0777");
    s.read("group", c.socket.group);
    s.read("allow_groups", c.socket.allowGroups);
    s.finish();
  }
  {
    Section s = top.child("laser");
    s.read("device", c.laser.device);
    s.readOneOf("baud", c.laser.baud, {9600, 19200, 38400, 500000});
    s.readOneOf("angle_deg", c.laser.angleDeg, {180, 100});
    s.readOneOf("resolution_deg", c.laser.resolutionDeg, {1.0, 0.5, 0.25});
    if (c.laser.angleDeg == 180 && c.laser.resolutionDeg == 0.25)
      s.fail(YAML::Node(), "laser: resolution_deg 0.25 needs angle_deg 100 (the LMS rejects 180/0.25)");
    s.read("remission", c.laser.remission);
    s.readOneOf<std::string>("range_unit", c.laser.rangeUnit, {"mm", "cm"});
    s.readRange("remission_full_scale", c.laser.remissionFullScale, 1e-3, 1e6);
    s.readRange("reconnect_max_s", c.laser.reconnectMaxS, 0.1, 600.0);
    s.finish();
  }
  {
    Section s = top.child("tilt");
    s.read("interface", c.tilt.interface);
    s.readRange("node_id", c.tilt.nodeId, 1, 127);
    s.readRange("min_deg", c.tilt.minDeg, -90.0, 90.0);
    s.readRange("max_deg", c.tilt.maxDeg, -90.0, 90.0);
    if (c.tilt.minDeg >= c.tilt.maxDeg) s.fail(YAML::Node(), "tilt: min_deg must be below max_deg");
    s.readRange("speed_deg_s", c.tilt.speedDegS, 0.1, 360.0);
    s.readRange("counts_per_rev", c.tilt.countsPerRev, 1, 1 << 24);
    s.readRange("gear_ratio", c.tilt.gearRatio, 1e-3, 1e6);
    s.read("zero_offset_counts", c.tilt.zeroOffsetCounts);
    s.readRange("heartbeat_ms", c.tilt.heartbeatMs, 1, 65535);
    s.finish();
  }
  {
    Section s = top.child("camera");
    s.read("device", c.camera.device);
    s.read("usb", c.camera.usb);
    if (!c.camera.usb.empty())
      if (auto m = drivers::usb::parseUsbMatch(c.camera.usb); !m) s.fail(s.at("usb"), "key camera.usb: " + m.error().context);
    s.readOneOf<std::string>("format", c.camera.format, {"yuyv", "mjpeg", "auto"});
    s.readRange("width", c.camera.width, 16, 8192);
    s.readRange("height", c.camera.height, 16, 8192);
    s.readRange("fps", c.camera.fps, 1, 240);
    s.readRange("buffers", c.camera.buffers, 4, 32);
    for (const auto& [key, value] : {std::pair{"exposure", &c.camera.exposure}, std::pair{"gain", &c.camera.gain}}) {
      s.read(key, *value);
      if (!drivers::v4l2::parseControlSetting(*value))
        s.fail(s.at(key), std::string("key camera.") + key + ": '" + *value + "' is neither auto nor a non-negative integer");
    }
    s.readRange("stall_ms", c.camera.stallMs, 100, 600000);
    s.readRange("reconnect_max_s", c.camera.reconnectMaxS, 0.1, 600.0);
    s.read("calibration", c.camera.calibration);
    s.finish();
  }
  {
    Section s = top.child("fusion");
    Section e = s.child("laser_to_camera");
    e.read("rotation_rpy_deg", c.fusion.rotationRpyDeg);
    e.read("translation", c.fusion.translation);
    e.finish();
    s.read("tilt_axis_offset", c.fusion.tiltAxisOffset);
    s.readRange("laser_layer_scale", c.fusion.laserLayerScale, 0.05, 1.0);
    s.readRange("hole_fill_radius", c.fusion.holeFillRadius, 0, 32);
    s.readRange("max_pair_skew_ms", c.fusion.maxPairSkewMs, 0, 10000);
    s.readRange("tilt_window_ms", c.fusion.tiltWindowMs, 1, 10000);
    s.read("close_on_tilt", c.fusion.closeOnTilt);
    s.finish();
  }
  {
    Section s = top.child("neural");
    s.read("enabled", c.neural.enabled);
    s.readOneOf<std::string>("kind", c.neural.kind, {"darknet", "yolov5-onnx"});
    s.read("files", c.neural.files);
    s.read("directory", c.neural.directory);
    s.read("input", c.neural.input);
    try {
      const cv::Size in = fusion::parseInputSize(c.neural.input);
      if (c.neural.kind == "darknet" && (in.width % 32 || in.height % 32))
        s.fail(s.at("input"), "key neural.input: '" + c.neural.input + "': darknet wants multiples of 32");
    } catch (const std::invalid_argument& e) {
      s.fail(s.at("input"), std::string("key neural.input: ") + e.what());
    }
    s.readRange("scale", c.neural.scale, 0.05, 1.0);
    s.readRange("threads", c.neural.threads, 1, 64);
    s.finish();
  }
  {
    Section s = top.child("detection");
    s.read("models", c.detection.models);
    s.readRange("scale_factor", c.detection.scaleFactor, 1.01, 4.0);
    s.read("min_size", c.detection.minSize);
    s.read("max_size", c.detection.maxSize);
    s.readRange("step", c.detection.step, 0.1, 64.0);
    s.readRange("min_neighbors", c.detection.minNeighbors, 0, 1000);
    s.read("laser_extent", c.detection.laserExtent);
    s.readRange("threads", c.detection.threads, 0, 256);
    const bool classesGiven = bool(s.at("classes"));  // replaces the built-in ones (`classes: {}` = none)
    auto classes = s.entries("classes");
    if (classesGiven) {
      c.detection.classes.clear();
      for (auto& [name, e] : classes) {
        Config::Detection::ClassSettings k{name, c.detection.minNeighbors, c.detection.laserExtent};
        e.readRange("min_neighbors", k.minNeighbors, 0, 1000);
        e.read("laser_extent", k.laserExtent);
        e.finish();
        c.detection.classes.push_back(std::move(k));
      }
    }
    s.finish();
  }
  {
    Section s = top.child("tracking");
    tracking::TrackerParams& t = c.tracking;
    s.readRange("acceleration_sigma", t.noise.accelerationSigma, 1e-3, 1e3);
    s.readRange("measurement_sigma", t.noise.measurementSigma, 1e-3, 1e3);
    s.readRange("initial_velocity_sigma", t.noise.initialVelocitySigma, 1e-3, 1e3);
    s.readRange("gate", t.gate, 1e-3, 1e6);
    s.readRange("birth_hits", t.birthHits, 1, 100);
    s.readRange("birth_window", t.birthWindow, 1, 100);
    if (t.birthWindow < t.birthHits) s.fail(s.at("birth_window"), "key tracking.birth_window: must be >= tracking.birth_hits");
    s.readRange("max_misses", t.maxMisses, 0, 1000);
    s.readRange("max_coast_s", t.maxCoastS, 1e-3, 3600.0);
    s.finish();
  }
  {
    Section s = top.child("live");
    s.read("listen", c.live.listen);
    try {
      (void)live::parseListenAddress(c.live.listen);
    } catch (const std::invalid_argument& e) {
      s.fail(s.at("listen"), std::string("key live.listen: ") + e.what());
    }
    s.read("layers", c.live.layers);
    for (const std::string& name : c.live.layers)
      if (name.empty()) s.fail(s.at("layers"), "key live.layers: an empty layer name");
    s.readRange("max_viewers", c.live.maxViewers, 1, 256);
    s.readRange("viewer_queue_bytes", c.live.viewerQueueBytes, 1 << 20, 1 << 30);
    s.finish();
  }
  {
    Section s = top.child("replay");
    s.read("file", c.replay.file);
    s.read("realtime", c.replay.realtime);
    s.readRange("speed", c.replay.speed, 0.01, 100.0);
    s.read("restamp", c.replay.restamp);
    s.readOneOf<std::string>("at_end", c.replay.atEnd, {"exit", "idle", "loop"});
    if (c.replay.atEnd == "loop" && !c.replay.restamp)
      s.fail(s.at("at_end"), "key replay.at_end: loop needs replay.restamp true (stamps must keep increasing)");
    s.finish();
  }
  top.finish();
  return c;
}

}  // namespace

Config parseConfig(const std::string& yamlText, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(yamlText);
  } catch (const YAML::ParserException& e) {
    throw ConfigError(source + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax: " + e.msg);
  }
  try {
    return parseTree(root, source, nullptr);
  } catch (const YAML::Exception& e) {
    // Every read above turns yaml-cpp's errors into ConfigError; this is the net for a case
    // missed, so that a bad file is a config error (SIGHUP keeps the running config), never a crash.
    throw ConfigError(source + (e.mark.is_null() ? std::string() : ":" + std::to_string(e.mark.line + 1)) + ": " + e.msg);
  }
}

std::vector<std::string> configKeys() {
  std::vector<std::string> keys;
  (void)parseTree(YAML::Node(), "(keys)", &keys);
  return keys;
}

const std::vector<std::string>& reloadableConfigKeys() {
  static const std::vector<std::string> keys{"log.level",           "socket.max_clients",        "socket.max_request_bytes",
                                             "socket.client_queue", "socket.client_send_buffer", "socket.allow_groups",
                                             "detection"};
  return keys;
}

Config withReloaded(const Config& running, const Config& next) {
  YAML::Node out = YAML::Load(dumpConfig(running));
  const YAML::Node in = YAML::Load(dumpConfig(next));
  for (const std::string& key : reloadableConfigKeys()) {
    const auto dot = key.find('.');
    if (dot == std::string::npos) {
      out[key] = YAML::Clone(in[key]);
    } else {
      YAML::Node section = out[key.substr(0, dot)];
      section[key.substr(dot + 1)] = YAML::Clone(in[key.substr(0, dot)][key.substr(dot + 1)]);
    }
  }
  return parseConfig(YAML::Dump(out), "(reloaded configuration)");
}

Config loadConfig(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw ConfigError(file.string() + ": cannot open config file");
  std::stringstream text;
  text << in.rdbuf();
  return parseConfig(text.str(), file.string());
}

std::optional<unsigned> parseSocketMode(const std::string& text) {
  if (text.empty() || text.size() > 4 || text.find_first_not_of("01234567") != std::string::npos) return std::nullopt;
  const auto mode = static_cast<unsigned>(std::stoul(text, nullptr, 8));
  if (mode > 0777u) return std::nullopt;
  return mode;
}

std::filesystem::path installedConfigFile(const std::filesystem::path& executable) {
  const std::filesystem::path prefix = executable.parent_path().parent_path();
  const std::filesystem::path etc = prefix == "/usr" ? std::filesystem::path("/etc") : prefix / "etc";
  return etc / "fusedet" / "fusedet.yaml";
}

namespace {

// yaml-cpp's emitter writes a string holding control characters (a run of carriage returns, say)
// as a plain scalar, which does not read back the same: such strings are written double-quoted
// (escaped), every other value as the emitter chooses. Found by fuzzing (tests/fuzz/config_yaml).
struct Text {
  const std::string& value;
};
Text text(const std::string& value) { return {value}; }
template <class T>
const T& text(const T& value) {
  return value;
}
YAML::Emitter& operator<<(YAML::Emitter& out, Text t) {
  const bool control = std::any_of(t.value.begin(), t.value.end(), [](char ch) {
    const auto u = static_cast<unsigned char>(ch);
    return u < 0x20 || u == 0x7f;
  });
  if (control) out << YAML::DoubleQuoted;
  return out << t.value;
}

}  // namespace

std::string dumpConfig(const Config& c) {
  YAML::Emitter out;
  auto seq = [&out](const auto& values) {
    out << YAML::Flow << YAML::BeginSeq;
    for (const auto& v : values) out << text(v);
    out << YAML::EndSeq;
  };
  out << YAML::BeginMap;
  out << YAML::Key << "version" << YAML::Value << c.version;
  out << YAML::Key << "log" << YAML::Value << YAML::BeginMap << YAML::Key << "level" << YAML::Value
      << text(c.logLevel) << YAML::EndMap;
  out << YAML::Key << "socket" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "path" << YAML::Value << text(c.socket.path);
  out << YAML::Key << "max_clients" << YAML::Value << c.socket.maxClients;
  out << YAML::Key << "max_request_bytes" << YAML::Value << c.socket.maxRequestBytes;
  out << YAML::Key << "client_queue" << YAML::Value << c.socket.clientQueue;
  out << YAML::Key << "client_send_buffer" << YAML::Value << c.socket.clientSendBuffer;
  out << YAML::Key << "mode" << YAML::Value << YAML::DoubleQuoted << c.socket.mode;
  out << YAML::Key << "group" << YAML::Value << YAML::DoubleQuoted << c.socket.group;
  out << YAML::Key << "allow_groups" << YAML::Value;
  seq(c.socket.allowGroups);
  out << YAML::EndMap;
  out << YAML::Key << "laser" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "device" << YAML::Value << text(c.laser.device);
  out << YAML::Key << "baud" << YAML::Value << c.laser.baud;
  out << YAML::Key << "angle_deg" << YAML::Value << c.laser.angleDeg;
  out << YAML::Key << "resolution_deg" << YAML::Value << c.laser.resolutionDeg;
  out << YAML::Key << "remission" << YAML::Value << c.laser.remission;
  out << YAML::Key << "range_unit" << YAML::Value << text(c.laser.rangeUnit);
  out << YAML::Key << "remission_full_scale" << YAML::Value << c.laser.remissionFullScale;
  out << YAML::Key << "reconnect_max_s" << YAML::Value << c.laser.reconnectMaxS << YAML::EndMap;
  out << YAML::Key << "tilt" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "interface" << YAML::Value << text(c.tilt.interface);
  out << YAML::Key << "node_id" << YAML::Value << c.tilt.nodeId;
  out << YAML::Key << "min_deg" << YAML::Value << c.tilt.minDeg;
  out << YAML::Key << "max_deg" << YAML::Value << c.tilt.maxDeg;
  out << YAML::Key << "speed_deg_s" << YAML::Value << c.tilt.speedDegS;
  out << YAML::Key << "counts_per_rev" << YAML::Value << c.tilt.countsPerRev;
  out << YAML::Key << "gear_ratio" << YAML::Value << c.tilt.gearRatio;
  out << YAML::Key << "zero_offset_counts" << YAML::Value << c.tilt.zeroOffsetCounts;
  out << YAML::Key << "heartbeat_ms" << YAML::Value << c.tilt.heartbeatMs << YAML::EndMap;
  out << YAML::Key << "camera" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "device" << YAML::Value << text(c.camera.device);
  out << YAML::Key << "usb" << YAML::Value << text(c.camera.usb);
  out << YAML::Key << "format" << YAML::Value << text(c.camera.format);
  out << YAML::Key << "width" << YAML::Value << c.camera.width;
  out << YAML::Key << "height" << YAML::Value << c.camera.height;
  out << YAML::Key << "fps" << YAML::Value << c.camera.fps;
  out << YAML::Key << "buffers" << YAML::Value << c.camera.buffers;
  out << YAML::Key << "exposure" << YAML::Value << text(c.camera.exposure);
  out << YAML::Key << "gain" << YAML::Value << text(c.camera.gain);
  out << YAML::Key << "stall_ms" << YAML::Value << c.camera.stallMs;
  out << YAML::Key << "reconnect_max_s" << YAML::Value << c.camera.reconnectMaxS;
  out << YAML::Key << "calibration" << YAML::Value << text(c.camera.calibration) << YAML::EndMap;
  out << YAML::Key << "fusion" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "laser_to_camera" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "rotation_rpy_deg" << YAML::Value;
  seq(c.fusion.rotationRpyDeg);
  out << YAML::Key << "translation" << YAML::Value;
  seq(c.fusion.translation);
  out << YAML::EndMap;
  out << YAML::Key << "tilt_axis_offset" << YAML::Value;
  seq(c.fusion.tiltAxisOffset);
  out << YAML::Key << "laser_layer_scale" << YAML::Value << c.fusion.laserLayerScale;
  out << YAML::Key << "hole_fill_radius" << YAML::Value << c.fusion.holeFillRadius;
  out << YAML::Key << "max_pair_skew_ms" << YAML::Value << c.fusion.maxPairSkewMs;
  out << YAML::Key << "tilt_window_ms" << YAML::Value << c.fusion.tiltWindowMs;
  out << YAML::Key << "close_on_tilt" << YAML::Value << c.fusion.closeOnTilt << YAML::EndMap;
  out << YAML::Key << "neural" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "enabled" << YAML::Value << c.neural.enabled;
  out << YAML::Key << "kind" << YAML::Value << text(c.neural.kind);
  out << YAML::Key << "files" << YAML::Value;
  seq(c.neural.files);
  out << YAML::Key << "directory" << YAML::Value << text(c.neural.directory);
  out << YAML::Key << "input" << YAML::Value << text(c.neural.input);
  out << YAML::Key << "scale" << YAML::Value << c.neural.scale;
  out << YAML::Key << "threads" << YAML::Value << c.neural.threads << YAML::EndMap;
  out << YAML::Key << "detection" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "models" << YAML::Value;
  seq(c.detection.models);
  out << YAML::Key << "scale_factor" << YAML::Value << c.detection.scaleFactor;
  out << YAML::Key << "min_size" << YAML::Value;
  seq(c.detection.minSize);
  out << YAML::Key << "max_size" << YAML::Value;
  seq(c.detection.maxSize);
  out << YAML::Key << "step" << YAML::Value << c.detection.step;
  out << YAML::Key << "min_neighbors" << YAML::Value << c.detection.minNeighbors;
  out << YAML::Key << "laser_extent" << YAML::Value << c.detection.laserExtent;
  out << YAML::Key << "threads" << YAML::Value << c.detection.threads;
  out << YAML::Key << "classes" << YAML::Value << YAML::BeginMap;
  for (const auto& k : c.detection.classes)
    out << YAML::Key << text(k.name) << YAML::Value << YAML::BeginMap << YAML::Key << "min_neighbors" << YAML::Value
        << k.minNeighbors << YAML::Key << "laser_extent" << YAML::Value << k.laserExtent << YAML::EndMap;
  out << YAML::EndMap << YAML::EndMap;
  out << YAML::Key << "tracking" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "acceleration_sigma" << YAML::Value << c.tracking.noise.accelerationSigma;
  out << YAML::Key << "measurement_sigma" << YAML::Value << c.tracking.noise.measurementSigma;
  out << YAML::Key << "initial_velocity_sigma" << YAML::Value << c.tracking.noise.initialVelocitySigma;
  out << YAML::Key << "gate" << YAML::Value << c.tracking.gate;
  out << YAML::Key << "birth_hits" << YAML::Value << c.tracking.birthHits;
  out << YAML::Key << "birth_window" << YAML::Value << c.tracking.birthWindow;
  out << YAML::Key << "max_misses" << YAML::Value << c.tracking.maxMisses;
  out << YAML::Key << "max_coast_s" << YAML::Value << c.tracking.maxCoastS << YAML::EndMap;
  out << YAML::Key << "live" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "listen" << YAML::Value << YAML::DoubleQuoted << c.live.listen;
  out << YAML::Key << "layers" << YAML::Value;
  seq(c.live.layers);
  out << YAML::Key << "max_viewers" << YAML::Value << c.live.maxViewers;
  out << YAML::Key << "viewer_queue_bytes" << YAML::Value << c.live.viewerQueueBytes << YAML::EndMap;
  out << YAML::Key << "replay" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "file" << YAML::Value << text(c.replay.file);
  out << YAML::Key << "realtime" << YAML::Value << c.replay.realtime;
  out << YAML::Key << "speed" << YAML::Value << c.replay.speed;
  out << YAML::Key << "restamp" << YAML::Value << c.replay.restamp;
  out << YAML::Key << "at_end" << YAML::Value << text(c.replay.atEnd) << YAML::EndMap;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace fusedet::daemon
