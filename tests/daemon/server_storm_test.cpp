// SPDX-License-Identifier: Apache-2.0
// The socket server under floods (issue 37's fault matrix): a thousand clients connecting at
// once, the daemon out of file descriptors while clients keep connecting, and a request line of
// 1 GiB. Results are synthetic (no detection cost): the test is about the server. Each prints
// what it measured (the times in docs/reliability.md come from these lines).

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <thread>
#include <vector>

#include "fusedet/daemon/client.h"
#include "fusedet/daemon/server.h"
#include "server_fixtures.h"

using namespace fusedet;
using namespace fusedet::daemon;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using fusedet::daemon::server_test::makeResult;
using fusedet::daemon::server_test::tempSocket;

namespace {

double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// Resident set of this process [bytes] (/proc/self/statm, second field in pages).
std::size_t residentBytes() {
  std::ifstream statm("/proc/self/statm");
  std::size_t size = 0, resident = 0;
  statm >> size >> resident;
  return resident * static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
}

// Raises the soft descriptor limit to `want` if the hard limit allows; false if it does not.
bool haveDescriptors(rlim_t want) {
  rlimit l{};
  if (::getrlimit(RLIMIT_NOFILE, &l) != 0) return false;
  if (l.rlim_cur >= want) return true;
  if (l.rlim_max != RLIM_INFINITY && l.rlim_max < want) return false;
  l.rlim_cur = want;
  return ::setrlimit(RLIMIT_NOFILE, &l) == 0;
}

}  // namespace

// 1,000 clients connect at once (the listen backlog is 64: most wait in connect() until the server
// takes them) and subscribe, next to a subscriber that was there before. Every one of them gets
// every stack published afterwards; the earlier subscriber misses nothing while they come; when
// they leave, the server is back to one client.
TEST(ServerStorm, AThousandClientsConnectAtOnceAndEachGetsEveryStack) {
  constexpr int kClients = 1000;
  if (!haveDescriptors(2 * kClients + 200)) GTEST_SKIP() << "the hard RLIMIT_NOFILE is below " << 2 * kClients + 200;
  const std::string path = tempSocket("thousand.sock");
  ServerLimits limits;
  limits.maxClients = kClients + 1;
  Server server(bindUnixSocket(path), limits, {});
  server.start();
  Client early(path);
  early.send({{"cmd", "subscribe"}});
  ASSERT_TRUE(early.read(10s));
  // Stacks at 20 Hz all through the storm, for the early subscriber.
  std::atomic<bool> publishing{true};
  std::atomic<std::uint64_t> published{0};
  std::thread publisher([&] {
    while (publishing) {
      server.publish(makeResult(++published, 1));
      std::this_thread::sleep_for(50ms);
    }
  });
  const auto t0 = Clock::now();
  std::vector<std::unique_ptr<Client>> clients;
  for (int i = 0; i < kClients; ++i) {
    clients.push_back(std::make_unique<Client>(path));
    clients.back()->send({{"cmd", "subscribe"}});
  }
  const double connectMs = msSince(t0);
  int subscribed = 0;
  for (auto& c : clients)
    for (int k = 0; k < 100; ++k) {  // detection lines may come before the reply is read
      auto m = c->read(10s);
      if (!m) break;
      if ((*m)["type"] == "subscribed") {
        ++subscribed;
        break;
      }
    }
  const double subscribedMs = msSince(t0);
  EXPECT_EQ(subscribed, kClients);
  EXPECT_EQ(server.counters().clients, static_cast<std::size_t>(kClients + 1));
  EXPECT_EQ(server.counters().refused + server.counters().refusedNoFd, 0u);
  publishing = false;
  publisher.join();
  // The last stack published after everyone subscribed reaches every client.
  const std::uint64_t last = ++published;
  server.publish(makeResult(last, 1));
  int gotLast = 0;
  for (auto& c : clients)
    for (int k = 0; k < 1000; ++k) {
      auto m = c->read(10s);
      if (!m) break;
      if ((*m)["type"] == "detections" && (*m)["stack"] == last) {
        ++gotLast;
        break;
      }
    }
  EXPECT_EQ(gotLast, kClients);
  // The early subscriber got every stack, in order, storm or not.
  std::uint64_t expect = 1;
  for (;;) {
    auto m = early.read(5s);
    ASSERT_TRUE(m) << "stack " << expect << " of " << last << " missing";
    if ((*m)["type"] != "detections") continue;
    ASSERT_EQ((*m)["stack"], expect);
    if (expect++ == last) break;
  }
  EXPECT_EQ(server.counters().droppedSlow, 0u);
  clients.clear();
  const auto left = Clock::now();
  while (server.counters().clients != 1 && Clock::now() - left < 10s) std::this_thread::sleep_for(10ms);
  EXPECT_EQ(server.counters().clients, 1u);
  std::printf("storm: %d clients connected in %.0f ms, all subscribed after %.0f ms; %ju stacks to the early "
              "subscriber, none missing; back to 1 client %.0f ms after they left\n",
              kClients, connectMs, subscribedMs, static_cast<std::uintmax_t>(last), msSince(left));
  server.stop(Clock::now() + 1s);
}

// The daemon out of file descriptors (its limit below what max_clients needs): accept() fails
// with EMFILE while the connection stays pending, so the listener stays readable and the server
// thread span in epoll_wait, and the clients waited forever without a word. Now each gets an
// error line and is closed; once descriptors are free again, clients are served at once.
TEST(ServerStorm, OutOfFileDescriptorsRefusesWithALineAndRecovers) {
  const std::string path = tempSocket("nofd.sock");
  Server server(bindUnixSocket(path), ServerLimits{}, {});
  server.start();
  // Sockets for the clients first (connect() needs no new descriptor), then every descriptor left.
  constexpr int kClients = 20;
  std::vector<int> sockets;
  for (int i = 0; i < kClients; ++i) sockets.push_back(::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0));
  std::vector<int> hogs;
  for (int fd; (fd = ::open("/dev/null", O_RDONLY | O_CLOEXEC)) >= 0;) hogs.push_back(fd);
  ASSERT_EQ(errno, EMFILE);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::snprintf(addr.sun_path, sizeof addr.sun_path, "%s", path.c_str());
  rusage before{};
  ::getrusage(RUSAGE_SELF, &before);
  const auto t0 = Clock::now();
  for (int s : sockets) ASSERT_EQ(::connect(s, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0) << std::strerror(errno);
  int refused = 0;
  double lastLineMs = 0;
  for (int s : sockets) {
    std::string got;
    char buf[512];
    timeval tv{5, 0};
    ::setsockopt(s, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    for (ssize_t n; (n = ::recv(s, buf, sizeof buf, 0)) > 0;) got.append(buf, static_cast<std::size_t>(n));
    if (got.find("\"type\":\"error\"") != std::string::npos && got.find("out of file descriptors") != std::string::npos) {
      ++refused;
      lastLineMs = msSince(t0);
    }
  }
  std::this_thread::sleep_for(500ms);  // a spinning server thread would burn this half second
  rusage after{};
  ::getrusage(RUSAGE_SELF, &after);
  const double cpuS = static_cast<double>(after.ru_utime.tv_sec - before.ru_utime.tv_sec + after.ru_stime.tv_sec -
                                          before.ru_stime.tv_sec) +
                      static_cast<double>(after.ru_utime.tv_usec - before.ru_utime.tv_usec + after.ru_stime.tv_usec -
                                          before.ru_stime.tv_usec) *
                          1e-6;
  const double wallS = msSince(t0) * 1e-3;
  EXPECT_EQ(refused, kClients);
  EXPECT_EQ(server.counters().refusedNoFd, static_cast<std::uint64_t>(kClients));
  EXPECT_LT(cpuS, 0.5 * wallS) << "the server thread spins";
  for (int fd : hogs) ::close(fd);
  for (int s : sockets) ::close(s);
  const auto freed = Clock::now();
  Client c(path);
  c.send({{"cmd", "hello"}});
  auto hello = c.read(5s);
  ASSERT_TRUE(hello);
  EXPECT_EQ((*hello)["type"], "hello");
  std::printf("out of descriptors: %d clients refused with a line within %.0f ms, %.2f s CPU in %.2f s; a new "
              "client served %.1f ms after descriptors were free\n",
              refused, lastLineMs, cpuS, wallS, msSince(freed));
  server.stop(Clock::now() + 1s);
}

// A request line of 1 GiB: the server keeps at most max_request_bytes of it, answers with the
// error line as soon as the limit is passed, skips the rest as it streams in (the process's
// resident memory does not grow with it), serves another client meanwhile, and the flooding
// connection works again after its newline.
TEST(ServerStorm, AGigabyteRequestLineIsRefusedWithoutBeingKept) {
  const std::string path = tempSocket("gigabyte.sock");
  Server server(bindUnixSocket(path), ServerLimits{}, {});
  server.start();
  Client flooder(path);
  Client other(path);
  const std::size_t rssBefore = residentBytes();
  constexpr std::size_t kLine = std::size_t{1} << 30;
  std::atomic<bool> sent{false};
  std::atomic<double> sentMs{0};
  const auto t0 = Clock::now();
  std::thread sender([&] {
    const std::string block(std::size_t{1} << 20, 'x');
    auto sendAll = [&](const char* p, std::size_t n) {
      while (n > 0) {
        const ssize_t k = ::send(flooder.fd(), p, n, MSG_NOSIGNAL);
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) return false;
        p += k;
        n -= static_cast<std::size_t>(k);
      }
      return true;
    };
    for (std::size_t done = 0; done < kLine; done += block.size())
      if (!sendAll(block.data(), block.size())) return;
    sendAll("\n", 1);
    sentMs = msSince(t0);
    sent = true;
  });
  const auto refusal = flooder.read(60s);
  const double refusalMs = msSince(t0);
  ASSERT_TRUE(refusal);
  EXPECT_EQ((*refusal)["type"], "error");
  EXPECT_EQ((*refusal)["error"], "request longer than 4096 bytes");
  std::size_t rssPeak = residentBytes();
  double slowestOtherMs = 0;
  int otherReplies = 0;
  while (!sent) {
    const auto asked = Clock::now();
    other.send({{"cmd", "hello"}});
    const auto reply = other.read(10s);
    ASSERT_TRUE(reply);
    EXPECT_EQ((*reply)["type"], "hello");
    slowestOtherMs = std::max(slowestOtherMs, msSince(asked));
    ++otherReplies;
    rssPeak = std::max(rssPeak, residentBytes());
    std::this_thread::sleep_for(20ms);
  }
  sender.join();
  flooder.send({{"cmd", "hello"}, {"id", 7}});
  const auto after = flooder.read(10s);
  ASSERT_TRUE(after);
  EXPECT_EQ((*after)["type"], "hello");
  EXPECT_EQ((*after)["id"], 7);
  EXPECT_EQ(server.counters().oversized, 1u);
  const double grownMiB = (static_cast<double>(rssPeak) - static_cast<double>(rssBefore)) / (1 << 20);
  EXPECT_LT(grownMiB, 64.0);
  std::printf("1 GiB request line: error line after %.1f ms, the gigabyte through after %.0f ms, resident memory "
              "+%.1f MiB, another client answered %d times meanwhile (slowest %.1f ms)\n",
              refusalMs, sentMs.load(), grownMiB, otherReplies, slowestOtherMs);
  server.stop(Clock::now() + 1s);
}
