// SPDX-License-Identifier: Apache-2.0
// Tracker::update per stack with N objects moving at walking to driving speeds in a 60 x 60 m
// area around the robot, detected with 0.3 m noise in 90 % of the stacks, plus 10 % clutter; three
// classes. Peer in the same run: the prediction and gated cost matrices alone (no assignment,
// no corrections), to show what the optimal assignment costs on top.
// Ends with "bench: tracker_ms_per_stack_<N> <ms>" lines (wall time; tracker_cpu_ms_per_stack_<N>:
// the thread's CPU time, what a loaded machine does not inflate).
#include <benchmark/benchmark.h>

#include <cstdio>
#include <random>

#include "fusedet/tracking/kalman.h"
#include "fusedet/tracking/tracker.h"
#include "headline_reporter.h"

namespace {

using namespace fusedet;
using namespace fusedet::tracking;

constexpr std::int64_t kStackNs = 100'000'000;  // 10 stacks per second
const char* const kClasses[] = {"car", "bike", "person"};

// A scene of n objects and its observation stream, precomputed so the loop measures the tracker.
std::vector<std::vector<Observation>> scene(int n, int stacks) {
  std::mt19937 rng(static_cast<unsigned>(n));
  std::uniform_real_distribution<double> pos(-30, 30), speed(-8, 8);
  std::normal_distribution<double> noise(0, 0.3);
  std::bernoulli_distribution detected(0.9), clutter(0.1);
  std::vector<Eigen::Vector3d> p(static_cast<std::size_t>(n)), v(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    p[static_cast<std::size_t>(i)] = {pos(rng), pos(rng), 0};
    v[static_cast<std::size_t>(i)] = {speed(rng), speed(rng), 0};
  }
  std::vector<std::vector<Observation>> out(static_cast<std::size_t>(stacks));
  for (auto& obs : out) {
    for (int i = 0; i < n; ++i) {
      auto& pi = p[static_cast<std::size_t>(i)];
      pi += 0.1 * v[static_cast<std::size_t>(i)];
      if (!detected(rng)) continue;
      Observation o;
      o.className = kClasses[i % 3];
      o.position = pi + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
      obs.push_back(o);
    }
    for (int i = 0; i < n; ++i)
      if (clutter(rng)) {
        Observation o;
        o.className = kClasses[i % 3];
        o.position = Eigen::Vector3d(pos(rng), pos(rng), 0);
        obs.push_back(o);
      }
  }
  return out;
}

void BM_TrackerUpdate(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const auto stream = scene(n, 200);
  Tracker tracker;
  std::size_t k = 0;
  std::int64_t stamp = 0;
  for (int warm = 0; warm < 20; ++warm) tracker.update(Stamp{stamp += kStackNs}, stream[k++]);
  std::size_t tracks = 0;
  for (auto _ : state) {
    if (k == stream.size()) {  // start the scene again (stamps keep going: tracks die, new ones are born)
      k = 0;
      stamp += 10'000'000'000;
    }
    const TrackedStack s = tracker.update(Stamp{stamp += kStackNs}, stream[k++]);
    tracks = s.tracks.size();
    benchmark::DoNotOptimize(s.tracks.data());
  }
  state.counters["live_tracks"] = static_cast<double>(tracks);
}
BENCHMARK(BM_TrackerUpdate)->Arg(10)->Arg(50)->Arg(200)->Unit(benchmark::kMillisecond);

void BM_PredictAndGateOnly(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const auto stream = scene(n, 200);
  std::vector<ConstantVelocityKalman> filters;
  for (const Observation& o : stream[0]) filters.emplace_back(*o.position, KalmanNoise{});
  std::size_t k = 1;
  for (auto _ : state) {
    if (k == stream.size()) k = 1;
    double sum = 0;
    for (auto& f : filters) {
      f.predict(0.1);
      for (const Observation& o : stream[k]) sum += f.mahalanobis2(*o.position);
    }
    ++k;
    benchmark::DoNotOptimize(sum);
  }
}
BENCHMARK(BM_PredictAndGateOnly)->Arg(50)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  fusedet::bench::HeadlineReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  for (const char* n : {"10", "50", "200"}) {
    std::printf("bench: tracker_ms_per_stack_%s %.4f\n", n, reporter.wall[std::string("BM_TrackerUpdate/") + n]);
    std::printf("bench: tracker_cpu_ms_per_stack_%s %.4f\n", n, reporter.cpu[std::string("BM_TrackerUpdate/") + n]);
  }
  std::printf("bench: tracker_predict_gate_only_ms_50 %.4f\n", reporter.wall["BM_PredictAndGateOnly/50"]);
  return 0;
}
