// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/log/channels.h"

#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <optional>
#include <string_view>
#include <utility>

#include "fusedet/drivers/log/base64.h"

namespace fusedet::drivers::logs {

using nlohmann::json;

namespace {

// Schema texts: written for fusedet from the field lists of docs/log-format.md; the foxglove.*
// ones carry the fields Foxglove's viewers read (extra fusedet fields are allowed by JSON Schema).
constexpr char kTimeProp[] = R"("timestamp":{"type":"object","properties":{"sec":{"type":"integer"},"nsec":{"type":"integer"}}})";
constexpr char kVec3[] = R"({"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}}})";
constexpr char kQuat[] = R"({"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"},"w":{"type":"number"}}})";

std::string object(const std::string& title, const std::string& props) {
  return R"({"title":")" + title + R"(","type":"object","properties":{)" + kTimeProp + "," + props + "}}";
}
std::string pose() { return std::string(R"("pose":{"type":"object","properties":{"position":)") + kVec3 + R"(,"orientation":)" + kQuat + "}}"; }
const std::string kBytes = R"({"type":"string","contentEncoding":"base64"})";
const std::string kNumberArray = R"({"type":"array","items":{"type":"number"}})";
const std::string kColor = R"({"type":"object","properties":{"r":{"type":"number"},"g":{"type":"number"},"b":{"type":"number"},"a":{"type":"number"}}})";

const std::string& schemaText(Schema s) {
  static const std::string texts[] = {
      object("fusedet.RawSerial", R"("device":{"type":"string"},"baud":{"type":"integer"},"data":)" + kBytes),
      object("fusedet.CanFrame", R"("interface":{"type":"string"},"id":{"type":"integer"},"extended":{"type":"boolean"},)"
                                 R"("rtr":{"type":"boolean"},"error":{"type":"boolean"},"data":)" + kBytes),
      object("foxglove.RawImage", R"("frame_id":{"type":"string"},"width":{"type":"integer"},"height":{"type":"integer"},)"
                                  R"("encoding":{"type":"string"},"step":{"type":"integer"},"sequence":{"type":"integer"},"data":)" + kBytes),
      object("foxglove.CompressedImage", R"("frame_id":{"type":"string"},"format":{"type":"string"},"width":{"type":"integer"},)"
                                         R"("height":{"type":"integer"},"sequence":{"type":"integer"},"data":)" + kBytes),
      object("foxglove.LaserScan", R"("frame_id":{"type":"string"},)" + pose() + R"(,"start_angle":{"type":"number"},)"
                                   R"("end_angle":{"type":"number"},"ranges":)" + kNumberArray + R"(,"intensities":)" + kNumberArray +
                                   R"(,"sequence":{"type":"integer"},"beam_duration":{"type":"number"},"status":{"type":"integer"})"),
      object("fusedet.TiltSample", R"("angle":{"type":"number"},"velocity":{"type":"number"})"),
      object("foxglove.PointCloud", R"("frame_id":{"type":"string"},)" + pose() + R"(,"point_stride":{"type":"integer"},)"
                                    R"("fields":{"type":"array","items":{"type":"object","properties":{"name":{"type":"string"},)"
                                    R"("offset":{"type":"integer"},"type":{"type":"integer"}}}},"data":)" + kBytes),
      R"({"title":"foxglove.ImageAnnotations","type":"object","properties":{)" + std::string(kTimeProp) + R"(,"circles":{"type":"array"},)"
      R"("points":{"type":"array","items":{"type":"object","properties":{)" + std::string(kTimeProp) +
          R"(,"type":{"type":"integer"},"points":{"type":"array","items":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"}}}},)"
          R"("outline_color":)" + kColor + R"(,"outline_colors":{"type":"array","items":)" + kColor + R"(},"fill_color":)" + kColor +
          R"(,"thickness":{"type":"number"}}}},)"
          R"("texts":{"type":"array","items":{"type":"object","properties":{)" + std::string(kTimeProp) +
          R"(,"position":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"}}},"text":{"type":"string"},)"
          R"("font_size":{"type":"number"},"text_color":)" + kColor + R"(,"background_color":)" + kColor + "}}}}}",
      std::string(R"({"title":"foxglove.FrameTransform","type":"object","properties":{)") + kTimeProp +
          R"(,"parent_frame_id":{"type":"string"},"child_frame_id":{"type":"string"},"translation":)" + kVec3 +
          R"(,"rotation":)" + kQuat + "}}",
      object("foxglove.CameraCalibration", R"("frame_id":{"type":"string"},"width":{"type":"integer"},"height":{"type":"integer"},)"
                                           R"("distortion_model":{"type":"string"},"D":)" + kNumberArray + R"(,"K":)" + kNumberArray +
                                           R"(,"R":)" + kNumberArray + R"(,"P":)" + kNumberArray),
      object("fusedet.Tracks", R"("type":{"type":"string"},"stack":{"type":"integer"},"frame_ns":{"type":"integer"},)"
                               R"("sensor_ns":{"type":"integer"},"detected_ns":{"type":"integer"},"tracks":{"type":"array","items":)"
                               R"({"type":"object","properties":{"id":{"type":"integer"},"class":{"type":"string"},)"
                               R"("confirmed":{"type":"boolean"},"coasting":{"type":"boolean"},"robot":)" + kNumberArray +
                               R"(,"velocity":)" + kNumberArray + R"(,"sigma":{"type":"number"},"age":{"type":"number"},)"
                               R"("hits":{"type":"integer"},"misses":{"type":"integer"},"box":)" + kNumberArray + "}}}"),
      std::string(R"({"title":"foxglove.SceneUpdate","type":"object","properties":{"deletions":{"type":"array","items":{"type":"object","properties":{)") +
          kTimeProp + R"(,"type":{"type":"integer"},"id":{"type":"string"}}}},"entities":{"type":"array","items":{"type":"object","properties":{)" +
          kTimeProp + R"(,"frame_id":{"type":"string"},"id":{"type":"string"},"lifetime":{"type":"object","properties":{"sec":{"type":"integer"},)"
          R"("nsec":{"type":"integer"}}},"frame_locked":{"type":"boolean"},"metadata":{"type":"array","items":{"type":"object",)"
          R"("properties":{"key":{"type":"string"},"value":{"type":"string"}}}},)"
          R"("spheres":{"type":"array","items":{"type":"object","properties":{)" + pose() + R"(,"size":)" + kVec3 + R"(,"color":)" + kColor + "}}},"
          R"("arrows":{"type":"array","items":{"type":"object","properties":{)" + pose() + R"(,"shaft_length":{"type":"number"},)"
          R"("shaft_diameter":{"type":"number"},"head_length":{"type":"number"},"head_diameter":{"type":"number"},"color":)" + kColor + "}}},"
          R"("texts":{"type":"array","items":{"type":"object","properties":{)" + pose() + R"(,"billboard":{"type":"boolean"},)"
          R"("font_size":{"type":"number"},"scale_invariant":{"type":"boolean"},"color":)" + kColor + R"(,"text":{"type":"string"}}}},)"
          R"("cubes":{"type":"array","items":{"type":"object","properties":{)" + pose() + R"(,"size":)" + kVec3 + R"(,"color":)" + kColor + "}}},"
          R"("cylinders":{"type":"array"},"lines":{"type":"array"},"triangles":{"type":"array"},"models":{"type":"array"}}}}}})",
  };
  return texts[static_cast<int>(s)];
}

json timestamp(Stamp s) {
  const SecNsec t = secNsec(s);
  return json{{"sec", t.sec}, {"nsec", t.nsec}};
}

std::vector<std::uint8_t> bytesOf(const json& j) {
  const std::string s = j.dump();
  return {s.begin(), s.end()};
}

Error bad(const std::string& what) { return makeError(std::errc::bad_message, what); }

// Where the string value of the top-level member "data" lies in a message: [begin, end) between
// its quotes. Empty if there is none, or more than one, or the text is not plain JSON around it.
std::optional<std::pair<std::size_t, std::size_t>> findTopLevelData(std::span<const std::uint8_t> b) {
  std::optional<std::pair<std::size_t, std::size_t>> found;
  const auto skipSpace = [&](std::size_t i) {
    while (i < b.size() && (b[i] == ' ' || b[i] == '\t' || b[i] == '\n' || b[i] == '\r')) ++i;
    return i;
  };
  int depth = 0;
  for (std::size_t i = 0; i < b.size(); ++i) {
    const std::uint8_t c = b[i];
    if (c == '{' || c == '[') {
      ++depth;
    } else if (c == '}' || c == ']') {
      --depth;
    } else if (c == '"') {
      const std::size_t start = i + 1;
      for (++i; i < b.size() && b[i] != '"'; ++i)
        if (b[i] == '\\') ++i;  // an escaped character, maybe a quote
      if (i >= b.size()) return std::nullopt;
      if (depth != 1 || i - start != 4 || std::memcmp(&b[start], "data", 4) != 0) continue;
      std::size_t v = skipSpace(i + 1);
      if (v >= b.size() || b[v] != ':') continue;  // "data" as a value, not a key
      v = skipSpace(v + 1);
      if (v >= b.size() || b[v] != '"' || found) return std::nullopt;  // not a string, or a second "data"
      const auto* quote = static_cast<const std::uint8_t*>(std::memchr(b.data() + v + 1, '"', b.size() - v - 1));
      if (!quote) return std::nullopt;
      const std::size_t end = static_cast<std::size_t>(quote - b.data());
      if (std::memchr(b.data() + v + 1, '\\', end - v - 1)) return std::nullopt;  // escapes: not plain base64
      found = std::make_pair(v + 1, end);
      i = end;
    }
  }
  return found;
}

// A message with a large base64 payload (a camera frame: ~1.2 MB in "data") parsed without
// running that payload through the JSON lexer, which copies it a character at a time - most of
// a replay's CPU time before. The rest of the message is parsed as usual and the payload,
// decoded straight from the message bytes, becomes a binary value (dataOf reads both kinds).
// Anything unusual returns nothing and is left to the ordinary parse, which gives the same
// result or the same error.
std::optional<json> parseLiftingData(std::span<const std::uint8_t> bytes) {
  constexpr std::size_t kWorthIt = 4096;  // small messages: the ordinary parse is as fast
  if (bytes.size() < kWorthIt) return std::nullopt;
  const auto data = findTopLevelData(bytes);
  if (!data || data->second - data->first < kWorthIt / 2) return std::nullopt;
  auto payload = base64Decode(std::string_view(reinterpret_cast<const char*>(bytes.data()) + data->first,
                                               data->second - data->first));
  if (!payload) return std::nullopt;
  std::vector<std::uint8_t> rest(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(data->first));
  rest.insert(rest.end(), bytes.begin() + static_cast<std::ptrdiff_t>(data->second), bytes.end());
  json j = json::parse(rest.begin(), rest.end(), nullptr, false);
  // The member left behind must be the emptied "data" (a later duplicate key would win in the
  // ordinary parse: leave such a message to it).
  if (j.is_discarded() || !j.is_object() || j.value("data", json()) != "") return std::nullopt;
  j["data"] = json::binary(std::move(*payload));
  return j;
}

// Parses a message; every accessor below throws json exceptions that decode() turns into errors.
template <class T, class F>
Result<T> decode(std::span<const std::uint8_t> bytes, const char* what, F&& f) {
  std::optional<json> lifted = parseLiftingData(bytes);
  const json j = lifted ? std::move(*lifted) : json::parse(bytes.begin(), bytes.end(), nullptr, false);
  if (j.is_discarded() || !j.is_object()) return bad(std::string(what) + ": not a JSON object");
  try {
    return f(j);
  } catch (const json::exception& e) {
    return bad(std::string(what) + ": " + e.what());
  } catch (const std::invalid_argument& e) {
    return bad(std::string(what) + ": " + e.what());
  }
}

Stamp stampOf(const json& j) {
  const json& t = j.at("timestamp");
  return Stamp{t.at("sec").get<std::int64_t>() * 1'000'000'000 + t.at("nsec").get<std::int64_t>()};
}

std::vector<std::uint8_t> dataOf(const json& j) {
  if (const json& v = j.at("data"); v.is_binary()) return {v.get_binary().begin(), v.get_binary().end()};
  auto d = base64Decode(j.at("data").get<std::string>());
  if (!d) throw std::invalid_argument("field 'data' is not base64");
  return std::move(*d);
}

json identityPose() {
  return json{{"position", {{"x", 0}, {"y", 0}, {"z", 0}}}, {"orientation", {{"x", 0}, {"y", 0}, {"z", 0}, {"w", 1}}}};
}

// foxglove.LaserScan bearings count from +x (ahead); LaserScan angles from the right (0 = right).
constexpr double kBearingOffset = M_PI / 2;

}  // namespace

SecNsec secNsec(Stamp s) {
  const std::int64_t sec = s.ns >= 0 ? s.ns / 1'000'000'000 : -((-s.ns + 999'999'999) / 1'000'000'000);
  return {sec, s.ns - sec * 1'000'000'000};
}

std::string_view schemaName(Schema s) {
  static constexpr std::string_view names[] = {"fusedet.RawSerial", "fusedet.CanFrame", "foxglove.RawImage",
                                               "foxglove.CompressedImage", "foxglove.LaserScan", "fusedet.TiltSample",
                                               "foxglove.PointCloud", "foxglove.ImageAnnotations", "foxglove.FrameTransform",
                                               "foxglove.CameraCalibration", "fusedet.Tracks", "foxglove.SceneUpdate"};
  return names[static_cast<int>(s)];
}
std::string_view schemaJson(Schema s) { return schemaText(s); }
std::optional<Schema> schemaByName(std::string_view name) {
  for (Schema s : kAllSchemas)
    if (schemaName(s) == name) return s;
  return std::nullopt;
}

std::vector<std::uint8_t> encode(const SerialChunk& m) {
  return bytesOf(json{{"timestamp", timestamp(m.stamp)}, {"device", m.device}, {"baud", m.baud}, {"data", base64Encode(m.bytes)}});
}

std::vector<std::uint8_t> encode(const CanMessage& m) {
  return bytesOf(json{{"timestamp", timestamp(m.stamp)}, {"interface", m.interface}, {"id", m.id}, {"extended", m.extended},
                      {"rtr", m.rtr}, {"error", m.error}, {"data", base64Encode(m.data)}});
}

Schema schemaOf(const CameraFrame& m) { return m.format == PixelFormat::kMjpeg ? Schema::kCompressedImage : Schema::kRawImage; }

namespace {
std::string_view encodingOf(PixelFormat f) {
  switch (f) {
    case PixelFormat::kBgr24: return "bgr8";
    case PixelFormat::kGray8: return "mono8";
    case PixelFormat::kYuyv: return "yuyv";
    case PixelFormat::kMjpeg: return "jpeg";
  }
  return "";
}
}  // namespace

std::vector<std::uint8_t> encode(const CameraFrame& m) {
  json j{{"timestamp", timestamp(m.stamp)}, {"frame_id", "camera"}, {"sequence", m.sequence}, {"width", m.width},
         {"height", m.height}, {"data", base64Encode(m.bytes)}};
  if (m.format == PixelFormat::kMjpeg) {
    j["format"] = "jpeg";
  } else {
    j["encoding"] = encodingOf(m.format);
    j["step"] = m.stride;
  }
  return bytesOf(j);
}

std::vector<std::uint8_t> encode(const LaserScan& m) {
  const double last = m.ranges.empty() ? m.startAngle : m.beamAngle(m.size() - 1);
  json j{{"timestamp", timestamp(m.stamp)}, {"frame_id", "laser"}, {"pose", identityPose()},
         {"start_angle", m.startAngle - kBearingOffset}, {"end_angle", last - kBearingOffset}, {"ranges", m.ranges},
         {"intensities", m.remissions}, {"sequence", m.sequence}, {"beam_duration", m.beamDuration}, {"status", m.status}};
  return bytesOf(j);
}

std::vector<std::uint8_t> encode(const TiltSample& m) {
  return bytesOf(json{{"timestamp", timestamp(m.stamp)}, {"angle", m.angle}, {"velocity", m.velocity}});
}

std::vector<std::uint8_t> encode(const PointCloudMessage& m) {
  std::vector<std::uint8_t> data(m.points.size() * 16);
  if (!m.points.empty()) std::memcpy(data.data(), m.points.data(), data.size());
  constexpr int kFloat32 = 7;  // foxglove.NumericType FLOAT32
  json fields = json::array();
  const char* names[] = {"x", "y", "z", "remission"};
  for (int i = 0; i < 4; ++i) fields.push_back({{"name", names[i]}, {"offset", 4 * i}, {"type", kFloat32}});
  return bytesOf(json{{"timestamp", timestamp(m.stamp)}, {"frame_id", m.frame}, {"pose", identityPose()},
                      {"point_stride", 16}, {"fields", fields}, {"data", base64Encode(data)}});
}

std::vector<std::uint8_t> encode(const AnnotationsMessage& m) {
  json points = json::array(), texts = json::array();
  const json colour{{"r", 1.0}, {"g", 0.8}, {"b", 0.0}, {"a", 1.0}};
  const json clear{{"r", 0.0}, {"g", 0.0}, {"b", 0.0}, {"a", 0.0}};
  for (const Annotation& a : m.boxes) {
    constexpr int kLineLoop = 2;  // foxglove.PointsAnnotationType LINE_LOOP
    points.push_back({{"timestamp", timestamp(m.stamp)}, {"type", kLineLoop},
                      {"points", json::array({{{"x", a.x}, {"y", a.y}}, {{"x", a.x + a.width}, {"y", a.y}},
                                              {{"x", a.x + a.width}, {"y", a.y + a.height}}, {{"x", a.x}, {"y", a.y + a.height}}})},
                      {"outline_color", colour}, {"outline_colors", json::array()}, {"fill_color", clear}, {"thickness", 2.0}});
    char text[96];
    std::snprintf(text, sizeof text, "%s %.2f", a.label.c_str(), a.score);
    texts.push_back({{"timestamp", timestamp(m.stamp)}, {"position", {{"x", a.x}, {"y", a.y}}}, {"text", text},
                     {"font_size", 14.0}, {"text_color", colour}, {"background_color", {{"r", 0}, {"g", 0}, {"b", 0}, {"a", 0.6}}}});
  }
  return bytesOf(json{{"timestamp", timestamp(m.stamp)}, {"circles", json::array()}, {"points", points}, {"texts", texts}});
}

std::vector<std::uint8_t> encode(const CameraCalibrationMessage& m) {
  return bytesOf(json{{"timestamp", timestamp(m.stamp)}, {"frame_id", m.frame}, {"width", m.width}, {"height", m.height},
                      {"distortion_model", m.distortionModel}, {"D", m.D}, {"K", m.K}, {"R", m.R}, {"P", m.P}});
}

std::vector<std::uint8_t> encode(const TransformMessage& m) {
  const auto& t = m.translation;
  const auto& q = m.rotation;
  return bytesOf(json{{"timestamp", timestamp(m.stamp)}, {"parent_frame_id", m.parent}, {"child_frame_id", m.child},
                      {"translation", {{"x", t[0]}, {"y", t[1]}, {"z", t[2]}}},
                      {"rotation", {{"x", q[0]}, {"y", q[1]}, {"z", q[2]}, {"w", q[3]}}}});
}

namespace {
json vec3(const std::array<double, 3>& v) { return json{{"x", v[0]}, {"y", v[1]}, {"z", v[2]}}; }
json colourOf(const std::array<double, 4>& c) { return json{{"r", c[0]}, {"g", c[1]}, {"b", c[2]}, {"a", c[3]}}; }
json poseAt(const std::array<double, 3>& p, const std::array<double, 4>& q = {0, 0, 0, 1}) {
  return json{{"position", vec3(p)}, {"orientation", {{"x", q[0]}, {"y", q[1]}, {"z", q[2]}, {"w", q[3]}}}};
}
// The rotation (quaternion x y z w) that turns +x, the direction a foxglove.ArrowPrimitive points
// in, onto the unit vector u: about x cross u by the angle between them.
std::array<double, 4> turnXOnto(const std::array<double, 3>& u) {
  if (u[0] < -1 + 1e-9) return {0, 0, 1, 0};  // opposite: half a turn about z
  const double w = 1 + u[0], n = std::sqrt(w * w + u[1] * u[1] + u[2] * u[2]);
  return {0, -u[2] / n, u[1] / n, w / n};
}
}  // namespace

std::vector<std::uint8_t> encode(const SceneUpdateMessage& m) {
  constexpr int kDeleteAll = 1;             // foxglove.SceneEntityDeletionType ALL
  constexpr double kMinArrowSpeed = 0.05;   // [m/s] slower: no arrow
  const json lifetime = timestamp(Stamp{static_cast<std::int64_t>(std::llround(m.lifetimeS * 1e9))});
  json entities = json::array();
  for (const SceneObject& o : m.objects) {
    json metadata = json::array();
    for (const auto& [k, v] : o.metadata) metadata.push_back({{"key", k}, {"value", v}});
    const double speed = std::hypot(o.velocity[0], o.velocity[1], o.velocity[2]);
    json arrows = json::array();
    if (speed >= kMinArrowSpeed)
      arrows.push_back({{"pose", poseAt(o.position, turnXOnto({o.velocity[0] / speed, o.velocity[1] / speed, o.velocity[2] / speed}))},
                        {"shaft_length", speed * 1.0}, {"shaft_diameter", 0.08}, {"head_length", 0.3}, {"head_diameter", 0.25},
                        {"color", colourOf(o.colour)}});
    const bool box = o.boxSize[0] > 0 || o.boxSize[1] > 0 || o.boxSize[2] > 0;
    const json shape = json::array({{{"pose", poseAt(o.position)},
                                     {"size", vec3(box ? o.boxSize : std::array<double, 3>{o.diameter, o.diameter, o.diameter})},
                                     {"color", colourOf(o.colour)}}});
    const double halfHeight = box ? o.boxSize[2] / 2 : o.diameter / 2;
    const std::array<double, 3> above{o.position[0], o.position[1], o.position[2] + halfHeight + 0.3};
    entities.push_back({{"timestamp", timestamp(m.stamp)}, {"frame_id", m.frame}, {"id", o.id}, {"lifetime", lifetime},
                        {"frame_locked", false}, {"metadata", metadata}, {"arrows", arrows},
                        {"spheres", box ? json::array() : shape},
                        {"texts", json::array({{{"pose", poseAt(above)}, {"billboard", true}, {"font_size", 14.0},
                                                {"scale_invariant", true}, {"color", colourOf(o.colour)}, {"text", o.text}}})},
                        {"cubes", box ? shape : json::array()}, {"cylinders", json::array()}, {"lines", json::array()},
                        {"triangles", json::array()}, {"models", json::array()}});
  }
  return bytesOf(json{{"deletions", json::array({{{"timestamp", timestamp(m.stamp)}, {"type", kDeleteAll}, {"id", ""}}})},
                      {"entities", entities}});
}

Result<SerialChunk> decodeSerial(std::span<const std::uint8_t> bytes) {
  return decode<SerialChunk>(bytes, "fusedet.RawSerial", [](const json& j) {
    return SerialChunk{stampOf(j), j.at("device").get<std::string>(), j.at("baud").get<int>(), dataOf(j)};
  });
}

Result<CanMessage> decodeCan(std::span<const std::uint8_t> bytes) {
  return decode<CanMessage>(bytes, "fusedet.CanFrame", [](const json& j) {
    CanMessage m{stampOf(j), j.at("interface").get<std::string>(), j.at("id").get<std::uint32_t>(),
                 j.at("extended").get<bool>(), j.at("rtr").get<bool>(), j.at("error").get<bool>(), dataOf(j)};
    if (m.data.size() > 8) throw std::invalid_argument("CAN frame with " + std::to_string(m.data.size()) + " data bytes");
    if (m.id > (m.extended ? 0x1FFFFFFFu : 0x7FFu)) throw std::invalid_argument("CAN id out of range");
    return m;
  });
}

Result<CameraFrame> decodeCamera(std::span<const std::uint8_t> bytes) {
  return decode<CameraFrame>(bytes, "camera image", [](const json& j) {
    CameraFrame f;
    f.stamp = stampOf(j);
    f.sequence = j.value("sequence", std::uint64_t{0});
    f.width = j.at("width").get<int>();
    f.height = j.at("height").get<int>();
    if (j.contains("format")) {
      if (j.at("format").get<std::string>() != "jpeg") throw std::invalid_argument("compressed format is not jpeg");
      f.format = PixelFormat::kMjpeg;
    } else {
      const std::string e = j.at("encoding").get<std::string>();
      if (e == "bgr8") f.format = PixelFormat::kBgr24;
      else if (e == "mono8") f.format = PixelFormat::kGray8;
      else if (e == "yuyv") f.format = PixelFormat::kYuyv;
      else throw std::invalid_argument("unsupported encoding '" + e + "'");
      f.stride = j.at("step").get<int>();
    }
    f.bytes = dataOf(j);
    return f;
  });
}

Result<LaserScan> decodeLaserScan(std::span<const std::uint8_t> bytes) {
  return decode<LaserScan>(bytes, "foxglove.LaserScan", [](const json& j) {
    LaserScan s;
    s.stamp = stampOf(j);
    s.ranges = j.at("ranges").get<std::vector<float>>();
    s.remissions = j.value("intensities", std::vector<float>{});
    s.startAngle = j.at("start_angle").get<double>() + kBearingOffset;
    const double end = j.at("end_angle").get<double>() + kBearingOffset;
    s.angleStep = s.ranges.size() > 1 ? (end - s.startAngle) / static_cast<double>(s.ranges.size() - 1) : 0;
    s.sequence = j.value("sequence", std::uint64_t{0});
    s.beamDuration = j.value("beam_duration", 0.0);
    s.status = j.value("status", std::uint8_t{0});
    return s;
  });
}

Result<TiltSample> decodeTilt(std::span<const std::uint8_t> bytes) {
  return decode<TiltSample>(bytes, "fusedet.TiltSample", [](const json& j) {
    return TiltSample{stampOf(j), j.at("angle").get<double>(), j.at("velocity").get<double>()};
  });
}

Result<PointCloudMessage> decodePointCloud(std::span<const std::uint8_t> bytes) {
  return decode<PointCloudMessage>(bytes, "foxglove.PointCloud", [](const json& j) {
    PointCloudMessage m;
    m.stamp = stampOf(j);
    m.frame = j.at("frame_id").get<std::string>();
    if (j.at("point_stride").get<int>() != 16) throw std::invalid_argument("point_stride is not 16 (x y z remission float32)");
    const std::vector<std::uint8_t> d = dataOf(j);
    if (d.size() % 16 != 0) throw std::invalid_argument("data is not a whole number of points");
    m.points.resize(d.size() / 16);
    if (!d.empty()) std::memcpy(m.points.data(), d.data(), d.size());
    return m;
  });
}

}  // namespace fusedet::drivers::logs
