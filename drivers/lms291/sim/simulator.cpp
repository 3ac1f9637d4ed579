// SPDX-License-Identifier: Apache-2.0
#include "simulator.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "fusedet/drivers/serial_port.h"

namespace fusedet::drivers::lms291::sim {

namespace {
constexpr auto kRotation = std::chrono::nanoseconds(1'000'000'000 / 75);  // mirror at 75 Hz
constexpr std::uint8_t kDeviceAddress = 0x80;
// Rotations missed while the thread was descheduled are replayed up to this far back; a longer
// gap is a stopped process, and its scans are counted (scansStalled) rather than burst out.
constexpr auto kMaxCatchUp = std::chrono::seconds(1);
// Receive buffer of a real host serial port (Linux TTYB_DEFAULT_MEM_LIMIT): only beyond it are
// device bytes lost (overrunBytes). A pty holds less, so the simulator keeps the rest (toHost_).
constexpr std::size_t kHostBuffer = 640 * 1024;
// The pty slave's line-discipline read buffer (N_TTY): TIOCINQ counts bytes waiting there.
constexpr int kPtyReadBuffer = 4095;

std::vector<std::uint8_t> ascii(const std::string& s) { return {s.begin(), s.end()}; }

std::vector<std::uint8_t> defaultConfig() {
  std::vector<std::uint8_t> c(kConfigSize, 0);
  c[2] = 0x46;  // stop threshold
  c[5] = kMeasuring8m;
  c[6] = 0;  // cm, the factory default
  return c;
}
}  // namespace

Simulator::Simulator(SimOptions options)
    : options_(std::move(options)), scene_(options_.scene), rng_(options_.seed), variant_(options_.variant),
      config_(defaultConfig()), status_(options_.status), faults_(options_.faults) {}

Simulator::~Simulator() { stop(); }

Result<void> Simulator::createPty() {
  UniqueFd master(posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC));
  if (!master.valid()) return errnoError(errno, "posix_openpt");
  if (grantpt(master.get()) != 0 || unlockpt(master.get()) != 0) return errnoError(errno, "unlockpt");
  char name[128];
  if (ptsname_r(master.get(), name, sizeof name) != 0) return errnoError(errno, "ptsname");
  UniqueFd slave(::open(name, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC));
  if (!slave.valid()) return errnoError(errno, std::string("open ") + name);
  // Raw at once: the default line discipline would echo our own output back to us.
  termios t{};
  tcgetattr(slave.get(), &t);
  cfmakeraw(&t);
  cfsetspeed(&t, B9600);
  tcsetattr(slave.get(), TCSANOW, &t);
  if (!options_.link.empty()) {
    const std::string tmp = options_.link + ".new";
    ::unlink(tmp.c_str());
    if (::symlink(name, tmp.c_str()) != 0 || ::rename(tmp.c_str(), options_.link.c_str()) != 0)
      return errnoError(errno, "link " + options_.link + " -> " + name);
  }
  master_ = std::move(master);
  slaveHold_ = std::move(slave);
  slavePath_ = name;
  return {};
}

Result<void> Simulator::attachTty() {
  auto port = SerialPort::open(options_.attach, options_.powerOnBaud);
  if (!port) return port.error();
  master_.reset(port->fd() >= 0 ? ::dup(port->fd()) : -1);
  if (!master_.valid()) return errnoError(errno, "dup " + options_.attach);
  slavePath_ = options_.attach;
  return {};
}

void Simulator::destroyPty() {
  if (!options_.link.empty()) ::unlink(options_.link.c_str());
  toHost_.clear();
  toHostBytes_ = 0;
  master_.reset();
  slaveHold_.reset();
}

void Simulator::setDeviceBaud(int baud) {
  if (options_.trace) std::fprintf(stderr, "%s sim: device now at %d baud\n", Stamp::now().toString().c_str(), baud);
  baud_ = baud;
  if (!options_.attach.empty() && master_.valid()) {
    // Our side of a real line runs at the device's speed.
    termios t{};
    if (tcgetattr(master_.get(), &t) == 0) {
      speed_t s = baud == 9600 ? B9600 : baud == 19200 ? B19200 : baud == 38400 ? B38400 : B500000;
      cfsetspeed(&t, s);
      (void)tcsetattr(master_.get(), TCSADRAIN, &t);
    }
  }
}

void Simulator::powerOn() {
  setDeviceBaud(options_.powerOnBaud);
  mode_ = static_cast<std::uint8_t>(Mode::kMonitoring);
  variant_ = options_.variant;
  out_.clear();
  reader_.clear();
  rotation_ = 0;
  telegramIndex_ = 0;
  lineFreeAt_ = Clock::now();
  nextRotation_ = lineFreeAt_ + kRotation;
  ++counters_.powerOns;
  if (options_.powerOnTelegram) reply(kPowerOnReply, ascii(options_.type + ";" + options_.firmware), Clock::now());
}

Result<void> Simulator::start() {
  std::lock_guard lock(mutex_);
  if (running_) return {};
  if (auto r = openLine(); !r) return r;
  present_ = true;
  powerOn();
  running_ = true;
  thread_ = std::thread([this] { run(); });
  return {};
}

void Simulator::stop() {
  running_ = false;
  if (thread_.joinable()) thread_.join();
  std::lock_guard lock(mutex_);
  destroyPty();
  present_ = false;
}

std::string Simulator::slavePath() const {
  std::lock_guard lock(mutex_);
  return slavePath_;
}

SimCounters Simulator::counters() const {
  std::lock_guard lock(mutex_);
  return counters_;
}

SimState Simulator::state() const {
  std::lock_guard lock(mutex_);
  SimState s;
  s.baud = baud_;
  s.hostBaud = present_ ? hostBaud() : 0;
  s.mode = mode_;
  s.streaming = mode_ == 0x24 || mode_ == 0x2A || mode_ == 0x2B;
  s.variant = variant_;
  s.config = config_;
  s.present = present_;
  return s;
}

std::vector<std::uint64_t> Simulator::crcBlindScans() const {
  std::lock_guard lock(mutex_);
  return crcBlindScans_;
}

std::vector<std::uint64_t> Simulator::damagedScans() const {
  std::lock_guard lock(mutex_);
  return damagedScans_;
}

void Simulator::setFaults(const Faults& f) {
  std::lock_guard lock(mutex_);
  faults_ = f;
}
void Simulator::setStatus(std::uint8_t status) {
  std::lock_guard lock(mutex_);
  status_ = status;
}
void Simulator::nakStorm(int requests) {
  std::lock_guard lock(mutex_);
  nakStorm_ = requests;
}
void Simulator::silence(std::chrono::milliseconds d) {
  std::lock_guard lock(mutex_);
  silentUntil_ = Clock::now() + d;
}
void Simulator::powerCycle() {
  std::lock_guard lock(mutex_);
  powerOn();
}
void Simulator::vanish(std::chrono::milliseconds d) {
  std::lock_guard lock(mutex_);
  vanishRequest_ = d;
}

int Simulator::hostBaud() const {
  if (!options_.attach.empty()) return baud_;  // not observable: assume the host follows
  int b = 0;
  if (!master_.valid() || detail::getBaudTermios2(master_.get(), &b) != 0) return 0;
  return b;
}

void Simulator::reply(std::uint8_t command, std::vector<std::uint8_t> data, Clock::time_point at, int baudAfter) {
  Telegram t;
  t.address = kDeviceAddress;
  t.command = command;
  t.data = std::move(data);
  t.status = status_;
  if (faults_.garbageRate > 0 && std::uniform_real_distribution<>(0, 1)(rng_) < faults_.garbageRate) {
    Output g;
    g.bytes.resize(std::uniform_int_distribution<std::size_t>(1, 16)(rng_));
    for (auto& b : g.bytes) b = static_cast<std::uint8_t>(rng_());
    g.notBefore = at;
    counters_.garbageBytes += g.bytes.size();
    out_.push_back(std::move(g));
  }
  Output o;
  o.bytes = encode(t);
  o.notBefore = at;
  o.telegram = true;
  o.scan = command == kMeasuredValues || command == kRangeRemission;
  o.baudAfter = baudAfter;
  o.scanNumber = scansQueued_;
  out_.push_back(std::move(o));
}

std::uint16_t Simulator::encodeRange(double meters) const {
  const int bits = distanceBits(config_[5]);
  const std::uint32_t maxCode = (1u << bits) - 1;
  if (meters <= 0) return static_cast<std::uint16_t>(maxCode);  // no valid value
  const double unit = config_[6] == 1 ? 1e-3 : 1e-2;
  const auto code = static_cast<std::uint32_t>(std::lround(meters / unit));
  if (code > maxCode - 9) return static_cast<std::uint16_t>(maxCode - 8);  // beyond the maximum
  return static_cast<std::uint16_t>(code);
}

// With --log, only the log's own scan mode is served: resampling would invent ranges.
bool Simulator::logRefuses(std::optional<Variant> v, std::optional<Unit> unit) const {
  if (!options_.log) return false;
  const LoggedScans& l = *options_.log;
  const auto cdeg = [](const Variant& x) { return std::to_string(x.angleDeg) + " deg / " + std::to_string(x.resolutionCdeg) + " cdeg"; };
  const auto name = [](Unit u) { return std::string(u == Unit::kMm ? "mm" : "cm"); };
  std::string asked, held;
  if (v && *v != l.variant) asked = cdeg(*v), held = cdeg(l.variant);
  if (unit && *unit != l.unit) asked = "range unit " + name(*unit), held = "range unit " + name(l.unit);
  if (asked.empty()) return false;
  std::fprintf(stderr, "lms291-sim: error: the host asked for %s, the log holds %s: refused (configure the driver like the log's rig)\n",
               asked.c_str(), held.c_str());
  return true;
}

std::vector<std::uint16_t> Simulator::scanValues(int rotation, int rotations, std::vector<std::uint16_t>* remission) {
  std::vector<std::uint16_t> values;
  const int n = variant_.beams();
  if (options_.log) {  // the logged scan, re-encoded in the device's current unit
    const LaserScan& s = options_.log->scans[logScan_ % options_.log->scans.size()];
    for (int i = rotation; i < n; i += rotations) {
      const auto k = static_cast<std::size_t>(i);
      const double r = k < s.ranges.size() && s.ranges[k] > 0 ? s.ranges[k] : 0.0;  // 0 / NaN: no return
      values.push_back(encodeRange(r));
      if (remission)
        remission->push_back(k < s.remissions.size() ? static_cast<std::uint16_t>(std::lround(std::clamp(s.remissions[k], 0.0f, 65535.0f))) : 0);
    }
    if (rotation + 1 >= rotations) ++logScan_;  // interlaced: after the scan's last part
    return values;
  }
  for (int i = rotation; i < n; i += rotations) {
    const double deg = variant_.startDeg() + i * variant_.resolutionCdeg / 100.0;
    const Hit h = scene_.cast(deg * M_PI / 180.0);
    values.push_back(encodeRange(h.range));
    if (remission) remission->push_back(static_cast<std::uint16_t>(std::lround(h.remission * 1000)));
  }
  if (options_.counterBeam && rotation == 0 && !values.empty())
    values[0] = static_cast<std::uint16_t>(1000 + scansQueued_ % 4000);
  return values;
}

void Simulator::queueScan(Clock::time_point now) {
  const Unit unit = config_[6] == 1 ? Unit::kMm : Unit::kCm;
  const int m = variant_.rotations();
  if (mode_ == 0x2B) {
    std::vector<RemissionBlock> blocks;
    std::vector<std::uint16_t> rem;
    const std::vector<std::uint16_t> all = scanValues(0, 1, &rem);
    for (auto [s, e] : remissionRanges_) {
      RemissionBlock b;
      b.start = s;
      b.end = e;
      b.countWord.unit = unit;
      b.ranges.assign(all.begin() + s - 1, all.begin() + e);
      b.remissions.assign(rem.begin() + s - 1, rem.begin() + e);
      blocks.push_back(std::move(b));
    }
    reply(kRangeRemission, encodeRangeRemission(blocks), now);
  } else {
    MeasuredValues v;
    v.countWord.unit = unit;
    if (mode_ == 0x2A) {
      const int r = static_cast<int>(rotation_ % static_cast<std::uint64_t>(m));
      v.values = scanValues(r, m, nullptr);
      v.countWord.partial = true;
      v.countWord.partialIndex = r * variant_.resolutionCdeg / 25;
    } else {
      v.values = scanValues(0, 1, nullptr);
    }
    if (config_[4] & 0x02) {
      v.scanIndex = static_cast<std::uint8_t>(rotation_);
      v.telegramIndex = telegramIndex_++;
    }
    reply(kMeasuredValues, encodeMeasuredValues(v), now);
  }
  ++scansQueued_;
}

void Simulator::handleRequest(const Telegram& t, Clock::time_point now) {
  const auto at = now + options_.replyDelay;
  const auto& d = t.data;
  const std::uint8_t r = t.command | kReplyBit;
  const bool fast = options_.type.find("S14") != std::string::npos;
  switch (static_cast<Command>(t.command)) {
    case Command::kReset:
      reply(kResetReply, {}, at, options_.powerOnBaud);
      mode_ = static_cast<std::uint8_t>(Mode::kMonitoring);
      reply(kPowerOnReply, ascii(options_.type + ";" + options_.firmware), at + std::chrono::milliseconds(100));
      return;
    case Command::kSwitchMode: {
      if (d.empty()) return reply(r, {2}, at);
      const std::uint8_t mm = d[0];
      if (mm == 0x00) {
        const bool ok = d.size() == 9 && std::equal(d.begin() + 1, d.end(), kInstallPassword);
        if (ok) mode_ = mm;
        return reply(r, {static_cast<std::uint8_t>(ok ? 0 : 1)}, at);
      }
      if (auto b = baudOfMode(mm)) return reply(r, {0}, at, *b);
      if (mm == 0x24 || mm == 0x25 || mm == 0x2A) {
        const bool wasStreaming = mode_ == 0x24 || mode_ == 0x2A || mode_ == 0x2B;
        mode_ = mm;
        if (!wasStreaming) nextRotation_ = now + kRotation;
        return reply(r, {0}, at);
      }
      if (mm == 0x2B) {
        // n subranges (start, end), 1-based inclusive; all in one telegram of <= 812 bytes.
        std::vector<std::pair<int, int>> ranges;
        bool ok = d.size() >= 3 && (config_[5] == 0x0D || config_[5] == 0x0E);
        const std::size_t n = ok ? u16(d, 1) : 0;
        ok = ok && n >= 1 && d.size() == 3 + 4 * n;
        std::size_t samples = 0;
        for (std::size_t i = 0; ok && i < n; ++i) {
          const int s = u16(d, 3 + 4 * i), e = u16(d, 5 + 4 * i);
          ok = s >= 1 && s <= e && e <= variant_.beams();
          ranges.emplace_back(s, e);
          samples += static_cast<std::size_t>(e - s + 1);
        }
        ok = ok && kFrameOverhead + 1 + 2 + 6 * n + 4 * samples + 1 <= 812;
        if (ok) {
          const bool wasStreaming = mode_ == 0x24 || mode_ == 0x2A || mode_ == 0x2B;
          mode_ = mm;
          remissionRanges_ = std::move(ranges);
          if (!wasStreaming) nextRotation_ = now + kRotation;
        }
        return reply(r, {static_cast<std::uint8_t>(ok ? 0 : 2)}, at);
      }
      return reply(r, {2}, at);  // modes this simulator does not model
    }
    case Command::kRequestValues: {
      if (d.size() != 1 || d[0] != 1) return reply(kUnknownCommandReply, {}, at);
      MeasuredValues v;
      v.countWord.unit = config_[6] == 1 ? Unit::kMm : Unit::kCm;
      v.values = scanValues(0, 1, nullptr);
      ++scansQueued_;
      return reply(kMeasuredValues, encodeMeasuredValues(v), at);
    }
    case Command::kStatus: {
      DeviceStatus s;
      s.firmware = options_.firmware;
      s.operatingMode = mode_;
      s.angleDeg = variant_.angleDeg;
      s.resolutionCdeg = variant_.resolutionCdeg;
      s.baud = baud_;
      s.unit = config_[6] == 1 ? Unit::kMm : Unit::kCm;
      return reply(r, encodeStatus(s), at);
    }
    case Command::kErrors: return reply(r, {}, at);
    case Command::kType: return reply(r, ascii(options_.type), at);
    case Command::kSetVariant: {
      if (fast) return reply(kUnknownCommandReply, {}, at);
      if (d.size() != 4) return reply(kUnknownCommandReply, {}, at);
      const Variant v{u16(d, 0), u16(d, 2)};
      const bool ok = v.valid() && !logRefuses(v, std::nullopt);
      if (ok) variant_ = v;
      std::vector<std::uint8_t> out{static_cast<std::uint8_t>(ok ? 1 : 0)};
      putU16(out, static_cast<std::uint16_t>(variant_.angleDeg));
      putU16(out, static_cast<std::uint16_t>(variant_.resolutionCdeg));
      return reply(r, out, at);
    }
    case Command::kReadConfig: return reply(r, config_, at);
    case Command::kWriteConfig: {
      const bool ok = mode_ == 0x00 && (d.size() == kConfigSize || d.size() == 32) && !logRefuses(std::nullopt, d[6] == 1 ? Unit::kMm : Unit::kCm);
      if (ok) std::copy(d.begin(), d.end(), config_.begin());
      std::vector<std::uint8_t> out{static_cast<std::uint8_t>(ok ? 1 : 0)};
      out.insert(out.end(), config_.begin(), config_.end());
      return reply(r, out, at + std::chrono::milliseconds(50));  // EEPROM write
    }
  }
  reply(kUnknownCommandReply, {}, at);
}

void Simulator::readHost(Clock::time_point now) {
  std::uint8_t buf[4096];
  for (;;) {
    const ssize_t n = ::read(master_.get(), buf, sizeof buf);
    if (n <= 0) break;
    if (now < silentUntil_) continue;
    if (options_.trace)
      std::fprintf(stderr, "%s sim: %zd bytes from host at %d baud, device at %d\n", Stamp::now().toString().c_str(), n,
                   hostBaud(), baud_);
    if (hostBaud() != baud_) {
      counters_.ignoredBytes += static_cast<std::uint64_t>(n);
      continue;
    }
    reader_.feed(std::span(buf, static_cast<std::size_t>(n)), Stamp::now());
  }
  while (auto e = reader_.next()) {
    if (e->kind == StreamEvent::Kind::kBadCrc) {
      ++counters_.badRequests;
      Output nak{{kNak}, now, false, false, 0};
      out_.push_back(nak);
    } else if (e->kind == StreamEvent::Kind::kTelegram) {
      ++counters_.requests;
      const bool refuse = nakStorm_ > 0 || (faults_.nakRate > 0 && std::uniform_real_distribution<>(0, 1)(rng_) < faults_.nakRate);
      if (refuse) {
        if (nakStorm_ > 0) --nakStorm_;
        ++counters_.naksInjected;
        out_.push_back(Output{{kNak}, now, false, false, 0});
        continue;
      }
      out_.push_back(Output{{kAck}, now + faults_.ackDelay, false, false, 0});
      handleRequest(e->telegram, now + faults_.ackDelay);
    }
  }
}

Simulator::Clock::duration Simulator::lineTime(std::size_t bytes) const {
  return std::chrono::nanoseconds(static_cast<std::int64_t>(byteSeconds(baud_) * 1e9 * static_cast<double>(bytes)));
}

void Simulator::pumpOutput(Clock::time_point now) {
  // The line is modelled in time, not by this thread's wake-ups: each output unit (telegram,
  // ACK/NAK, garbage burst) starts when it is due and the line is free, and is written to the
  // pty in one piece once its last byte has left the (virtual) UART. A descheduled simulator
  // thread therefore delays delivery, like a USB adapter's packet, but never splits a telegram
  // with a pause the host must take for a dead frame (the LMS leaves <= 14 ms between bytes)
  // and never loses line time it has to make up for by skipping scans.
  while (!out_.empty()) {
    Output& o = out_.front();
    const Clock::time_point start = std::max(lineFreeAt_, o.notBefore);
    const Clock::time_point end = start + lineTime(o.bytes.size());
    if (now < end) return;
    std::vector<std::uint8_t> bytes;
    bytes.reserve(o.bytes.size());
    bool damaged = false, dropped = false;
    for (std::uint8_t b : o.bytes) {
      if (faults_.dropRate > 0 && std::uniform_real_distribution<>(0, 1)(rng_) < faults_.dropRate) {
        ++counters_.droppedBytes;
        damaged = dropped = true;
        continue;
      }
      if (faults_.bitFlipRate > 0 && std::uniform_real_distribution<>(0, 1)(rng_) < faults_.bitFlipRate) {
        b ^= static_cast<std::uint8_t>(1u << std::uniform_int_distribution<int>(0, 7)(rng_));
        ++counters_.bitFlips;
        damaged = true;
      }
      bytes.push_back(b);
    }
    if (!bytes.empty()) {
      const int host = hostBaud();
      if (options_.trace)
        std::fprintf(stderr, "%s sim: sent 0x%02X (%zu bytes) at %d baud, host at %d%s\n", Stamp::now().toString().c_str(),
                     o.bytes.size() > 4 ? o.bytes[4] : o.bytes[0], bytes.size(), baud_, host,
                     host != baud_ ? " - NOT DELIVERED" : toHostBytes_ > 0 ? " - host buffer" : "");
      counters_.bytesOut += bytes.size();
      if (host == baud_)
        toHost(std::move(bytes));
      else
        counters_.undeliveredBytes += bytes.size();
    }
    lineFreeAt_ = end;
    if (o.telegram) {
      ++counters_.telegramsOut;
      if (o.scan) ++counters_.scansOut;
      if (damaged) {
        ++counters_.telegramsDamaged;
        if (o.scan) {
          ++counters_.scansDamaged;
          if (damagedScans_.size() < 1'000'000) damagedScans_.push_back(o.scanNumber);
          const std::size_t n = bytes.size();
          if (!dropped && n >= kFrameOverhead &&
              crc16(std::span(bytes).first(n - 2)) == (bytes[n - 2] | (bytes[n - 1] << 8))) {
            ++counters_.scansCrcBlind;
            crcBlindScans_.push_back(o.scanNumber);
          }
        }
      }
    }
    if (o.baudAfter) setDeviceBaud(o.baudAfter);
    out_.pop_front();
  }
}

// Into the host's receive buffer, behind what is already waiting there; bytes beyond a real
// port's buffer are an overrun, counted apart from those a speed mismatch swallows.
void Simulator::toHost(std::vector<std::uint8_t> bytes) {
  if (toHostBytes_ + bytes.size() > kHostBuffer) {
    const std::size_t keep = kHostBuffer - std::min(kHostBuffer, toHostBytes_);
    counters_.overrunBytes += bytes.size() - keep;
    bytes.resize(keep);
    if (bytes.empty()) return;
  }
  toHostBytes_ += bytes.size();
  toHost_.push_back(std::move(bytes));
  flushToHost();
}

// How many bytes the host's tty can take now without splitting a unit: the pty slave's read
// buffer has room for 4095 minus what waits in it (unknown on an attached tty: no limit here).
std::size_t Simulator::hostReadRoom() const {
  if (!slaveHold_.valid()) return kHostBuffer;
  int queued = 0;
  if (::ioctl(slaveHold_.get(), TIOCINQ, &queued) != 0) return kHostBuffer;
  return queued >= kPtyReadBuffer ? 0 : static_cast<std::size_t>(kPtyReadBuffer - queued);
}

// Waiting units enter the pty in order and whole while the host's read buffer has room for them
// (a unit the pty still cuts short keeps its rest at the front).
void Simulator::flushToHost() {
  while (!toHost_.empty() && master_.valid()) {
    std::vector<std::uint8_t>& unit = toHost_.front();
    if (unit.size() > hostReadRoom()) return;
    const ssize_t n = ::write(master_.get(), unit.data(), unit.size());
    if (n <= 0) return;
    const auto written = static_cast<std::size_t>(n);
    toHostBytes_ -= written;
    if (written < unit.size()) {
      unit.erase(unit.begin(), unit.begin() + n);
      return;
    }
    toHost_.pop_front();
  }
}

void Simulator::run() {
  std::unique_lock lock(mutex_);
  while (running_) {
    auto now = Clock::now();
    if (vanishRequest_.count() >= 0) {
      destroyPty();
      present_ = false;
      ++counters_.vanishes;
      reappearAt_ = now + vanishRequest_;
      vanishRequest_ = std::chrono::milliseconds(-1);
    }
    if (!present_) {
      if (now >= reappearAt_ && openLine()) {
        present_ = true;
        powerOn();
      } else {
        lock.unlock();
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
        lock.lock();
      }
      continue;
    }
    readHost(now);
    flushToHost();  // what waited for the host to read, before anything newer
    const bool streaming = mode_ == 0x24 || mode_ == 0x2A || mode_ == 0x2B;
    if (streaming && now < silentUntil_) nextRotation_ = now + kRotation;  // a hung device measures nothing
    if (streaming && now >= nextRotation_) {
      // Woke late: replay the rotations in time order (the device's mirror does not wait). Only
      // beyond kMaxCatchUp (a stopped process, not scheduling jitter) are rotations given up,
      // and their scans counted as stalled.
      const auto rotations = static_cast<std::uint64_t>(variant_.rotations());
      if (now - nextRotation_ > kMaxCatchUp) {
        const auto behind = static_cast<std::uint64_t>((now - nextRotation_) / kRotation);
        for (std::uint64_t i = 0; i < behind; ++i)
          if (++rotation_ % rotations == 0 || mode_ == 0x2A) ++counters_.scansStalled;
        nextRotation_ += behind * kRotation;
      }
      while (nextRotation_ <= now) {
        const Clock::time_point at = nextRotation_;
        ++rotation_;
        nextRotation_ += kRotation;
        const bool scanReady = mode_ == 0x2A || rotation_ % rotations == 0;
        if (!scanReady) continue;
        if (now >= silentUntil_) pumpOutput(at);  // what had left the line by then
        // Sent only if the line is idle at that rotation (a slow line drops scans).
        if (out_.empty())
          queueScan(at);
        else
          ++counters_.scansSkipped;
      }
    }
    if (now >= silentUntil_) pumpOutput(now);
    auto wake = now + std::chrono::milliseconds(5);
    if (streaming) wake = std::min(wake, nextRotation_);
    if (!out_.empty())
      wake = std::min(wake, std::max(lineFreeAt_, out_.front().notBefore) + lineTime(out_.front().bytes.size()));
    const int fd = master_.get();
    lock.unlock();
    const auto waitUs = std::chrono::duration_cast<std::chrono::microseconds>(wake - Clock::now()).count();
    if (waitUs > 0) {
      pollfd p{fd, POLLIN, 0};
      timespec ts{0, static_cast<long>(waitUs) * 1000};
      (void)::ppoll(&p, 1, &ts, nullptr);
    }
    lock.lock();
  }
}

}  // namespace fusedet::drivers::lms291::sim
