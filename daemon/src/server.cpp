// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/server.h"

#include <fcntl.h>
#include <spdlog/spdlog.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <map>
#include <set>
#include <system_error>

#include "fusedet/daemon/protocol.h"
#include "fusedet/daemon/thread_info.h"

namespace fusedet::daemon {
namespace {

constexpr std::uint64_t kListenerKey = 0;
constexpr std::uint64_t kWakeKey = 1;
constexpr std::size_t kReadChunk = 16384;
constexpr std::size_t kMaxReadPerWake = 262144;  // one busy client cannot monopolise the thread

[[noreturn]] void throwErrno(const std::string& what) {
  throw std::system_error(errno, std::generic_category(), what);
}

void setNonBlocking(int fd) {
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags < 0 || ::fcntl(fd, F_SETFL, flags | O_NONBLOCK) < 0) throwErrno("fcntl O_NONBLOCK");
}

}  // namespace

struct Server::Client {
  std::uint64_t key = 0;
  drivers::UniqueFd fd;
  ucred peer{0, 0, 0};
  std::string in;
  bool discarding = false;  // skipping the rest of an oversized request line
  bool readClosed = false;  // the client shut down its sending side
  bool dead = false;
  std::deque<std::shared_ptr<const std::string>> out;
  std::size_t offset = 0;  // bytes of out.front() already sent
  bool writeInterest = false;
  bool subscribed = false;
  std::set<std::string> classes;
  bool tracksSubscribed = false;
  std::set<std::string> trackClasses;
};

namespace {

std::string octal(unsigned mode) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04o", mode & 07777u);
  return buf;
}

// A socket in a directory that others may write to can be removed, replaced or pre-created by
// them (the sticky bit stops the first two, not the last): only its owner is safe there.
void checkSocketDirectory(const std::string& path) {
  std::filesystem::path dir = std::filesystem::path(path).parent_path();
  if (dir.empty()) dir = ".";
  struct stat st{};
  if (::stat(dir.c_str(), &st) < 0) throwErrno("socket directory " + dir.string());
  if ((st.st_mode & S_IWOTH) && st.st_uid != ::geteuid())
    throw std::system_error(std::make_error_code(std::errc::permission_denied),
                            "socket path " + path + ": its directory " + dir.string() + " is world-writable (mode " +
                                octal(st.st_mode) + ") and owned by uid " + std::to_string(st.st_uid) +
                                ", not by fusedetd's uid " + std::to_string(::geteuid()) +
                                ": another local user could replace or pre-create the socket there; use a directory "
                                "only fusedetd's user can write to (e.g. /run/fusedet)");
}

// The groups the peer had when it connected: its primary gid and its supplementary groups, from
// the kernel (SO_PEERGROUPS, Linux >= 4.13). Not from /proc/<pid>/status: the packaged unit's
// ProtectProc=invisible hides other users' processes from fusedetd, and by the time a queued
// connection is accepted its pid may be gone or reused.
std::vector<gid_t> peerGroups(int fd, const ucred& peer) {
  std::vector<gid_t> out(32);
  socklen_t len = static_cast<socklen_t>(out.size() * sizeof(gid_t));
  while (::getsockopt(fd, SOL_SOCKET, SO_PEERGROUPS, out.data(), &len) < 0) {
    if (errno != ERANGE || len <= out.size() * sizeof(gid_t)) {
      spdlog::warn("server: SO_PEERGROUPS: {}; judging uid {} by its primary group only", std::strerror(errno), peer.uid);
      return {peer.gid};
    }
    out.resize(len / sizeof(gid_t));  // the kernel said how many
  }
  out.resize(len / sizeof(gid_t));
  out.push_back(peer.gid);
  return out;
}

bool allowed(int fd, const ucred& peer, const ServerLimits& limits) {
  if (limits.allowGroups.empty() || peer.uid == 0 || peer.uid == ::geteuid()) return true;
  for (const gid_t g : peerGroups(fd, peer))
    for (const auto& [name, gid] : limits.allowGroups)
      if (g == gid) return true;
  return false;
}

}  // namespace

void checkPassedSocket(int fd, const SocketAccess& access) {
  sockaddr_un addr{};
  socklen_t len = sizeof addr;
  if (::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len) < 0) throwErrno("getsockname of the passed socket");
  if (len <= offsetof(sockaddr_un, sun_path) || addr.sun_path[0] == '\0') return;  // abstract or unnamed: no file
  const std::string path(addr.sun_path);
  struct stat st{};
  if (::stat(path.c_str(), &st) < 0) throwErrno("passed socket " + path);
  // Connecting needs write permission on the socket file; the other bits mean nothing for it.
  const unsigned mode = st.st_mode & 0777u;
  if ((mode & 0222u) & ~(access.mode & 0222u))
    throw std::runtime_error("passed socket " + path + " has mode " + octal(mode) + ": it lets more users connect than socket.mode " +
                             octal(access.mode) + " (SocketMode= in fusedetd.socket)");
  if (access.group && st.st_gid != *access.group)
    throw std::runtime_error("passed socket " + path + " belongs to gid " + std::to_string(st.st_gid) + ", not socket.group's " +
                             std::to_string(*access.group) + " (SocketGroup= in fusedetd.socket)");
}

drivers::UniqueFd bindUnixSocket(const std::string& path, const SocketAccess& access) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (path.empty() || path.size() >= sizeof addr.sun_path)
    throw std::system_error(std::make_error_code(std::errc::filename_too_long), "socket path '" + path + "'");
  std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
  checkSocketDirectory(path);
  drivers::UniqueFd fd(::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0));
  if (!fd.valid()) throwErrno("socket");
  auto* sa = reinterpret_cast<sockaddr*>(&addr);
  // Created owner-only, so no one can connect before mode and group are set below.
  const mode_t umaskBefore = ::umask(0177);
  struct RestoreUmask {
    mode_t m;
    ~RestoreUmask() { ::umask(m); }
  } restore{umaskBefore};
  if (::bind(fd.get(), sa, sizeof addr) < 0) {
    if (errno != EADDRINUSE) throwErrno("bind " + path);
    // A file exists: replace it only if it is a stale socket - connecting is refused (nobody
    // listens). Any other answer (EACCES: its owner keeps it from us; EPROTOTYPE: another kind
    // of socket) means it is not ours to remove.
    drivers::UniqueFd probe(::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0));
    if (!probe.valid()) throwErrno("socket");
    if (::connect(probe.get(), sa, sizeof addr) == 0)
      throw std::system_error(std::make_error_code(std::errc::address_in_use),
                              path + ": another fusedetd is serving on it");
    if (errno != ECONNREFUSED)
      throwErrno(path + ": exists and is not a stale socket (connecting to it failed otherwise than refused), left alone");
    if (::unlink(path.c_str()) < 0) throwErrno("removing the stale socket " + path);
    if (::bind(fd.get(), sa, sizeof addr) < 0) throwErrno("bind " + path);
  }
  if (access.group && ::chown(path.c_str(), static_cast<uid_t>(-1), *access.group) < 0)
    throwErrno("socket.group: chown " + path + " to gid " + std::to_string(*access.group));
  if (::chmod(path.c_str(), access.mode) < 0) throwErrno("socket.mode: chmod " + octal(access.mode) + " " + path);
  if (::listen(fd.get(), 64) < 0) throwErrno("listen " + path);
  return fd;
}

Server::Server(drivers::UniqueFd listener, ServerLimits limits, Handlers handlers)
    : listener_(std::move(listener)), handlers_(std::move(handlers)), limits_(limits) {
  setNonBlocking(listener_.get());
  epoll_.reset(::epoll_create1(EPOLL_CLOEXEC));
  if (!epoll_.valid()) throwErrno("epoll_create1");
  wake_.reset(::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK));
  if (!wake_.valid()) throwErrno("eventfd");
  epoll_event ev{};
  ev.events = EPOLLIN;
  ev.data.u64 = kListenerKey;
  if (::epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, listener_.get(), &ev) < 0) throwErrno("epoll_ctl listener");
  ev.data.u64 = kWakeKey;
  if (::epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, wake_.get(), &ev) < 0) throwErrno("epoll_ctl eventfd");
  spare_.reset(::open("/dev/null", O_RDONLY | O_CLOEXEC));
}

Server::~Server() { stop(std::chrono::steady_clock::now()); }

void Server::start() {
  beat_ = Stamp::now().ns;
  thread_ = std::thread([this] { run(); });
}

void Server::stop(std::chrono::steady_clock::time_point deadline) {
  if (!thread_.joinable()) return;
  deadline_ = deadline;
  stopping_ = true;
  const std::uint64_t one = 1;
  [[maybe_unused]] auto n = ::write(wake_.get(), &one, sizeof one);
  thread_.join();
}

void Server::publish(std::shared_ptr<const StackResult> result) {
  {
    std::lock_guard lock(mutex_);
    latest_ = result;
    // The server thread never blocks, so this only grows if it is starved of CPU; bound it anyway.
    if (pending_.size() >= 1024) pending_.erase(pending_.begin());
    pending_.push_back(std::move(result));
  }
  const std::uint64_t one = 1;
  [[maybe_unused]] auto n = ::write(wake_.get(), &one, sizeof one);
}

void Server::setLimits(const ServerLimits& limits) {
  std::lock_guard lock(mutex_);
  limits_ = limits;
}

ServerCounters Server::counters() const {
  std::lock_guard lock(mutex_);
  return counters_;
}

void Server::run() {
  nameThisThread("fd-server");
  epoll_event events[64];
  auto findClient = [this](std::uint64_t key) -> Client* {
    for (auto& c : clients_)
      if (c->key == key) return c.get();
    return nullptr;
  };
  while (!stopping_) {
    beat_ = Stamp::now().ns;
    const int n = ::epoll_wait(epoll_.get(), events, 64, listenerPausedUntil_ ? 20 : 200);
    if (n < 0 && errno != EINTR) {
      spdlog::error("server: epoll_wait: {}", std::strerror(errno));
      break;
    }
    if (listenerPausedUntil_ && std::chrono::steady_clock::now() >= *listenerPausedUntil_) {
      epoll_event ev{};
      ev.events = EPOLLIN;
      ev.data.u64 = kListenerKey;
      ::epoll_ctl(epoll_.get(), EPOLL_CTL_MOD, listener_.get(), &ev);
      listenerPausedUntil_.reset();
    }
    for (int i = 0; i < n; ++i) {
      const std::uint64_t key = events[i].data.u64;
      if (key == kWakeKey) {
        std::uint64_t v;
        [[maybe_unused]] auto r = ::read(wake_.get(), &v, sizeof v);
      } else if (key == kListenerKey) {
        accept();
      } else if (Client* c = findClient(key); c && !c->dead) {
        if (events[i].events & (EPOLLIN | EPOLLHUP | EPOLLERR)) readFrom(*c);
        if (!c->dead && (events[i].events & EPOLLOUT)) flush(*c);
      }
    }
    dispatch();
    // Clients are destroyed only here, so no event of this batch can point at a reused fd.
    const std::size_t before = clients_.size();
    std::erase_if(clients_, [](const std::unique_ptr<Client>& c) { return c->dead; });
    if (clients_.size() != before) updatePeers();
    std::lock_guard lock(mutex_);
    counters_.clients = clients_.size();
  }
  // Shutdown: no new clients; send what is queued until the deadline.
  ::epoll_ctl(epoll_.get(), EPOLL_CTL_DEL, listener_.get(), nullptr);
  dispatch();
  while (std::chrono::steady_clock::now() < deadline_) {
    bool pendingOutput = false;
    for (auto& c : clients_)
      if (!c->dead && !c->out.empty()) pendingOutput = true;
    if (!pendingOutput) break;
    const int n = ::epoll_wait(epoll_.get(), events, 64, 20);
    for (int i = 0; i < n; ++i)
      if (Client* c = findClient(events[i].data.u64); c && !c->dead && (events[i].events & EPOLLOUT)) flush(*c);
  }
  clients_.clear();
  std::lock_guard lock(mutex_);
  counters_.clients = 0;
  peers_.clear();
}

void Server::accept() {
  for (;;) {
    drivers::UniqueFd fd(::accept4(listener_.get(), nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC));
    if (!fd.valid()) {
      const int err = errno;
      if (err == EMFILE || err == ENFILE) {
        if (refuseWithoutDescriptor(err)) continue;
        pauseListener();
        return;
      }
      if (err != EAGAIN && err != EWOULDBLOCK && err != EINTR && err != ECONNABORTED)
        spdlog::warn("server: accept: {}", std::strerror(err));
      return;
    }
    ServerLimits limits;
    {
      std::lock_guard lock(mutex_);
      limits = limits_;
    }
    if (clients_.size() >= static_cast<std::size_t>(limits.maxClients)) {
      const std::string line = errorLine("too many clients (max_clients " + std::to_string(limits.maxClients) + ")");
      [[maybe_unused]] auto w = ::send(fd.get(), line.data(), line.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
      std::lock_guard lock(mutex_);
      ++counters_.refused;
      continue;
    }
    ucred peer{0, 0, 0};
    socklen_t credLen = sizeof peer;
    if (::getsockopt(fd.get(), SOL_SOCKET, SO_PEERCRED, &peer, &credLen) < 0) {
      spdlog::warn("server: SO_PEERCRED: {}; connection closed", std::strerror(errno));
      continue;
    }
    if (!allowed(fd.get(), peer, limits)) {
      std::string groups;
      for (const auto& [name, gid] : limits.allowGroups) groups += (groups.empty() ? "" : ", ") + name;
      const std::string why = "not allowed: uid " + std::to_string(peer.uid) + " (pid " + std::to_string(peer.pid) +
                              ") is in none of socket.allow_groups (" + groups + ")";
      spdlog::warn("server: refused a client: {}", why);
      {
        std::lock_guard lock(mutex_);
        ++counters_.refusedNotAllowed;  // counted before the client can read why
      }
      const std::string line = errorLine(why);
      [[maybe_unused]] auto w = ::send(fd.get(), line.data(), line.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
      continue;
    }
    if (limits.clientSendBuffer > 0 &&
        ::setsockopt(fd.get(), SOL_SOCKET, SO_SNDBUF, &limits.clientSendBuffer, sizeof limits.clientSendBuffer) < 0)
      spdlog::warn("server: SO_SNDBUF {}: {}", limits.clientSendBuffer, std::strerror(errno));
    auto c = std::make_unique<Client>();
    c->key = nextKey_++;
    c->fd = std::move(fd);
    c->peer = peer;
    epoll_event ev{};
    ev.events = EPOLLIN | EPOLLRDHUP;
    ev.data.u64 = c->key;
    if (::epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, c->fd.get(), &ev) < 0) {
      spdlog::warn("server: epoll_ctl client: {}", std::strerror(errno));
      continue;
    }
    spdlog::info("server: client {} connected: pid {} uid {} gid {}", c->key, peer.pid, peer.uid, peer.gid);
    clients_.push_back(std::move(c));
    {
      std::lock_guard lock(mutex_);
      ++counters_.accepted;
      counters_.clients = clients_.size();
    }
    updatePeers();
  }
}

bool Server::refuseWithoutDescriptor(int err) {
  const auto now = std::chrono::steady_clock::now();
  if (now - lastNoFdWarning_ >= std::chrono::seconds(1)) {  // once a second, not once a connection
    spdlog::warn("server: out of file descriptors ({}): refusing new clients", std::strerror(err));
    lastNoFdWarning_ = now;
  }
  if (!spare_.valid()) return false;
  spare_.reset();
  drivers::UniqueFd fd(::accept4(listener_.get(), nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC));
  const bool taken = fd.valid();
  if (taken) {
    const std::string line = errorLine(std::string("server out of file descriptors (") + std::strerror(err) + "); try again later");
    [[maybe_unused]] auto w = ::send(fd.get(), line.data(), line.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    fd.reset();
    std::lock_guard lock(mutex_);
    ++counters_.refusedNoFd;
  }
  spare_.reset(::open("/dev/null", O_RDONLY | O_CLOEXEC));
  return taken && spare_.valid();
}

void Server::pauseListener() {
  epoll_event ev{};
  ev.data.u64 = kListenerKey;
  ::epoll_ctl(epoll_.get(), EPOLL_CTL_MOD, listener_.get(), &ev);  // no events until resumed
  listenerPausedUntil_ = std::chrono::steady_clock::now() + std::chrono::milliseconds(100);
}

void Server::updatePeers() {
  std::vector<Peer> now;
  for (const auto& c : clients_)
    if (!c->dead) now.push_back({c->key, c->peer.pid, c->peer.uid, c->peer.gid, c->subscribed});
  std::lock_guard lock(mutex_);
  peers_ = std::move(now);
}

std::vector<Peer> Server::peers() const {
  std::lock_guard lock(mutex_);
  return peers_;
}

void Server::readFrom(Client& c) {
  std::size_t maxRequest;
  {
    std::lock_guard lock(mutex_);
    maxRequest = limits_.maxRequestBytes;
  }
  char buf[kReadChunk];
  std::size_t total = 0;
  while (!c.dead && !c.readClosed && total < kMaxReadPerWake) {
    const ssize_t n = ::recv(c.fd.get(), buf, sizeof buf, 0);
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno == EAGAIN || errno == EWOULDBLOCK) break;
      drop(c, false);
      return;
    }
    if (n == 0) {
      c.readClosed = true;  // half-close: replies already queued are still sent
      break;
    }
    total += static_cast<std::size_t>(n);
    std::string_view data(buf, static_cast<std::size_t>(n));
    while (!data.empty() && !c.dead) {
      const auto nl = data.find('\n');
      const std::string_view part = data.substr(0, nl);
      if (!c.discarding) c.in.append(part.substr(0, maxRequest + 1 - std::min(maxRequest + 1, c.in.size())));
      if (!c.discarding && c.in.size() > maxRequest) {
        // Over the limit: say so once and skip the rest of this line.
        queue(c, std::make_shared<const std::string>(
                     errorLine("request longer than " + std::to_string(maxRequest) + " bytes")));
        {
          std::lock_guard lock(mutex_);
          ++counters_.oversized;
        }
        c.in.clear();
        c.discarding = true;
      }
      if (nl == std::string_view::npos) break;
      if (c.discarding) {
        c.discarding = false;
      } else {
        std::string line = std::move(c.in);
        c.in.clear();
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (!line.empty()) handleLine(c, line);
      }
      data.remove_prefix(nl + 1);
    }
  }
  if (c.readClosed && !c.dead) {
    if (c.out.empty()) {
      drop(c, false);
    } else {
      epoll_event ev{};
      ev.events = EPOLLOUT;
      ev.data.u64 = c.key;
      ::epoll_ctl(epoll_.get(), EPOLL_CTL_MOD, c.fd.get(), &ev);
      c.writeInterest = true;
    }
  }
}

void Server::handleLine(Client& c, std::string_view line) {
  std::string error;
  nlohmann::json id;
  const auto request = parseRequest(line, error, &id);
  if (!request) {
    {
      std::lock_guard lock(mutex_);
      ++counters_.badRequests;
    }
    queue(c, std::make_shared<const std::string>(errorLine(error, id)));
    return;
  }
  nlohmann::json reply;
  switch (request->command) {
    case Request::Command::kHello:
      reply = handlers_.hello ? handlers_.hello() : nlohmann::json::object();
      reply["type"] = "hello";
      break;
    case Request::Command::kSubscribe:
      if (request->stream == "tracks") {
        c.tracksSubscribed = true;
        c.trackClasses = request->classes;
        reply = {{"type", "subscribed"}, {"stream", "tracks"}, {"classes", c.trackClasses}};
      } else {
        c.subscribed = true;
        c.classes = request->classes;
        reply = {{"type", "subscribed"}, {"classes", c.classes}};
      }
      updatePeers();
      break;
    case Request::Command::kUnsubscribe:
      if (request->stream != "tracks") c.subscribed = false;
      if (request->stream != "detections") c.tracksSubscribed = false;
      updatePeers();
      reply = {{"type", "unsubscribed"}};
      if (!request->stream.empty()) reply["stream"] = request->stream;
      break;
    case Request::Command::kLatest: {
      std::shared_ptr<const StackResult> latest;
      {
        std::lock_guard lock(mutex_);
        latest = latest_;
      }
      if (latest) {
        reply = resultToJson(*latest, {}, "latest");
      } else {
        reply = {{"type", "latest"}, {"stack", nullptr}, {"detections", nlohmann::json::array()}};
      }
      break;
    }
    case Request::Command::kStatus:
      reply = handlers_.status ? handlers_.status() : nlohmann::json::object();
      reply["type"] = "status";
      break;
  }
  if (!request->id.is_null()) reply["id"] = request->id;
  queue(c, std::make_shared<const std::string>(toLine(reply)));
}

void Server::queue(Client& c, std::shared_ptr<const std::string> line) {
  if (c.dead) return;
  std::size_t limit;
  {
    std::lock_guard lock(mutex_);
    limit = limits_.clientQueue;
    ++counters_.linesSent;
  }
  if (c.out.size() >= limit) {
    // The client does not keep up (or does not read at all): it goes, nobody waits for it.
    drop(c, true);
    return;
  }
  c.out.push_back(std::move(line));
  if (!c.writeInterest) flush(c);
}

void Server::flush(Client& c) {
  while (!c.out.empty()) {
    const std::string& s = *c.out.front();
    const ssize_t n = ::send(c.fd.get(), s.data() + c.offset, s.size() - c.offset, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno == EAGAIN || errno == EWOULDBLOCK) break;
      drop(c, false);
      return;
    }
    c.offset += static_cast<std::size_t>(n);
    if (c.offset == s.size()) {
      c.out.pop_front();
      c.offset = 0;
    }
  }
  if (c.out.empty() && c.readClosed) {
    drop(c, false);
    return;
  }
  updateInterest(c);
}

void Server::updateInterest(Client& c) {
  const bool want = !c.out.empty();
  if (want == c.writeInterest) return;
  epoll_event ev{};
  ev.events = (c.readClosed ? 0u : static_cast<unsigned>(EPOLLIN | EPOLLRDHUP)) | (want ? static_cast<unsigned>(EPOLLOUT) : 0u);
  ev.data.u64 = c.key;
  ::epoll_ctl(epoll_.get(), EPOLL_CTL_MOD, c.fd.get(), &ev);
  c.writeInterest = want;
}

void Server::drop(Client& c, bool slow) {
  if (c.dead) return;
  c.dead = true;
  spdlog::debug("server: client {} (pid {}) {}", c.key, c.peer.pid, slow ? "dropped: does not keep up" : "disconnected");
  ::epoll_ctl(epoll_.get(), EPOLL_CTL_DEL, c.fd.get(), nullptr);
  c.fd.reset();
  c.out.clear();
  std::lock_guard lock(mutex_);
  if (slow) ++counters_.droppedSlow;
  else ++counters_.disconnected;
}

void Server::dispatch() {
  std::vector<std::shared_ptr<const StackResult>> results;
  {
    std::lock_guard lock(mutex_);
    results.swap(pending_);
    counters_.results += results.size();
  }
  for (const auto& r : results) {
    // One encoded line per distinct class filter, shared by the clients using it.
    std::map<std::set<std::string>, std::shared_ptr<const std::string>> lines, trackLines;
    for (auto& c : clients_) {
      if (c->dead) continue;
      if (c->subscribed) {
        auto& line = lines[c->classes];
        if (!line) line = std::make_shared<const std::string>(toLine(resultToJson(*r, c->classes)));
        queue(*c, line);
      }
      if (c->tracksSubscribed) {
        auto& line = trackLines[c->trackClasses];
        if (!line) line = std::make_shared<const std::string>(toLine(tracksToJson(*r, c->trackClasses)));
        queue(*c, line);
      }
    }
    latency_.add(static_cast<double>(Stamp::now() - r->sensorStamp) * 1e-6);
  }
}

}  // namespace fusedet::daemon
