// SPDX-License-Identifier: Apache-2.0
// Sensor-log channels: base64 vectors (RFC 4648 §10), JSON codecs round trip, malformed input,
// and the Recorder writing a readable log from several threads.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>
#include <thread>

#include "fusedet/drivers/log/base64.h"
#include "fusedet/drivers/log/channels.h"
#include "fusedet/drivers/log/mcap_reader.h"
#include "fusedet/drivers/log/recorder.h"

namespace fs = std::filesystem;
using namespace fusedet;
using namespace fusedet::drivers;
using namespace fusedet::drivers::logs;

namespace {
std::vector<std::uint8_t> bytes(std::string_view s) { return {s.begin(), s.end()}; }
std::span<const std::uint8_t> span(const std::string& s) { return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()}; }
}  // namespace

TEST(Base64, Rfc4648Vectors) {
  const std::pair<const char*, const char*> v[] = {{"", ""},         {"f", "Zg=="},         {"fo", "Zm8="},
                                                   {"foo", "Zm9v"}, {"foob", "Zm9vYg=="}, {"fooba", "Zm9vYmE="},
                                                   {"foobar", "Zm9vYmFy"}};
  for (const auto& [plain, coded] : v) {
    EXPECT_EQ(base64Encode(bytes(plain)), coded);
    ASSERT_TRUE(base64Decode(coded).has_value()) << coded;
    EXPECT_EQ(*base64Decode(coded), bytes(plain));
  }
  for (const char* badText : {"Zg=", "Z===", "Zm9v!A==", "Zg==Zg==", "=Zg=", "Zm=v"}) EXPECT_FALSE(base64Decode(badText)) << badText;
}

TEST(Base64, RandomRoundTrip) {
  std::mt19937 rng(7);
  for (int n = 0; n < 200; ++n) {
    std::vector<std::uint8_t> b(rng() % 100);
    for (auto& x : b) x = static_cast<std::uint8_t>(rng());
    EXPECT_EQ(base64Decode(base64Encode(b)).value(), b);
  }
}

TEST(Channels, SerialAndCanRoundTrip) {
  SerialChunk s{Stamp{1'500'000'123}, "/dev/ttyUSB0", 500000, {0x02, 0x80, 0xFF, 0x00}};
  auto d = decodeSerial(encode(s));
  ASSERT_TRUE(d) << d.error().message();
  EXPECT_EQ(d->stamp, s.stamp);
  EXPECT_EQ(d->device, s.device);
  EXPECT_EQ(d->baud, 500000);
  EXPECT_EQ(d->bytes, s.bytes);
  // the wire form is what docs/log-format.md shows
  const std::vector<std::uint8_t> wire = encode(s);
  EXPECT_EQ(std::string(wire.begin(), wire.end()),
            R"({"baud":500000,"data":"AoD/AA==","device":"/dev/ttyUSB0","timestamp":{"nsec":500000123,"sec":1}})");

  CanMessage c{Stamp{42}, "can0", 0x185, false, false, false, {1, 2, 3, 4}};
  auto dc = decodeCan(encode(c));
  ASSERT_TRUE(dc);
  EXPECT_EQ(dc->id, 0x185u);
  EXPECT_EQ(dc->data, c.data);
  EXPECT_EQ(dc->stamp.ns, 42);
}

TEST(Channels, CameraScanTiltRoundTrip) {
  CameraFrame f;
  f.stamp = Stamp{-5};  // negative stamps survive sec/nsec
  f.sequence = 9;
  f.width = 4;
  f.height = 2;
  f.stride = 8;
  f.format = PixelFormat::kYuyv;
  f.bytes.assign(16, 0x80);
  auto df = decodeCamera(encode(f));
  ASSERT_TRUE(df) << df.error().message();
  EXPECT_EQ(df->stamp.ns, -5);
  EXPECT_EQ(df->format, PixelFormat::kYuyv);
  EXPECT_EQ(df->stride, 8);
  EXPECT_EQ(df->bytes, f.bytes);
  f.format = PixelFormat::kMjpeg;
  EXPECT_EQ(schemaOf(f), Schema::kCompressedImage);
  EXPECT_EQ(decodeCamera(encode(f))->format, PixelFormat::kMjpeg);

  LaserScan s;
  s.stamp = Stamp{123456789};
  s.startAngle = 40 * M_PI / 180;
  s.angleStep = M_PI / 180;
  s.beamDuration = 3.7e-5;
  s.ranges = {1.5f, 0.f, 7.25f};
  s.remissions = {100.f, 0.f, 900.f};
  auto ds = decodeLaserScan(encode(s));
  ASSERT_TRUE(ds);
  EXPECT_NEAR(ds->startAngle, s.startAngle, 1e-12);
  EXPECT_NEAR(ds->angleStep, s.angleStep, 1e-12);
  EXPECT_EQ(ds->ranges, s.ranges);
  EXPECT_EQ(ds->remissions, s.remissions);
  EXPECT_DOUBLE_EQ(ds->beamDuration, s.beamDuration);

  auto dt = decodeTilt(encode(TiltSample{Stamp{77}, 0.25, -0.5}));
  ASSERT_TRUE(dt);
  EXPECT_EQ(dt->angle, 0.25);
  EXPECT_EQ(dt->velocity, -0.5);

  PointCloudMessage pc{Stamp{3}, "laser_base", {{1, 2, 3, 0.5f}, {-1, 0, 2, 1}}};
  auto dp = decodePointCloud(encode(pc));
  ASSERT_TRUE(dp);
  EXPECT_EQ(dp->points, pc.points);
}

// Large payloads skip the JSON lexer (decode lifts the top-level "data" string out); whatever the
// text around it looks like, the result must be what a JSON reader gives: written by hand here,
// not by encode().
TEST(Channels, LargeCameraPayloadsDecodeAsJsonSaysWhateverTheLayout) {
  std::mt19937 rng(7);
  auto frameBytes = [&] {
    std::vector<std::uint8_t> b(64 * 40 * 2);
    for (auto& x : b) x = static_cast<std::uint8_t>(rng());
    return b;
  };
  const std::vector<std::uint8_t> a = frameBytes(), b = frameBytes();
  const std::string a64 = base64Encode(a), b64 = base64Encode(b);
  const std::string head = R"("timestamp":{"sec":3,"nsec":5},"width":64,"height":40,"encoding":"yuyv","step":128)";
  auto decoded = [](const std::string& text) { return decodeCamera(span(text)); };

  for (const std::string& text :
       {"{\"data\":\"" + a64 + "\"," + head + "}",                       // first member, no spaces
        "{ " + head + " ,\n \"data\" :\t \"" + a64 + "\" }",              // last, with white space
        "{" + head + R"(,"frame_id":"data","extra":{"data":"xyz"},"data":")" + a64 + "\"}",  // "data" elsewhere
        "{" + head + R"(,"x":"\"data\":\"AAAA","data":")" + a64 + "\"}"}) {         // inside an escaped string
    auto r = decoded(text);
    ASSERT_TRUE(r) << r.error().message();
    EXPECT_EQ(r->bytes, a);
    EXPECT_EQ(r->width, 64);
    EXPECT_EQ(r->stamp.ns, 3'000'000'005);
  }
  // An escaped '/' is still JSON for '/': the same bytes.
  std::string escaped = a64;
  const std::size_t slash = escaped.find('/');
  ASSERT_NE(slash, std::string::npos);
  escaped.replace(slash, 1, "\\/");
  auto r = decoded("{" + head + ",\"data\":\"" + escaped + "\"}");
  ASSERT_TRUE(r) << r.error().message();
  EXPECT_EQ(r->bytes, a);
  // Duplicate keys: the last one wins, as in the JSON reader.
  r = decoded("{\"data\":\"" + a64 + "\"," + head + ",\"data\":\"" + b64 + "\"}");
  ASSERT_TRUE(r) << r.error().message();
  EXPECT_EQ(r->bytes, b);
  // Not base64, not a string, cut short anywhere: errors naming the message type, no crash.
  std::string bad = a64;
  bad[100] = '!';
  const std::string whole = "{" + head + ",\"data\":\"" + a64 + "\"}";
  std::vector<std::string> broken{"{" + head + ",\"data\":\"" + bad + "\"}", "{" + head + ",\"data\":[\"" + a64 + "\"]}",
                                  "{" + head + ",\"data\":\"" + a64 + "\",}"};
  for (std::size_t cut = 1; cut < whole.size(); cut += 97) broken.push_back(whole.substr(0, cut));
  for (const std::string& text : broken) {
    auto e = decoded(text);
    ASSERT_FALSE(e) << text.substr(0, 80);
    EXPECT_NE(e.error().message().find("camera image"), std::string::npos);
  }
}

TEST(Channels, MalformedMessagesAreErrorsNamingTheProblem) {
  const std::string cases[] = {"", "[]", "{", R"({"timestamp":{"sec":1,"nsec":0}})",
                               R"({"timestamp":{"sec":1,"nsec":0},"device":"x","baud":1,"data":"!!"})",
                               R"({"timestamp":"now","device":"x","baud":1,"data":""})"};
  for (const std::string& c : cases) {
    auto r = decodeSerial(span(c));
    ASSERT_FALSE(r) << c;
    EXPECT_EQ(r.error().code, std::make_error_code(std::errc::bad_message));
    EXPECT_NE(r.error().message().find("fusedet.RawSerial"), std::string::npos);
  }
  const std::string tooLong = R"({"timestamp":{"sec":1,"nsec":0},"interface":"c","id":1,"extended":false,"rtr":false,"error":false,"data":"AAAAAAAAAAAA"})";
  EXPECT_FALSE(decodeCan(span(tooLong)));
  const std::string badId = R"({"timestamp":{"sec":1,"nsec":0},"interface":"c","id":4096,"extended":false,"rtr":false,"error":false,"data":""})";
  EXPECT_FALSE(decodeCan(span(badId)));
  const std::string badEncoding = R"({"timestamp":{"sec":1,"nsec":0},"width":1,"height":1,"encoding":"rgb16","step":6,"data":""})";
  EXPECT_FALSE(decodeCamera(span(badEncoding)));
}

// The arrow of a moving object points along its velocity: the encoded quaternion, applied to +x
// (the arrow's direction in Foxglove) by the rotation formula here, gives velocity / speed; a
// standing object has none; the lifetime and the delete-all come out as sent.
TEST(Channels, SceneUpdateArrowsPointAlongTheVelocity) {
  SceneUpdateMessage m;
  m.stamp = Stamp{12'500'000'000};
  m.lifetimeS = 3.25;
  const std::array<std::array<double, 3>, 5> velocities{{{-2, 0, 0}, {0, 3, 4}, {1, -1, 0.5}, {0.99, 0.001, 0}, {0.01, 0, 0}}};
  for (std::size_t i = 0; i < velocities.size(); ++i)
    m.objects.push_back({"track-" + std::to_string(i), "car", {1.0 * i, 2, 0}, velocities[i], 0.5, {1, 0, 0, 1}, {{"id", std::to_string(i)}}});
  const auto bytes = encode(m);
  const nlohmann::json j = nlohmann::json::parse(bytes.begin(), bytes.end());
  ASSERT_EQ(j.at("deletions").size(), 1u);
  EXPECT_EQ(j["deletions"][0]["type"], 1);  // ALL
  ASSERT_EQ(j.at("entities").size(), velocities.size());
  for (std::size_t i = 0; i < velocities.size(); ++i) {
    const nlohmann::json& e = j["entities"][i];
    EXPECT_EQ(e["lifetime"]["sec"], 3);
    EXPECT_EQ(e["lifetime"]["nsec"], 250'000'000);
    EXPECT_EQ(e["timestamp"]["sec"], 12);
    EXPECT_EQ(e["spheres"][0]["pose"]["position"]["x"].get<double>(), 1.0 * i);
    const auto& v = velocities[i];
    const double speed = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (speed < 0.05) {
      EXPECT_TRUE(e["arrows"].empty()) << i;
      continue;
    }
    ASSERT_EQ(e["arrows"].size(), 1u) << i;
    const nlohmann::json& q = e["arrows"][0]["pose"]["orientation"];
    const double x = q["x"], y = q["y"], z = q["z"], w = q["w"];
    EXPECT_NEAR(x * x + y * y + z * z + w * w, 1.0, 1e-12) << i;
    // R(q) e_x = first column of the rotation matrix
    const double d[3] = {1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y)};
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(d[k], v[static_cast<std::size_t>(k)] / speed, 1e-9) << i << " " << k;
    EXPECT_NEAR(e["arrows"][0]["shaft_length"].get<double>(), speed, 1e-12);
  }
}

TEST(Channels, EverySchemaIsJsonWithItsName) {
  for (Schema s : kAllSchemas) {
    const std::string text(schemaJson(s));
    EXPECT_NE(text.find("\"title\":\"" + std::string(schemaName(s)) + "\""), std::string::npos) << text;
    EXPECT_EQ(schemaByName(schemaName(s)), s);
  }
}

TEST(Recorder, ThreadsWriteOneReadableLog) {
  const fs::path p = fs::temp_directory_path() / ("fusedet_recorder_" + std::to_string(::getpid()) + ".mcap");
  {
    Recorder rec(p, {}, std::chrono::milliseconds(5));
    rec.setRig("version: 1\n", "image_width: 4\n");
    std::thread a([&] {
      for (int i = 0; i < 500; ++i) rec.record(SerialChunk{Stamp{1000 + i}, "lms", 38400, {static_cast<std::uint8_t>(i)}});
    });
    std::thread b([&] {
      for (int i = 0; i < 300; ++i) rec.record(TiltSample{Stamp{1000 + 2 * i}, 0.01 * i, 0});
    });
    a.join();
    b.join();
    rec.close();
    EXPECT_EQ(rec.error(), "");
  }
  mcap::McapReader r(p);
  EXPECT_TRUE(r.index().intact());
  ASSERT_NE(r.index().channel(topic::kLaserRaw), nullptr);
  EXPECT_EQ(r.index().messageCounts.at(r.index().channel(topic::kLaserRaw)->id), 500u);
  EXPECT_EQ(r.index().messageCounts.at(r.index().channel(topic::kTilt)->id), 300u);
  EXPECT_EQ(r.index().findMetadata(kConfigMetadata)->entries.at(kCameraYamlKey), "image_width: 4\n");
  fs::remove(p);
}

TEST(Recorder, UnwritableFileIsAnError) {
  EXPECT_THROW(Recorder("/nonexistent-dir/x.mcap"), mcap::McapError);
}
