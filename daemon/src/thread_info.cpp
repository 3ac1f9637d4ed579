// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/thread_info.h"

#include <pthread.h>
#include <tbb/task_scheduler_observer.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fusedet::daemon {

void nameThisThread(const std::string& name) { ::pthread_setname_np(::pthread_self(), name.substr(0, 15).c_str()); }

class TbbWorkerNames::Observer : public tbb::task_scheduler_observer {
 public:
  explicit Observer(std::string name) : name_(std::move(name)) { observe(true); }
  ~Observer() override { observe(false); }
  void on_scheduler_entry(bool worker) override {
    if (worker) nameThisThread(name_);
  }

 private:
  std::string name_;
};

TbbWorkerNames::TbbWorkerNames(std::string name) : observer_(std::make_unique<Observer>(std::move(name))) {}
TbbWorkerNames::~TbbWorkerNames() = default;

std::vector<ThreadCpu> processThreadCpu() {
  std::vector<ThreadCpu> out;
  const double msPerTick = 1e3 / static_cast<double>(::sysconf(_SC_CLK_TCK));
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task", ec)) {
    std::ifstream in(entry.path() / "stat");
    std::string line;
    if (!std::getline(in, line)) continue;  // the thread ended meanwhile
    // "tid (comm) state ..." - comm may hold spaces and parentheses: it ends at the last ')'.
    const auto open = line.find('('), close = line.rfind(')');
    if (open == std::string::npos || close == std::string::npos || close < open) continue;
    ThreadCpu t;
    t.tid = std::atoi(line.c_str());
    t.name = line.substr(open + 1, close - open - 1);
    std::istringstream rest(line.substr(close + 2));
    std::string field;
    double utime = 0, stime = 0;
    for (int i = 3; i <= 15 && rest >> field; ++i) {  // fields 14 and 15: utime, stime (clock ticks)
      if (i == 14) utime = std::stod(field);
      if (i == 15) stime = std::stod(field);
    }
    t.cpuMs = (utime + stime) * msPerTick;
    out.push_back(std::move(t));
  }
  std::sort(out.begin(), out.end(), [](const ThreadCpu& a, const ThreadCpu& b) { return a.tid < b.tid; });
  return out;
}

}  // namespace fusedet::daemon
