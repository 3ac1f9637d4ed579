// SPDX-License-Identifier: Apache-2.0
// daemon_soak: fusedetd replaying a sensor log in a loop (replay.at_end: loop, paced like the
// recording, the bundled models) while 50 clients connect, subscribe, ask and leave, for a given
// time (issue 37's soak). Every 10 s it samples the daemon's resident memory and open descriptors
// (/proc/PID: sockets and the rest), the clients connected and the latency p99 (`status`). A
// subscriber that stays the whole time is the reference: every subscribed session must receive a
// run of consecutive stacks of the reference's (no gap for a client that keeps up). Writes
// OUT/soak.csv and OUT/soak.png (memory, descriptors, p99 over time), prints the samples as a
// Markdown table and one verdict line, and exits 1 unless, after the warm-up (a fifth of the run,
// at most 300 s), memory grew < 5 % (the last third of the samples against the first), the
// descriptors that are not sockets did not grow (their fewest in the last third of the samples is
// at most their fewest in the first: a leaked descriptor raises that floor, one open for a moment -
// the log reopened at its end, a status answer reading /proc - does not), once the churning
// clients have left the sockets are the listener's and the reference's again, and no session saw
// a gap. The p99 is
// reported, not judged: on this shared, niced machine it follows the other jobs' load.
//   daemon_soak SECONDS OUT_DIR [CLIENTS]

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "fusedet/daemon/client.h"
#include "replay_logs.h"

extern char** environ;

namespace fs = std::filesystem;
using namespace fusedet::daemon;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

namespace {

struct Sample {
  double t = 0;          // s since start
  double rssMiB = 0;     // VmRSS
  int fds = 0;           // /proc/PID/fd entries
  int sockets = 0;       // of these, sockets (the listener, the clients' connections)
  int clients = 0;       // status clients.connected (each holds one descriptor)
  double p99Ms = 0;      // status latency_ms.p99
  std::uint64_t stacks = 0;
};

double rssMiB(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  return 0;
}

// Open descriptors and how many of them are sockets. An entry whose link cannot be read was
// closed between listing and reading (a client leaving): it is not counted, else it would count
// as a descriptor that is not a socket.
std::pair<int, int> openFds(pid_t pid) {
  std::error_code ec;
  int n = 0, sockets = 0;
  for (auto it = fs::directory_iterator("/proc/" + std::to_string(pid) + "/fd", ec); !ec && it != fs::directory_iterator();
       it.increment(ec)) {
    std::error_code lec;
    const std::string target = fs::read_symlink(it->path(), lec).string();
    if (lec) continue;
    ++n;
    if (target.rfind("socket:", 0) == 0) ++sockets;
  }
  return {n, sockets};
}

// One sample of the daemon (the status client itself is not counted among the clients).
void sample(pid_t pid, const std::string& socket, Sample& s) {
  s.rssMiB = rssMiB(pid);
  std::tie(s.fds, s.sockets) = openFds(pid);
  try {
    Client c(socket);
    c.send({{"cmd", "status"}});
    if (auto st = c.read(5s)) {
      s.clients = (*st)["clients"]["connected"].get<int>() - 1;
      s.p99Ms = (*st)["latency_ms"]["p99"].get<double>();
      s.stacks = (*st)["pipeline"]["stacks_detected"].get<std::uint64_t>();
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "soak: status at %.0f s: %s\n", s.t, e.what());
  }
}

// One panel: a polyline of `values` over `t` in the rectangle `r`, its range written beside it.
void panel(cv::Mat& img, cv::Rect r, const std::vector<double>& t, const std::vector<double>& values, const std::string& title,
           double tMax) {
  cv::rectangle(img, r, cv::Scalar(0, 0, 0), 1);
  if (values.empty()) return;
  double lo = *std::min_element(values.begin(), values.end()), hi = *std::max_element(values.begin(), values.end());
  const double pad = std::max(1e-9, (hi - lo) * 0.1 + std::abs(hi) * 0.02);
  lo -= pad;
  hi += pad;
  std::vector<cv::Point> pts;
  for (std::size_t i = 0; i < values.size(); ++i)
    pts.emplace_back(r.x + static_cast<int>(t[i] / tMax * r.width),
                     r.y + r.height - static_cast<int>((values[i] - lo) / (hi - lo) * r.height));
  cv::polylines(img, pts, false, cv::Scalar(180, 60, 0), 2, cv::LINE_AA);
  char text[160];
  std::snprintf(text, sizeof text, "%s: %.1f .. %.1f", title.c_str(), lo + pad, hi - pad);
  cv::putText(img, text, {r.x + 6, r.y + 18}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: daemon_soak SECONDS OUT_DIR [CLIENTS]\n");
    return 2;
  }
  const double seconds = std::stod(argv[1]);
  const fs::path out = argv[2];
  const int clientCount = argc > 3 ? std::stoi(argv[3]) : 50;
  const double warmup = std::min(300.0, seconds / 5);
  fs::create_directories(out);
  const std::string socket = (out / "soak.sock").string();
  fs::remove(socket);  // a previous run's: its existence must not pass for the daemon's readiness
  const std::string models = std::string(FUSEDET_SOURCE_DIR) + "/models/";
  {
    std::ofstream c(out / "soak.yaml");
    c << "socket:\n  path: " << socket << "\n  max_clients: " << clientCount + 8 << "\n"
      << "detection:\n  models: [" << models << "car.json, " << models << "bike.json, " << models << "person.json]\n"
      << "replay:\n  file: " << fusedet::testlogs::daemonTestLog(6).string() << "\n  at_end: loop\n  realtime: true\n";
  }
  std::string daemonPath = std::string(FUSEDET_BINARY_DIR) + "/tools/fusedetd", configArg = (out / "soak.yaml").string();
  std::string configFlag = "--config";
  char* args[] = {daemonPath.data(), configFlag.data(), configArg.data(), nullptr};
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 2, (out / "fusedetd.log").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = -1;
  const int spawned = posix_spawn(&pid, args[0], &fa, nullptr, args, environ);
  posix_spawn_file_actions_destroy(&fa);
  if (spawned != 0) {
    std::fprintf(stderr, "soak: cannot start %s\n", daemonPath.c_str());
    return 1;
  }
  // Ready when it accepts a connection (the log may be synthesised first: up to a minute).
  bool ready = false;
  for (int i = 0; i < 1200 && !ready; ++i) {
    try {
      Client probe(socket);
      ready = true;
    } catch (const std::exception&) {
      std::this_thread::sleep_for(100ms);
    }
  }
  if (!ready) {
    std::fprintf(stderr, "soak: fusedetd did not accept a connection within 120 s (see %s)\n", (out / "fusedetd.log").c_str());
    ::kill(pid, SIGKILL);
    ::waitpid(pid, nullptr, 0);
    return 1;
  }
  std::this_thread::sleep_for(300ms);  // the probe's connection closed on the daemon's side too
  Sample initial;  // before any client: the listener's sockets
  sample(pid, socket, initial);
  const auto t0 = Clock::now();
  const auto end = t0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  std::atomic<bool> stop{false}, stopChurn{false};

  // The reference subscriber: every stack the daemon published, in order.
  std::mutex refMutex;
  std::vector<std::uint64_t> reference;
  std::atomic<bool> refFailed{false};
  std::thread ref([&] {
    try {
      Client c(socket);
      c.send({{"cmd", "subscribe"}});
      while (!stop) {
        auto m = c.read(1s);
        if (m && (*m)["type"] == "detections") {
          std::lock_guard lock(refMutex);
          reference.push_back((*m)["stack"].get<std::uint64_t>());
        }
        if (!m && c.closed()) break;
      }
    } catch (const std::exception& e) {
      std::fprintf(stderr, "soak: reference subscriber: %s\n", e.what());
    }
    if (!stop) refFailed = true;  // it must stay to the end
  });

  // Churning clients; each subscribed session's stacks are checked against the reference later.
  std::mutex sessionMutex;
  std::vector<std::vector<std::uint64_t>> sessions;
  std::atomic<std::uint64_t> connects{0}, requests{0}, errors{0};
  std::vector<std::thread> clients;
  for (int k = 0; k < clientCount; ++k)
    clients.emplace_back([&, k] {
      std::mt19937 rng(static_cast<unsigned>(k) * 7919u + 1);
      while (!stopChurn) {
        try {
          Client c(socket);
          ++connects;
          const int kind = static_cast<int>(rng() % 4);
          if (kind < 2) {  // subscribe and keep up for 2-20 s
            c.send({{"cmd", "subscribe"}});
            std::vector<std::uint64_t> got;
            const auto until = Clock::now() + std::chrono::milliseconds(2000 + rng() % 18000);
            while (!stopChurn && Clock::now() < until) {
              auto m = c.read(500ms);
              if (m && (*m)["type"] == "detections") got.push_back((*m)["stack"].get<std::uint64_t>());
              if (!m && c.closed()) break;
            }
            std::lock_guard lock(sessionMutex);
            sessions.push_back(std::move(got));
          } else if (kind == 2) {  // a few requests
            for (const char* cmd : {"hello", "status", "latest"}) {
              c.send({{"cmd", cmd}});
              if (c.read(5s)) ++requests;
            }
          }  // kind 3: connect and leave at once
        } catch (const std::exception&) {
          ++errors;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(rng() % 2000));
      }
    });

  std::vector<Sample> samples;
  for (auto next = t0; Clock::now() < end; next += 10s) {
    std::this_thread::sleep_until(std::min(next, end));
    Sample s;
    s.t = std::chrono::duration<double>(Clock::now() - t0).count();
    sample(pid, socket, s);
    samples.push_back(s);
    std::fprintf(stderr, "soak: %.0f s: rss %.1f MiB, %d fds (%d sockets), %d clients, p99 %.1f ms\n", s.t, s.rssMiB, s.fds,
                 s.sockets, s.clients, s.p99Ms);
  }
  // The churning clients leave; the reference stays: the daemon's sockets must be back to the
  // listener's and the reference's.
  stopChurn = true;
  for (auto& t : clients) t.join();
  Sample quiet;
  for (int i = 0; i < 50; ++i) {
    std::this_thread::sleep_for(100ms);
    sample(pid, socket, quiet);
    if (quiet.clients == 1 && quiet.sockets - quiet.clients == initial.sockets - initial.clients) break;
  }
  stop = true;
  ref.join();
  ::kill(pid, SIGTERM);
  int status = 0;
  ::waitpid(pid, &status, 0);

  // Gaps: a session's stacks must be consecutive entries of the reference.
  std::map<std::uint64_t, std::size_t> position;
  for (std::size_t i = 0; i < reference.size(); ++i) position[reference[i]] = i;
  std::size_t subscribed = 0, gaps = 0, stacksSeen = 0;
  for (const auto& s : sessions) {
    if (s.empty()) continue;
    ++subscribed;
    stacksSeen += s.size();
    for (std::size_t i = 1; i < s.size(); ++i) {
      const auto a = position.find(s[i - 1]), b = position.find(s[i]);
      if (a == position.end() || b == position.end() || b->second != a->second + 1) ++gaps;
    }
  }

  // After the warm-up: memory, descriptors that are not sockets, p99. Sockets: at the start (no
  // client yet) and once the churn has left (the reference still there) the listener's only.
  std::vector<Sample> steady;
  for (const Sample& s : samples)
    if (s.t >= warmup) steady.push_back(s);
  double growth = 0, p99Ratio = 0;
  int otherFdSpread = 0, otherFdFloorFirst = 0, otherFdFloorLast = 0;
  if (steady.size() >= 3) {
    // Memory moves by a few MiB from sample to sample (allocations of the stacks in flight): the
    // last third of the samples against the first, each averaged.
    const std::size_t third = steady.size() / 3;
    double first = 0, last = 0;
    for (std::size_t i = 0; i < third; ++i) {
      first += steady[i].rssMiB / static_cast<double>(third);
      last += steady[steady.size() - 1 - i].rssMiB / static_cast<double>(third);
    }
    growth = (last - first) / first;
    int lo = 1 << 30, hi = 0;
    for (const Sample& s : steady) {
      lo = std::min(lo, s.fds - s.sockets);
      hi = std::max(hi, s.fds - s.sockets);
      if (steady.front().p99Ms > 0) p99Ratio = std::max(p99Ratio, s.p99Ms / steady.front().p99Ms);
    }
    otherFdSpread = hi - lo;
    otherFdFloorFirst = otherFdFloorLast = 1 << 30;
    for (std::size_t i = 0; i < third; ++i) {
      const Sample& a = steady[i];
      const Sample& b = steady[steady.size() - 1 - i];
      otherFdFloorFirst = std::min(otherFdFloorFirst, a.fds - a.sockets);
      otherFdFloorLast = std::min(otherFdFloorLast, b.fds - b.sockets);
    }
  }
  const int listenerSockets = initial.sockets - initial.clients;
  const bool socketsBack = quiet.clients == 1 && quiet.sockets - quiet.clients == listenerSockets;

  std::ofstream csv(out / "soak.csv");
  csv << "t_s,rss_mib,fds,sockets,clients,p99_ms,stacks\n";
  std::printf("| t [s] | RSS [MiB] | fds | of them sockets | clients | p99 [ms] | stacks |\n|---|---|---|---|---|---|---|\n");
  for (const Sample& s : samples) {
    csv << s.t << ',' << s.rssMiB << ',' << s.fds << ',' << s.sockets << ',' << s.clients << ',' << s.p99Ms << ',' << s.stacks
        << '\n';
    std::printf("| %.0f | %.1f | %d | %d | %d | %.1f | %ju |\n", s.t, s.rssMiB, s.fds, s.sockets, s.clients, s.p99Ms,
                static_cast<std::uintmax_t>(s.stacks));
  }
  cv::Mat img(600, 900, CV_8UC3, cv::Scalar(255, 255, 255));
  std::vector<double> t, rss, fds, p99;
  for (const Sample& s : samples) {
    t.push_back(s.t);
    rss.push_back(s.rssMiB);
    fds.push_back(s.fds - s.sockets);
    p99.push_back(s.p99Ms);
  }
  char title[200];
  std::snprintf(title, sizeof title, "fusedetd soak: %.0f s, %d clients churning (x: time 0 .. %.0f s)", seconds, clientCount,
                seconds);
  cv::putText(img, title, {20, 24}, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  panel(img, {60, 40, 800, 160}, t, rss, "resident memory [MiB]", seconds);
  panel(img, {60, 225, 800, 160}, t, fds, "open descriptors other than sockets", seconds);
  panel(img, {60, 410, 800, 160}, t, p99, "latency p99 [ms]", seconds);
  cv::imwrite((out / "soak.png").string(), img);

  const bool ok = !refFailed && steady.size() >= 3 && growth < 0.05 && otherFdFloorLast <= otherFdFloorFirst && socketsBack &&
                  gaps == 0 && subscribed > 0 && WIFEXITED(status) && WEXITSTATUS(status) == 0;
  std::printf("soak: %s: %.0f s, %d clients: %ju connections, %zu subscribed sessions (%zu stacks, %zu gaps), %ju requests "
              "answered, %ju client errors; after %.0f s warm-up memory grew %.1f %% (last third of the samples against the first), descriptors other than sockets "
              "varied by %d (fewest %d in the first third of the samples, %d in the last), sockets after the churn %d "
              "(listener %d + reference), p99 at most %.2fx its first value; "
              "fusedetd exit %d\n",
              ok ? "OK" : "FAILED", seconds, clientCount, static_cast<std::uintmax_t>(connects.load()), subscribed,
              stacksSeen, gaps, static_cast<std::uintmax_t>(requests.load()), static_cast<std::uintmax_t>(errors.load()),
              warmup, growth * 100, otherFdSpread, otherFdFloorFirst, otherFdFloorLast, quiet.sockets, listenerSockets, p99Ratio,
              WIFEXITED(status) ? WEXITSTATUS(status) : -1);
  return ok ? 0 : 1;
}
