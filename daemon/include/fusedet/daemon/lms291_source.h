// SPDX-License-Identifier: Apache-2.0
#pragma once
// Lms291Source: the live SICK LMS 291 as a pipeline source. The driver's ScanStream owns the
// thread and reconnects on its own; each scan is handed to the sink, which never blocks.

#include <memory>

#include "fusedet/daemon/config.h"
#include "fusedet/daemon/source.h"
#include "fusedet/drivers/lms291/scan_stream.h"

namespace fusedet::daemon {

class Lms291Source : public Source {
 public:
  explicit Lms291Source(const Config& config);  // laser section, via rig.h's laserConfig
  ~Lms291Source() override;
  void start(SensorSink& sink) override;
  void stop() override;
  std::vector<SensorHealth> health() const override;

 private:
  drivers::lms291::Lms291Config config_;
  double reconnectMaxS_;
  std::unique_ptr<drivers::lms291::ScanStream> stream_;
};

}  // namespace fusedet::daemon
