// SPDX-License-Identifier: Apache-2.0
#include "fusedet/sensor_logs/track_channels.h"

#include <algorithm>
#include <cstdio>

#include "fusedet/daemon/protocol.h"

namespace fusedet::sensor_logs {

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

std::vector<std::uint8_t> tracksMessage(const daemon::StackResult& result) {
  nlohmann::json j = daemon::tracksToJson(result);
  const logs::SecNsec t = logs::secNsec(result.frameStamp);
  j["timestamp"] = {{"sec", t.sec}, {"nsec", t.nsec}};
  const std::string s = j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  return {s.begin(), s.end()};
}

logs::SceneUpdateMessage trackScene(const daemon::StackResult& result, double lifetimeS) {
  logs::SceneUpdateMessage m;
  m.stamp = result.frameStamp;
  m.frame = "laser_base";
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

}  // namespace fusedet::sensor_logs
