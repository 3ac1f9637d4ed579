// SPDX-License-Identifier: Apache-2.0
// fusedet query: a client of fusedetd's socket (docs/protocol.md). Prints the lines the daemon
// sends, one JSON object per line.

#include <cstdio>
#include <memory>

#include "command.h"
#include "fusedet/daemon/client.h"

namespace fusedet::tools {
namespace {

struct QueryOptions {
  std::string socket = "/run/fusedet/fusedet.sock";
  bool follow = false;
  bool tracks = false;   // follow the tracks stream instead of detections
  std::vector<std::string> classes;
  bool status = false;
  bool hello = false;
  long count = 0;        // --follow: stop after this many detection lines (0 = never)
  bool text = false;     // detections as readable text instead of JSON
  double timeout = 10;   // seconds to wait for a reply (or, with --follow, for the next line)
};

std::string vec3(const nlohmann::json& v) {
  if (!v.is_array() || v.size() != 3) return "-";
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.2f, %.2f, %.2f) m", v[0].get<double>(), v[1].get<double>(), v[2].get<double>());
  return buf;
}

std::string metres(const nlohmann::json& v) {
  if (!v.is_number()) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f m", v.get<double>());
  return buf;
}

// One stack's detections for a person to read: stamps in seconds of CLOCK_MONOTONIC, then one
// line per detection.
void printText(const nlohmann::json& m) {
  auto s = [&m](const char* key) { return m.value(key, std::int64_t{0}) * 1e-9; };
  std::printf("stack %s  sweep %.3f..%.3f s  frame %.3f s  sensor->detected %.0f ms (fuse %.0f, detect %.0f)\n",
              m.value("stack", nlohmann::json()).dump().c_str(), s("sweep_start_ns"), s("sweep_end_ns"), s("frame_ns"),
              (s("detected_ns") - s("sensor_ns")) * 1e3, m.value("fuse_ms", 0.0), m.value("detect_ms", 0.0));
  const auto& found = m.value("detections", nlohmann::json::array());
  if (found.empty()) std::printf("  (nothing found)\n");
  for (const auto& d : found) {
    const auto& b = d.value("box", nlohmann::json::array());
    std::printf("  %-7s score %5.1f  box x %4.0f y %4.0f w %4.0f h %4.0f  camera %s  robot %s  range %s\n",
                d.value("class", "?").c_str(), d.value("score", 0.0), b.size() == 4 ? b[0].get<double>() : 0.0,
                b.size() == 4 ? b[1].get<double>() : 0.0, b.size() == 4 ? b[2].get<double>() : 0.0,
                b.size() == 4 ? b[3].get<double>() : 0.0, vec3(d.value("camera", nlohmann::json())).c_str(),
                vec3(d.value("robot", nlohmann::json())).c_str(),
                metres(d.value("range", nlohmann::json())).c_str());
    if (d.value("track", nlohmann::json()).is_number())
      std::printf("          track %s%s  velocity %s/s  age %.1f s\n", d["track"].dump().c_str(),
                  d.value("confirmed", false) ? "" : " (tentative)", vec3(d.value("velocity", nlohmann::json())).c_str(),
                  d.value("age", 0.0));
  }
}

// One stack's live tracks for a person to read.
void printTracksText(const nlohmann::json& m) {
  std::printf("stack %s  frame %.3f s  %zu tracks\n", m.value("stack", nlohmann::json()).dump().c_str(),
              m.value("frame_ns", std::int64_t{0}) * 1e-9, m.value("tracks", nlohmann::json::array()).size());
  for (const auto& t : m.value("tracks", nlohmann::json::array()))
    std::printf("  track %-5s %-7s %-9s %-8s robot %s  velocity %s/s  age %.1f s  hits %d  misses %d\n",
                t.value("id", nlohmann::json()).dump().c_str(), t.value("class", "?").c_str(),
                t.value("confirmed", false) ? "confirmed" : "tentative", t.value("coasting", false) ? "coasting" : "",
                vec3(t.value("robot", nlohmann::json())).c_str(), vec3(t.value("velocity", nlohmann::json())).c_str(),
                t.value("age", 0.0), t.value("hits", 0), t.value("misses", 0));
}

int runQuery(const QueryOptions& o) {
  daemon::Client client(o.socket);
  const auto timeout = std::chrono::milliseconds(static_cast<long>(o.timeout * 1000));
  auto printNext = [&]() -> std::optional<nlohmann::json> {
    auto line = client.readLine(timeout);
    if (!line) {
      std::fprintf(stderr, "fusedet query: %s\n",
                   client.closed() ? "the daemon closed the connection" : "no reply within --timeout");
      return std::nullopt;
    }
    auto message = nlohmann::json::parse(*line, nullptr, false);
    if (o.text && message.is_object() && message.value("type", "") == "detections")
      printText(message);
    else if (o.text && message.is_object() && message.value("type", "") == "tracks")
      printTracksText(message);
    else
      std::printf("%s\n", line->c_str());
    std::fflush(stdout);
    return message;
  };
  const bool follow = o.follow || o.tracks;
  if (o.hello || follow) {
    client.send({{"cmd", "hello"}});
    if (!printNext()) return 1;
  }
  if (o.status) {
    client.send({{"cmd", "status"}});
    return printNext() ? 0 : 1;
  }
  if (!follow) {
    if (o.hello) return 0;
    client.send({{"cmd", "latest"}});
    return printNext() ? 0 : 1;
  }
  nlohmann::json request{{"cmd", "subscribe"}};
  if (!o.classes.empty()) request["classes"] = o.classes;
  if (o.tracks) request["stream"] = "tracks";
  client.send(request);
  const std::string counted = o.tracks ? "tracks" : "detections";
  for (long seen = 0; o.count == 0 || seen < o.count;) {
    auto message = printNext();
    if (!message) return 1;
    if (message->is_object() && message->value("type", "") == "error") return 1;
    if (message->is_object() && message->value("type", "") == counted) ++seen;
  }
  return 0;
}

const bool registered = registerCommand(
    "query", "Ask a running fusedetd for detections or its status (socket client)", [](CLI::App& app) {
      auto o = std::make_shared<QueryOptions>();
      app.add_option("-s,--socket", o->socket, "the daemon's socket")->capture_default_str();
      app.add_flag("-f,--follow", o->follow, "subscribe and print every stack's detections as they come");
      app.add_flag("--tracks", o->tracks,
                   "subscribe to the tracks stream: one line per stack with every live track (implies --follow)");
      app.add_option("-c,--class", o->classes, "with --follow: only these classes (repeat for several)");
      app.add_option("-n,--count", o->count, "with --follow: stop after this many detections (or tracks) lines (0 = never)")
          ->capture_default_str();
      app.add_flag("--text", o->text, "print detections as readable text (one line per stack and per detection)");
      app.add_flag("--status", o->status, "print the daemon's status (sensors, rates, drops, latency)");
      app.add_flag("--hello", o->hello, "print the daemon's hello (versions, classes)");
      app.add_option("-t,--timeout", o->timeout, "seconds to wait for each reply")->capture_default_str();
      app.footer(
          "Without options prints the detections of the latest processed stack. Output is what the\n"
          "daemon sends: one JSON object per line (docs/protocol.md). --follow first prints the\n"
          "hello, then one \"detections\" line per stack (an empty list when nothing of the chosen\n"
          "classes was found) until --count lines, the daemon closing, or --timeout without a line.\n"
          "--text prints each detections line as text instead: the stack's stamps (CLOCK_MONOTONIC\n"
          "seconds) and sensor->detected time, then per detection class, score, box (pixels), camera\n"
          "and robot frame position and range (metres; - when the box has too few laser cells), and its\n"
          "track (id, velocity, age). --tracks follows the \"tracks\" stream instead: per stack every live\n"
          "track (id, class, confirmed or tentative, coasting, robot-frame position and velocity, age).\n\n"
          "Exit status: 0 on success; 1 when the daemon cannot be reached, sends an error line, closes\n"
          "the connection or does not answer in time.\n\n"
          "Examples:\n"
          "  fusedet query --status\n"
          "  fusedet query --follow --class person --class car\n"
          "  fusedet query --tracks --text\n"
          "  fusedet query --socket /tmp/fusedet.sock --follow --count 5\n"
          "  fusedet query --socket /tmp/fusedet-demo.sock --follow --text");
      return [o] { return runQuery(*o); };
    });

}  // namespace
}  // namespace fusedet::tools
