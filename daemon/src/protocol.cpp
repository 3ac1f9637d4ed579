// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/protocol.h"

namespace fusedet::daemon {
namespace {

nlohmann::json vec3(const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

}  // namespace

std::optional<Request> parseRequest(std::string_view line, std::string& error, nlohmann::json* id) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(line.begin(), line.end());
  } catch (const nlohmann::json::exception& e) {  // parse_error, and out_of_range for a number like 1e999
    error = std::string("not JSON: ") + e.what();
    return std::nullopt;
  }
  if (!j.is_object()) {
    error = "expected a JSON object";
    return std::nullopt;
  }
  Request r;
  if (j.contains("id")) r.id = j["id"];
  if (id) *id = r.id;
  const auto cmd = j.find("cmd");
  if (cmd == j.end() || !cmd->is_string()) {
    error = "missing \"cmd\" (a string: hello, subscribe, unsubscribe, latest, status)";
    return std::nullopt;
  }
  const std::string c = cmd->get<std::string>();
  if (c == "hello") r.command = Request::Command::kHello;
  else if (c == "subscribe") r.command = Request::Command::kSubscribe;
  else if (c == "unsubscribe") r.command = Request::Command::kUnsubscribe;
  else if (c == "latest") r.command = Request::Command::kLatest;
  else if (c == "status") r.command = Request::Command::kStatus;
  else {
    error = "unknown cmd '" + c.substr(0, 64) + "'";
    return std::nullopt;
  }
  if (const auto stream = j.find("stream"); stream != j.end() && !stream->is_null()) {
    if (r.command != Request::Command::kSubscribe && r.command != Request::Command::kUnsubscribe) {
      error = "\"stream\" only goes with subscribe and unsubscribe";
      return std::nullopt;
    }
    if (!stream->is_string() || (*stream != "detections" && *stream != "tracks")) {
      error = "\"stream\" must be \"detections\" or \"tracks\"";
      return std::nullopt;
    }
    r.stream = stream->get<std::string>();
  }
  if (r.command == Request::Command::kSubscribe && r.stream.empty()) r.stream = "detections";
  if (const auto classes = j.find("classes"); classes != j.end() && !classes->is_null()) {
    if (r.command != Request::Command::kSubscribe) {
      error = "\"classes\" only goes with subscribe";
      return std::nullopt;
    }
    if (!classes->is_array()) {
      error = "\"classes\" must be an array of class names";
      return std::nullopt;
    }
    for (const auto& name : *classes) {
      if (!name.is_string()) {
        error = "\"classes\" must be an array of class names";
        return std::nullopt;
      }
      r.classes.insert(name.get<std::string>());
    }
  }
  return r;
}

nlohmann::json resultToJson(const StackResult& r, const std::set<std::string>& classes, const char* type) {
  nlohmann::json dets = nlohmann::json::array();
  for (const LocatedDetection& ld : r.detections) {
    const Detection& d = ld.detection;
    if (!classes.empty() && !classes.count(d.className)) continue;
    nlohmann::json j;
    j["class"] = d.className;
    j["score"] = d.score;
    j["box"] = {d.box.x, d.box.y, d.box.w, d.box.h};
    if (ld.position) {
      j["camera"] = vec3(ld.position->camera);
      j["robot"] = vec3(ld.position->robot);
      j["range"] = ld.position->range;
    } else {
      j["camera"] = nullptr;
      j["robot"] = nullptr;
      j["range"] = nullptr;
    }
    if (ld.track >= 0) {
      const tracking::TrackState& t = r.tracks.at(static_cast<std::size_t>(ld.track));
      j["track"] = t.id;
      j["velocity"] = vec3(t.velocity);
      j["age"] = t.ageS;
      j["confirmed"] = t.confirmed;
    } else {
      j["track"] = nullptr;
      j["velocity"] = nullptr;
      j["age"] = nullptr;
      j["confirmed"] = false;
    }
    dets.push_back(std::move(j));
  }
  nlohmann::json line{{"type", type},
          {"stack", r.stackId},
          {"sweep_start_ns", r.sweepStart.ns},
          {"sweep_end_ns", r.sweepEnd.ns},
          {"frame_ns", r.frameStamp.ns},
          {"sensor_ns", r.sensorStamp.ns},
          {"detected_ns", r.detectedAt.ns},
          {"fuse_ms", r.fuseMs},
          {"detect_ms", r.detectMs},
          {"stages_ms", {{"close", r.stages.closeMs},
                         {"decode", r.stages.decodeMs},
                         {"fuse", r.stages.fuseMs},
                         {"fuse_cpu", r.stages.fuseCpuMs},
                         {"neural_queue", r.stages.neuralQueueMs},
                         {"neural", r.stages.neuralMs},
                         {"neural_cpu", r.stages.neuralCpuMs},
                         {"queue", r.stages.queueMs},
                         {"detect", r.stages.detectMs},
                         {"detect_cpu", r.stages.detectCpuMs},
                         {"localize", r.stages.localizeMs},
                         {"track", r.stages.trackMs}}},
          {"detections", std::move(dets)}};
  if (!r.networkError.empty()) {
    line["network_error"] = r.networkError;
    line["classes_not_run"] = r.classesNotRun;
  }
  return line;
}

nlohmann::json tracksToJson(const StackResult& r, const std::set<std::string>& classes) {
  nlohmann::json tracks = nlohmann::json::array();
  for (const tracking::TrackState& t : r.tracks) {
    if (!classes.empty() && !classes.count(t.className)) continue;
    tracks.push_back({{"id", t.id},
                      {"class", t.className},
                      {"confirmed", t.confirmed},
                      {"coasting", t.coasting},
                      {"robot", vec3(t.position)},
                      {"velocity", vec3(t.velocity)},
                      {"sigma", t.positionSigma},
                      {"age", t.ageS},
                      {"hits", t.hits},
                      {"misses", t.misses},
                      {"box", {t.box.x, t.box.y, t.box.w, t.box.h}}});
  }
  return {{"type", "tracks"},
          {"stack", r.stackId},
          {"frame_ns", r.frameStamp.ns},
          {"sensor_ns", r.sensorStamp.ns},
          {"detected_ns", r.detectedAt.ns},
          {"tracks", std::move(tracks)}};
}

std::string toLine(const nlohmann::json& message) {
  return message.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

std::string errorLine(const std::string& reason, const nlohmann::json& id) {
  nlohmann::json j{{"type", "error"}, {"error", reason}};
  if (!id.is_null()) j["id"] = id;
  return toLine(j);
}

}  // namespace fusedet::daemon
