// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/stack_channels.h"

#include <algorithm>
#include <cstdio>

#include "fusedet/daemon/protocol.h"

namespace fusedet::daemon {

namespace logs = drivers::logs;

namespace {

std::array<double, 4> classColour(const std::string& className) {
  if (className == "car") return {0.2, 0.55, 1.0, 1.0};
  if (className == "bike") return {1.0, 0.6, 0.1, 1.0};
  if (className == "person") return {0.2, 0.9, 0.3, 1.0};
  return {0.9, 0.3, 0.9, 1.0};
}

std::string number(double v, int decimals = 3) {
  char s[32];
  std::snprintf(s, sizeof s, "%.*f", decimals, v);
  return s;
}

}  // namespace

logs::PointCloudMessage sweepCloud(Stamp t, const std::vector<fusion::SweepPoint>& points) {
  logs::PointCloudMessage cloud{t, kBaseFrame, {}};
  cloud.points.reserve(points.size());
  for (const fusion::SweepPoint& p : points) cloud.points.push_back({p.x, p.y, p.z, p.remission});
  return cloud;
}

logs::AnnotationsMessage detectionAnnotations(const StackResult& result) {
  logs::AnnotationsMessage a{result.frameStamp, {}};
  for (const LocatedDetection& ld : result.detections) {
    const Detection& d = ld.detection;
    a.boxes.push_back({d.className, d.score, d.box.x, d.box.y, d.box.w, d.box.h});
  }
  return a;
}

logs::SceneUpdateMessage detectionScene(const StackResult& result, const Eigen::Matrix3d& K, double lifetimeS) {
  logs::SceneUpdateMessage m;
  m.stamp = result.frameStamp;
  m.frame = kBaseFrame;
  m.lifetimeS = lifetimeS;
  for (std::size_t i = 0; i < result.detections.size(); ++i) {
    const LocatedDetection& ld = result.detections[i];
    if (!ld.position) continue;
    const Detection& d = ld.detection;
    const double width = d.box.w / K(0, 0) * ld.position->range, height = d.box.h / K(1, 1) * ld.position->range;
    logs::SceneObject o;
    o.id = "detection-" + std::to_string(i);
    o.text = d.className + " " + number(d.score, 2) + " " + number(ld.position->range, 1) + " m";
    o.position = {ld.position->robot.x(), ld.position->robot.y(), ld.position->robot.z()};
    o.boxSize = {width, width, height};
    o.colour = classColour(d.className);
    o.colour[3] = 0.6;
    o.metadata = {{"class", d.className}, {"score", number(d.score)}, {"range", number(ld.position->range)},
                  {"box", number(d.box.x, 1) + " " + number(d.box.y, 1) + " " + number(d.box.w, 1) + " " + number(d.box.h, 1)}};
    m.objects.push_back(std::move(o));
  }
  return m;
}

logs::TransformMessage frameTransform(Stamp t, const std::string& parent, const std::string& child,
                                      const Eigen::Isometry3d& childInParent) {
  const Eigen::Quaterniond q(childInParent.linear());
  const Eigen::Vector3d p = childInParent.translation();
  return logs::TransformMessage{t, parent, child, {p.x(), p.y(), p.z()}, {q.x(), q.y(), q.z(), q.w()}};
}

logs::CameraCalibrationMessage cameraCalibration(Stamp t, const fusion::CameraModel& c) {
  logs::CameraCalibrationMessage m;
  m.stamp = t;
  m.frame = kCameraFrame;
  m.width = c.width;
  m.height = c.height;
  m.distortionModel = c.distortion.size() > 5 ? "rational_polynomial" : "plumb_bob";
  m.D = c.distortion;
  for (int i = 0; i < 9; ++i) m.K[static_cast<std::size_t>(i)] = c.K(i / 3, i % 3);
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) m.P[static_cast<std::size_t>(r * 4 + k)] = c.K(r, k);  // P = [K | 0]
  return m;
}

std::vector<std::uint8_t> tracksMessage(const StackResult& result) {
  nlohmann::json j = tracksToJson(result);
  const logs::SecNsec t = logs::secNsec(result.frameStamp);
  j["timestamp"] = {{"sec", t.sec}, {"nsec", t.nsec}};
  const std::string s = j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  return {s.begin(), s.end()};
}

logs::SceneUpdateMessage trackScene(const StackResult& result, double lifetimeS) {
  logs::SceneUpdateMessage m;
  m.stamp = result.frameStamp;
  m.frame = kBaseFrame;
  m.lifetimeS = lifetimeS;
  for (const tracking::TrackState& t : result.tracks) {
    logs::SceneObject o;
    o.id = "track-" + std::to_string(t.id);
    const char* state = !t.confirmed ? "tentative" : t.coasting ? "coasting" : "confirmed";
    const double speed = t.velocity.norm();
    o.text = t.className + " " + std::to_string(t.id) + (t.confirmed && !t.coasting ? "" : std::string(" ") + state) + " " +
             number(speed, 1) + " m/s";
    o.position = {t.position.x(), t.position.y(), t.position.z()};
    o.velocity = {t.velocity.x(), t.velocity.y(), t.velocity.z()};
    o.diameter = std::clamp(2 * t.positionSigma, 0.3, 10.0);
    o.colour = t.confirmed ? classColour(t.className) : std::array<double, 4>{0.6, 0.6, 0.6, 0.8};
    if (t.confirmed && t.coasting) o.colour[3] = 0.3;
    o.metadata = {{"id", std::to_string(t.id)},
                  {"class", t.className},
                  {"state", state},
                  {"velocity", number(t.velocity.x()) + " " + number(t.velocity.y()) + " " + number(t.velocity.z())},
                  {"speed", number(speed)},
                  {"sigma", number(t.positionSigma)},
                  {"age", number(t.ageS)},
                  {"hits", std::to_string(t.hits)},
                  {"misses", std::to_string(t.misses)}};
    m.objects.push_back(std::move(o));
  }
  return m;
}

}  // namespace fusedet::daemon
