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
  std::vector<std::string> classes;
  bool status = false;
  bool hello = false;
  long count = 0;        // --follow: stop after this many detection lines (0 = never)
  double timeout = 10;   // seconds to wait for a reply (or, with --follow, for the next line)
};

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
    std::printf("%s\n", line->c_str());
    std::fflush(stdout);
    return nlohmann::json::parse(*line, nullptr, false);
  };
  if (o.hello || o.follow) {
    client.send({{"cmd", "hello"}});
    if (!printNext()) return 1;
  }
  if (o.status) {
    client.send({{"cmd", "status"}});
    return printNext() ? 0 : 1;
  }
  if (!o.follow) {
    if (o.hello) return 0;
    client.send({{"cmd", "latest"}});
    return printNext() ? 0 : 1;
  }
  nlohmann::json request{{"cmd", "subscribe"}};
  if (!o.classes.empty()) request["classes"] = o.classes;
  client.send(request);
  for (long seen = 0; o.count == 0 || seen < o.count;) {
    auto message = printNext();
    if (!message) return 1;
    if (message->is_object() && message->value("type", "") == "error") return 1;
    if (message->is_object() && message->value("type", "") == "detections") ++seen;
  }
  return 0;
}

const bool registered = registerCommand(
    "query", "Ask a running fusedetd for detections or its status (socket client)", [](CLI::App& app) {
      auto o = std::make_shared<QueryOptions>();
      app.add_option("-s,--socket", o->socket, "the daemon's socket")->capture_default_str();
      app.add_flag("-f,--follow", o->follow, "subscribe and print every stack's detections as they come");
      app.add_option("-c,--class", o->classes, "with --follow: only these classes (repeat for several)");
      app.add_option("-n,--count", o->count, "with --follow: stop after this many detection lines (0 = never)")
          ->capture_default_str();
      app.add_flag("--status", o->status, "print the daemon's status (sensors, rates, drops, latency)");
      app.add_flag("--hello", o->hello, "print the daemon's hello (versions, classes)");
      app.add_option("-t,--timeout", o->timeout, "seconds to wait for each reply")->capture_default_str();
      app.footer(
          "Without options prints the detections of the latest processed stack. Output is what the\n"
          "daemon sends: one JSON object per line (docs/protocol.md). --follow first prints the\n"
          "hello, then one \"detections\" line per stack (an empty list when nothing of the chosen\n"
          "classes was found) until --count lines, the daemon closing, or --timeout without a line.\n\n"
          "Exit status: 0 on success; 1 when the daemon cannot be reached, sends an error line, closes\n"
          "the connection or does not answer in time.\n\n"
          "Examples:\n"
          "  fusedet query --status\n"
          "  fusedet query --follow --class person --class car\n"
          "  fusedet query --socket /tmp/fusedet.sock --follow --count 5");
      return [o] { return runQuery(*o); };
    });

}  // namespace
}  // namespace fusedet::tools
