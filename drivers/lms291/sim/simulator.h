// SPDX-License-Identifier: Apache-2.0
#pragma once
// Simulator: a SICK LMS 291 on a pseudo-terminal. The host (a driver) opens the pty's slave
// side (or the symlink `link`); the simulator plays the device on the master side.
//
// Line speed. A pty accepts any termios speed but does not pace bytes, so the simulator
//  - paces its own output at the device's current baud (10 bits per byte, 8N1) on a virtual
//    line: each telegram is written whole once its last byte has left it (a late thread
//    replays the missed rotations and writes what is due, never splitting a telegram), and
//  - reads the speed the host set on its side (TCGETS2 on the master returns the slave's
//    termios). Bytes written by the host while its speed differs from the device's are
//    discarded (a real LMS sees framing errors and ignores them), and device output while
//    the speeds differ is not delivered (the host's UART would drop it as framing errors).
// Device behaviour: power-on telegram (0x90) at the power-on baud, baud switch after the reply
// has been sent at the old speed, variant, configuration (EEPROM: survives power cycles),
// status, type, continuous B0 output (mode 24; mode 2A interlaced partial scans), F5 range +
// remission (mode 2B, measuring mode 0x0D/0x0E), one scan on request (0x30 01). A new scan
// is ready every mirror rotation (75 Hz; 0.5 deg needs 2, 0.25 deg 4 rotations); a scan is
// sent only if the line is idle, so slow lines drop scans like the device does.
// Faults: bit flips / dropped bytes per output byte, garbage bursts between telegrams, NAKs,
// silence, vanish/reappear (pty closed, link removed, new pty + power-on later).

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "fusedet/core/result.h"
#include "fusedet/drivers/lms291/protocol.h"
#include "fusedet/drivers/lms291/telegram.h"
#include "fusedet/drivers/unique_fd.h"
#include "log_scans.h"
#include "scene.h"

namespace fusedet::drivers::lms291::sim {

struct Faults {
  double bitFlipRate = 0;  // per output byte: one random bit flipped
  double dropRate = 0;     // per output byte: byte not sent
  double garbageRate = 0;  // per telegram: a burst of 1..16 random bytes before it
  double nakRate = 0;      // per valid request: answered with NAK instead
  // Request -> ACK (a late device; longer than the host's ACK timeout makes it send the request
  // again, and every copy is answered).
  std::chrono::milliseconds ackDelay{0};
  bool operator==(const Faults&) const = default;
};

struct SimOptions {
  std::string link;                    // symlink to the slave ("" = none)
  // Attach to an existing tty instead of creating a pty (a socat/qemu pty end, or a real serial
  // port): the other side's speed cannot be read there, so bytes are taken to match; on a real
  // port the simulator sets the line speed itself and a mismatch is physical.
  std::string attach;
  std::string type = "LMS291;S05";     // reply to 0x3A
  std::string firmware = "V02.10 ";    // 7 characters
  int powerOnBaud = 9600;              // as if the permanent-baud flag were set, if not 9600
  bool powerOnTelegram = true;
  Variant variant{180, 50};            // at power-on
  std::uint8_t status = 0x10;          // status byte of normal replies
  SceneOptions scene;
  // Instead of the room: these scans, one per scan in order, looping at the end (lms291-sim
  // --log). The device then accepts only the log's variant and range unit: a host asking for
  // another is refused (variant 0x3B / configuration 0x77 answered "not accepted", reason on
  // stderr), no resampling. A host asking for remission from a log without it gets 0 remissions.
  std::shared_ptr<const LoggedScans> log;
  bool counterBeam = false;            // beam 0 carries the sent-scan counter: 1 m + n mm (n mod 4000)
  Faults faults;
  std::uint64_t seed = 1;
  std::chrono::microseconds replyDelay{2000};  // request received -> reply queued
  bool trace = false;                  // one stderr line per host read and per device speed change
};

struct SimCounters {
  std::uint64_t bytesOut = 0;          // bytes put on the line (after faults)
  std::uint64_t telegramsOut = 0;      // telegrams put on the line
  std::uint64_t scansOut = 0;          // measured-value telegrams (B0/F5) put on the line
  std::uint64_t scansSkipped = 0;      // scans not sent because the line was busy
  // Scans of rotations given up because the simulator thread was stopped for over a second
  // (shorter delays are replayed in time order, so scheduling jitter never skips a scan).
  std::uint64_t scansStalled = 0;
  std::uint64_t telegramsDamaged = 0;  // telegrams with >= 1 flipped or dropped byte
  std::uint64_t scansDamaged = 0;      // of them measured-value telegrams
  // Damaged scans whose CRC still matches (bit flips only, no drops): no receiver can reject them.
  std::uint64_t scansCrcBlind = 0;
  std::uint64_t bitFlips = 0;
  std::uint64_t droppedBytes = 0;
  std::uint64_t garbageBytes = 0;
  std::uint64_t requests = 0;          // valid host telegrams
  std::uint64_t badRequests = 0;       // host telegrams with a bad CRC (answered NAK)
  std::uint64_t naksInjected = 0;
  std::uint64_t ignoredBytes = 0;      // host bytes at the wrong speed
  std::uint64_t undeliveredBytes = 0;  // device bytes while the host speed differed
  // Device bytes refused because the host's receive buffer was full: it stopped reading for longer
  // than a real serial port's kernel buffer (640 KB) lasts; a pty's smaller buffer does not count.
  std::uint64_t overrunBytes = 0;
  std::uint64_t vanishes = 0;
  std::uint64_t powerOns = 0;
};

struct SimState {
  int baud = 9600;
  int hostBaud = 0;  // what the host set on the pty
  std::uint8_t mode = 0x25;
  bool streaming = false;
  Variant variant;
  std::vector<std::uint8_t> config;
  bool present = true;
};

class Simulator {
 public:
  explicit Simulator(SimOptions options);
  ~Simulator();
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  Result<void> start();  // creates the pty (and link), sends power-on, runs the device thread
  void stop();           // joins the thread, removes the link

  std::string slavePath() const;
  const std::string& linkPath() const { return options_.link; }
  SimCounters counters() const;
  SimState state() const;

  void setFaults(const Faults& f);
  void setStatus(std::uint8_t status);
  void nakStorm(int requests);                    // the next `requests` valid requests get NAK
  void silence(std::chrono::milliseconds d);      // neither reads nor writes for d
  void vanish(std::chrono::milliseconds d);       // pty gone for d, then power-on again
  void powerCycle();                              // the device restarts; the pty stays (9600, monitoring)
  // Numbers (see SimOptions::counterBeam) of the scans that went out damaged, in order.
  std::vector<std::uint64_t> damagedScans() const;
  std::vector<std::uint64_t> crcBlindScans() const;  // damaged but with a matching CRC

 private:
  struct Output {
    std::vector<std::uint8_t> bytes;
    std::chrono::steady_clock::time_point notBefore;
    bool telegram = false;
    bool scan = false;
    int baudAfter = 0;  // switch the device speed once these bytes are on the line
    std::uint64_t scanNumber = 0;  // scans: how many scans were queued before this one
  };
  using Clock = std::chrono::steady_clock;

  Result<void> createPty();
  Result<void> attachTty();
  Result<void> openLine() { return options_.attach.empty() ? createPty() : attachTty(); }
  void destroyPty();
  void powerOn();
  void run();
  void readHost(Clock::time_point now);
  void handleRequest(const Telegram& t, Clock::time_point now);
  void reply(std::uint8_t command, std::vector<std::uint8_t> data, Clock::time_point at, int baudAfter = 0);
  void queueScan(Clock::time_point now);
  std::vector<std::uint16_t> scanValues(int rotation, int rotations, std::vector<std::uint16_t>* remission);
  std::uint16_t encodeRange(double meters) const;
  bool logRefuses(std::optional<Variant> v, std::optional<Unit> unit) const;
  void pumpOutput(Clock::time_point now);
  void toHost(std::vector<std::uint8_t> bytes);
  void flushToHost();
  std::size_t hostReadRoom() const;
  Clock::duration lineTime(std::size_t bytes) const;
  int hostBaud() const;
  void setDeviceBaud(int baud);

  SimOptions options_;
  Scene scene_;
  mutable std::mutex mutex_;
  std::atomic<bool> running_{false};
  std::thread thread_;
  UniqueFd master_;
  UniqueFd slaveHold_;  // keeps the slave open: no EIO on the master while no host is attached
  std::string slavePath_;
  TelegramReader reader_{Direction::kFromHost};
  std::mt19937_64 rng_;

  // Device state.
  int baud_ = 9600;
  std::uint8_t mode_ = 0x25;
  Variant variant_;
  std::vector<std::uint8_t> config_;
  std::vector<std::pair<int, int>> remissionRanges_;  // mode 2B subranges (1-based)
  std::uint8_t status_ = 0x10;
  std::uint64_t rotation_ = 0;
  std::uint8_t telegramIndex_ = 0;
  Clock::time_point nextRotation_;
  Clock::time_point lineFreeAt_;  // when the last output unit's last byte left the line
  std::deque<Output> out_;
  // Units that have left the line but not yet entered the pty: a real serial port's kernel
  // buffer holds 640 KB (Linux tty flip buffers, 13 s at 500 kbaud), a pty only ~16 KB (0.3 s),
  // less than a loaded machine may leave the host's reader unscheduled. They wait here in order
  // and enter the pty whole, so the host never waits inside a telegram for held-back bytes.
  std::deque<std::vector<std::uint8_t>> toHost_;
  std::size_t toHostBytes_ = 0;
  Faults faults_;
  int nakStorm_ = 0;
  Clock::time_point silentUntil_;
  Clock::time_point reappearAt_;
  std::chrono::milliseconds vanishRequest_{-1};
  std::uint64_t scansQueued_ = 0;
  std::uint64_t logScan_ = 0;  // with options_.log: index of the next logged scan (mod size)
  bool present_ = false;
  SimCounters counters_;
  std::vector<std::uint64_t> damagedScans_;
  std::vector<std::uint64_t> crcBlindScans_;
};

}  // namespace fusedet::drivers::lms291::sim
