// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/config.h"
#include "fusedet/daemon/rig.h"

#include <gtest/gtest.h>

#include <filesystem>

using namespace fusedet::daemon;

namespace {
std::string errorOf(const std::string& yaml) {
  try {
    (void)parseConfig(yaml, "test.yaml");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Config, ShippedFileParsesAndEqualsTheDefaults) {
  const Config shipped = loadConfig(std::string(FUSEDET_SOURCE_DIR) + "/config/fusedet.yaml");
  // The documented file and the built-in defaults must not drift apart.
  EXPECT_EQ(dumpConfig(shipped), dumpConfig(Config{}));
  EXPECT_EQ(shipped.laser.baud, 38400);
}

TEST(Config, EmptyFileGivesDefaultsAndDumpRoundTrips) {
  const Config c = parseConfig("", "empty.yaml");
  // every key at its default, the built-in detection.classes too (a sensor log's rig has no
  // detection section: its car was detected with 3 neighbours instead of 16 before)
  EXPECT_EQ(dumpConfig(c), dumpConfig(Config{}));
  ASSERT_EQ(c.detection.classes.size(), 1u);
  EXPECT_EQ(c.detection.classes[0].minNeighbors, 16);
  EXPECT_EQ(dumpConfig(parseConfig("version: 1\nlaser:\n  baud: 500000\n", "rig.yaml")).find("classes:\n    {}"), std::string::npos);
  EXPECT_EQ(c.socket.path, "/run/fusedet/fusedet.sock");
  Config changed = c;
  changed.laser.baud = 500000;
  changed.detection.models = {"a.yaml", "b.yaml"};
  const Config back = parseConfig(dumpConfig(changed), "dump.yaml");
  EXPECT_EQ(back.laser.baud, 500000);
  EXPECT_EQ(back.detection.models, changed.detection.models);
}

// A config written for a release that had NMS grouping names the removed keys and what to do.
TEST(Config, RemovedKeysSayTheyWereRemovedAndWhatToDo) {
  const std::string grouping = errorOf("detection:\n  min_neighbors: 3\n  grouping: nms\n");
  EXPECT_EQ(grouping.rfind("test.yaml:3: key detection.grouping was removed (commit c0a1fa7)", 0), 0u) << grouping;
  EXPECT_NE(grouping.find("delete the key"), std::string::npos) << grouping;
  const std::string perClass = errorOf("detection:\n  classes:\n    car:\n      nms_iou: 0.4\n");
  EXPECT_EQ(perClass.rfind("test.yaml:4: key detection.classes.car.nms_iou was removed", 0), 0u) << perClass;
  // Only in the section that had it: elsewhere the same name is just unknown.
  EXPECT_EQ(errorOf("tracking:\n  grouping: 1\n"), "test.yaml:2: unknown key tracking.grouping");
}

TEST(Config, ErrorsNameFileLineAndKey) {
  EXPECT_EQ(errorOf("laser:\n  baud: 12345\n"),
            "test.yaml:2: key laser.baud: '12345' is not one of: 9600 19200 38400 500000");
  EXPECT_EQ(errorOf("laser:\n  bauds: 9600\n"), "test.yaml:2: unknown key laser.bauds");
  EXPECT_EQ(errorOf("tilt:\n  node_id: abc\n"), "test.yaml:2: key tilt.node_id: wrong type");
  EXPECT_EQ(errorOf("tilt:\n  node_id: 200\n"), "test.yaml:2: key tilt.node_id: 200 is outside [1, 127]");
  EXPECT_NE(errorOf("laser: [1, 2\n").find("YAML syntax"), std::string::npos);
  EXPECT_NE(errorOf("laser: 5\n").find("expected a mapping"), std::string::npos);
  EXPECT_NE(errorOf("laser:\n  resolution_deg: 0.25\n").find("needs angle_deg 100"), std::string::npos);
  EXPECT_NE(errorOf("tilt:\n  min_deg: 10\n  max_deg: 5\n").find("min_deg must be below"), std::string::npos);
}

// Issue 37: a complex key (a sequence or mapping as key) was a yaml-cpp conversion error that
// nothing caught (SIGHUP and --check-config ended in std::terminate), and `.nan` passed every
// range check. Both are config errors naming the file, line and key.
TEST(Config, ComplexKeysAndNonFiniteNumbersAreConfigErrors) {
  EXPECT_EQ(errorOf("? [a]: 1\n"), "test.yaml:1: a key must be a plain name, not a mapping");
  EXPECT_EQ(errorOf("[a]: 1\n"), "test.yaml:1: a key must be a plain name, not a sequence");
  EXPECT_EQ(errorOf("laser:\n  ? {x: 1}\n  : 2\n"), "test.yaml:2: a key must be a plain name, not a mapping (in laser)");
  EXPECT_EQ(errorOf("detection:\n  classes:\n    ? [car]\n    : {min_neighbors: 2}\n"),
            "test.yaml:3: a key must be a plain name, not a sequence (in detection.classes)");
  EXPECT_EQ(errorOf("detection:\n  scale_factor: .nan\n"), "test.yaml:2: key detection.scale_factor: not a finite number");
  EXPECT_EQ(errorOf("detection:\n  step: .inf\n"), "test.yaml:2: key detection.step: not a finite number");
  EXPECT_EQ(errorOf("fusion:\n  tilt_axis_offset: [0, .nan, 0.05]\n"),
            "test.yaml:2: key fusion.tilt_axis_offset: not a finite number");
  EXPECT_EQ(errorOf("fusion:\n  laser_to_camera:\n    translation: [-.inf, 0, 0]\n"),
            "test.yaml:3: key fusion.laser_to_camera.translation: not a finite number");
}

TEST(Config, SocketAccessKeys) {
  const Config c = parseConfig("socket:\n  mode: \"0640\"\n  group: robots\n  allow_groups: [robots, ops]\n", "t.yaml");
  EXPECT_EQ(parseSocketMode(c.socket.mode), 0640u);
  EXPECT_EQ(c.socket.group, "robots");
  EXPECT_EQ(c.socket.allowGroups, (std::vector<std::string>{"robots", "ops"}));
  EXPECT_EQ(parseConfig(dumpConfig(c), "dump.yaml").socket.allowGroups, c.socket.allowGroups);
  EXPECT_EQ(parseSocketMode(parseConfig(dumpConfig(c), "dump.yaml").socket.mode), 0640u);
  EXPECT_EQ(errorOf("socket:\n  mode: \"0999\"\n"),
            "test.yaml:2: key socket.mode: '0999' is not an octal mode from 0000 to 0777");
  EXPECT_NE(errorOf("socket:\n  mode: \"17777\"\n").find("not an octal mode"), std::string::npos);
  EXPECT_EQ(errorOf("socket:\n  allow_groups: robots\n"), "test.yaml:2: key socket.allow_groups: wrong type");
}

TEST(Config, CameraKeys) {
  const Config c = parseConfig("camera:\n  usb: 046d:0825:ABC\n  format: auto\n  exposure: 8000\n  gain: auto\n  buffers: 6\n",
                               "cam.yaml");
  EXPECT_EQ(c.camera.usb, "046d:0825:ABC");
  EXPECT_EQ(c.camera.format, "auto");
  EXPECT_EQ(c.camera.exposure, "8000");
  EXPECT_EQ(c.camera.buffers, 6);
  const Config back = parseConfig(dumpConfig(c), "dump.yaml");
  EXPECT_EQ(back.camera.exposure, "8000");
  EXPECT_EQ(back.camera.usb, "046d:0825:ABC");
  EXPECT_EQ(errorOf("camera:\n  exposure: fast\n"),
            "test.yaml:2: key camera.exposure: 'fast' is neither auto nor a non-negative integer");
  EXPECT_EQ(errorOf("camera:\n  gain: -3\n"), "test.yaml:2: key camera.gain: '-3' is neither auto nor a non-negative integer");
  EXPECT_EQ(errorOf("camera:\n  buffers: 2\n"), "test.yaml:2: key camera.buffers: 2 is outside [4, 32]");
  EXPECT_NE(errorOf("camera:\n  usb: '0403'\n").find("test.yaml:2: key camera.usb: USB device '0403': no ':'"),
            std::string::npos);
  EXPECT_NE(errorOf("camera:\n  format: rgb\n").find("is not one of: yuyv mjpeg auto"), std::string::npos);
}

TEST(Config, ReplayKeys) {
  const Config c = parseConfig("replay:\n  file: run.mcap\n  realtime: false\n  speed: 2.5\n  at_end: exit\n", "r.yaml");
  EXPECT_EQ(c.replay.file, "run.mcap");
  EXPECT_FALSE(c.replay.realtime);
  EXPECT_EQ(c.replay.speed, 2.5);
  EXPECT_TRUE(c.replay.restamp);
  EXPECT_EQ(c.replay.atEnd, "exit");
  const Config back = parseConfig(dumpConfig(c), "dump.yaml");
  EXPECT_EQ(back.replay.speed, 2.5);
  EXPECT_EQ(back.replay.atEnd, "exit");
  EXPECT_NE(errorOf("replay:\n  at_end: stop\n").find("test.yaml:2: key replay.at_end: 'stop' is not one of: exit idle loop"),
            std::string::npos);
  EXPECT_EQ(errorOf("replay:\n  restamp: false\n  at_end: loop\n"),
            "test.yaml:3: key replay.at_end: loop needs replay.restamp true (stamps must keep increasing)");
  EXPECT_EQ(errorOf("replay:\n  speed: 0\n"), "test.yaml:2: key replay.speed: 0 is outside [0.01, 100]");
}

TEST(Config, CloseOnTiltReachesTheSweepAssembly) {
  EXPECT_TRUE(sweepConfig(Config{}).closeOnTilt);
  const Config off = parseConfig("fusion:\n  close_on_tilt: false\n", "f.yaml");
  EXPECT_FALSE(sweepConfig(off).closeOnTilt);
  EXPECT_FALSE(parseConfig(dumpConfig(off), "dump.yaml").fusion.closeOnTilt);
  EXPECT_NE(errorOf("fusion:\n  close_on_tilt: maybe\n").find("test.yaml:2"), std::string::npos);
}

TEST(Config, DemoFileLoadsAndNamesTheBundledModels) {
  const std::filesystem::path dir = std::filesystem::path(FUSEDET_SOURCE_DIR) / "config";
  const Config demo = loadConfig(dir / "demo.yaml");
  EXPECT_EQ(demo.replay.file, "../build/logs/demo.mcap");
  EXPECT_EQ(demo.replay.atEnd, "exit");
  ASSERT_EQ(demo.detection.models.size(), 3u);
  for (const auto& m : demo.detection.models) EXPECT_TRUE(std::filesystem::exists(dir / m)) << m;
}

TEST(Config, MissingFile) {
  EXPECT_THROW((void)loadConfig("/nonexistent/fusedet.yaml"), ConfigError);
}

TEST(Config, InstalledConfigFileFollowsThePrefixAndTheFhsRuleForUsr) {
  EXPECT_EQ(installedConfigFile("/usr/bin/fusedetd"), "/etc/fusedet/fusedet.yaml");
  EXPECT_EQ(installedConfigFile("/usr/local/bin/fusedetd"), "/usr/local/etc/fusedet/fusedet.yaml");
  EXPECT_EQ(installedConfigFile("/opt/robot/bin/fusedetd"), "/opt/robot/etc/fusedet/fusedet.yaml");
}

TEST(Config, TrackingKeysRoundTripAndAreChecked) {
  const Config c = parseConfig("tracking:\n  gate: 9.0\n  birth_hits: 3\n  birth_window: 5\n  max_misses: 1\n  max_coast_s: 0.5\n"
                               "  acceleration_sigma: 1.5\n  measurement_sigma: 0.3\n  initial_velocity_sigma: 4\n",
                               "t.yaml");
  EXPECT_EQ(c.tracking.gate, 9.0);
  EXPECT_EQ(c.tracking.birthHits, 3);
  EXPECT_EQ(c.tracking.birthWindow, 5);
  EXPECT_EQ(c.tracking.maxMisses, 1);
  EXPECT_EQ(c.tracking.maxCoastS, 0.5);
  EXPECT_EQ(c.tracking.noise.accelerationSigma, 1.5);
  EXPECT_EQ(c.tracking.noise.measurementSigma, 0.3);
  EXPECT_EQ(c.tracking.noise.initialVelocitySigma, 4.0);
  const Config back = parseConfig(dumpConfig(c), "dump.yaml");
  EXPECT_EQ(dumpConfig(back), dumpConfig(c));
  EXPECT_EQ(errorOf("tracking:\n  birth_hits: 4\n  birth_window: 3\n"),
            "test.yaml:3: key tracking.birth_window: must be >= tracking.birth_hits");
  EXPECT_EQ(errorOf("tracking:\n  gates: 3\n"), "test.yaml:2: unknown key tracking.gates");
  EXPECT_EQ(errorOf("tracking:\n  gate: -1\n"), "test.yaml:2: key tracking.gate: -1 is outside [0.001, 1e+06]");
}

// Found by fuzzing: a value ending in carriage returns was dumped as a plain scalar and read back
// one shorter (the reload's merge and --dump-config go through the dump).
TEST(Config, ADumpedStringWithControlCharactersReadsBackTheSame) {
  const Config c = parseConfig("replay:\n  file: \"log.mcap\\r\\r\"\nlaser:\n  device: \"/dev/tty\\tUSB0\"\n", "t.yaml");
  EXPECT_EQ(c.replay.file, "log.mcap\r\r");
  EXPECT_EQ(c.laser.device, "/dev/tty\tUSB0");
  const Config back = parseConfig(dumpConfig(c), "dump.yaml");
  EXPECT_EQ(back.replay.file, c.replay.file);
  EXPECT_EQ(back.laser.device, c.laser.device);
  EXPECT_EQ(dumpConfig(back), dumpConfig(c));
}
