// SPDX-License-Identifier: Apache-2.0
// bench_mpi_round: scale-out of one boosting round (fusedet/boost/sharded_stage.h) over MPI ranks, 1 vs 2
// ranks on equal terms (one thread per rank, same samples, same pool), with the payload each rank
// hands to MPI per round. Samples: OpenCV's default pool (grid 24, types a-e, 162,336 features) on
// intensity windows of the shared KITTI drives (car boxes + mirrored copies, label-free windows),
// as bench_boost_round uses; frames dealt to ranks as `fusedet train` does (frame i on rank i % N).
//
// Run without a launcher it is the driver: it starts itself under `mpirun -np 1` and `-np 2`,
// prints both and ends with
//   bench: mpi_round_speedup_2 <round time 1 rank / round time 2 ranks>
//   bench: mpi_bytes_per_round <bytes each rank hands to MPI per round, 2 ranks>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "boost_round_data.h"
#include "fusedet/boost/gentle_boost.h"
#include "fusedet/boost/sharded_samples.h"
#include "fusedet/boost/sharded_stage.h"
#include "mpi_job.h"

namespace {

using Clock = std::chrono::steady_clock;
using namespace fusedet;
using namespace fusedet::boosting;

struct Args {
  std::size_t features = 162336, samples = 3000, frames = 0;
  int rounds = 5, threads = 1;
  bool smoke = false, worker = false;
  std::string mpirun = FUSEDET_MPIRUN;
};

// Command line (CLI11); exits after --help (0) or a bad argument (non-zero).
Args parse(int argc, char** argv) {
  Args a;
  CLI::App app{
      "bench_mpi_round - boosting rounds of the sharded trainer under mpirun -np 1 and -np 2 (T threads per\n"
      "rank) and the bytes each rank hands to MPI per round."};
  app.add_flag("--smoke", a.smoke, "tiny run for ctest: 2000 features, 400 samples, 3 frames per drive, 2 rounds");
  app.add_flag("--worker", a.worker, "run as one rank (the driver starts its ranks so)");
  app.add_option("--features", a.features, "features (pool size)")->capture_default_str();
  app.add_option("--samples", a.samples, "samples")->capture_default_str();
  app.add_option("--frames", a.frames, "frames per drive (0 = all)")->capture_default_str();
  app.add_option("--rounds", a.rounds, "rounds timed")->capture_default_str();
  app.add_option("--threads", a.threads, "threads per rank")->capture_default_str();
  app.add_option("--mpirun", a.mpirun, "MPI launcher")->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    std::exit(app.exit(e));
  }
  if (a.smoke) {
    a.features = 2000;
    a.samples = 400;
    a.frames = 3;
    a.rounds = 2;
  }
  return a;
}

// One rank: its frames, the global samples, the sharded stage, timed rounds.
int worker(const Args& a) {
  const std::unique_ptr<tools::MpiJob> job = tools::openMpiJob(600);
  const Shard shard{job->rank(), job->size()};
  const std::vector<DatasetItem> items =
      bench::kittiIntensityItems(a.frames, [&](std::size_t i) { return shard.owns(i); });
  SampleConfig sc;
  sc.className = "car";
  sc.scan.scaleFactor = 1.25;
  const std::vector<std::string> layers = {"intensity"};
  const TrainingStacks stacks(items, layers, std::nullopt, sc, shard);
  std::vector<Sample> samples = stacks.positives();
  if (samples.size() > a.samples / 3) samples.resize(a.samples / 3);
  const std::size_t positives = samples.size();
  const NegativeHarvest neg =
      shardedHarvest(stacks, bench::negativeScan(stacks), a.samples - positives, 1, a.threads, *job);
  samples.insert(samples.end(), neg.samples.begin(), neg.samples.end());
  const std::vector<Feature> pool = bench::roundPool(a.features, layers);

  const auto t0 = Clock::now();
  ShardedStage stage(stacks, pool, samples, positives, *job, a.threads);
  const double matrixSeconds = std::chrono::duration<double>(Clock::now() - t0).count();
  StageConfig config;
  config.maxWeak = a.rounds;
  config.maxFalseAlarm = 1e-12;  // never stop early: exactly `rounds` rounds
  const std::uint64_t bytes0 = job->bytesSent();
  const auto t1 = Clock::now();
  const StageResult r = boostStage(
      samples.size(), positives,
      [&](std::span<const float> w, std::span<float> chosen) { return stage.findStump(w, chosen, config.refineTop); },
      config);
  const double roundSeconds = std::chrono::duration<double>(Clock::now() - t1).count() / double(r.stumps.size());
  const double bytesPerRound = double(job->bytesSent() - bytes0) / double(r.stumps.size());
  if (job->rank() == 0)
    std::printf("mpi_round ranks %d samples %zu positives %zu local %zu features %zu rounds %zu round_s %.6f "
                "bytes_per_round %.0f matrix_s %.3f first_stump %zu\n",
                job->size(), samples.size(), positives, stage.localSamples(), pool.size(), r.stumps.size(),
                roundSeconds, bytesPerRound, matrixSeconds, r.stumps.front().feature);
  return 0;
}

// Runs the worker under mpirun -np `ranks`; returns rank 0's "mpi_round ..." fields.
std::map<std::string, std::string> launch(const Args& a, int ranks) {
  std::ostringstream cmd;
  cmd << a.mpirun << " --oversubscribe -np " << ranks << " " << std::filesystem::read_symlink("/proc/self/exe")
      << " --worker --features " << a.features << " --samples " << a.samples << " --frames " << a.frames
      << " --rounds " << a.rounds << " --threads " << a.threads;
  std::fprintf(stderr, "running: %s\n", cmd.str().c_str());
  FILE* p = popen(cmd.str().c_str(), "r");
  if (!p) throw std::runtime_error("cannot start " + a.mpirun);
  std::string out;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, p)) out += buf;
  const int status = pclose(p);
  if (status != 0) throw std::runtime_error("mpirun -np " + std::to_string(ranks) + " failed:\n" + out);
  std::map<std::string, std::string> f;
  std::istringstream in(out.substr(out.find("mpi_round ")));
  std::string key, value;
  in >> key;
  while (in >> key >> value) f[key] = value;
  return f;
}

}  // namespace

int main(int argc, char** argv) try {
  const Args a = parse(argc, argv);
  if (a.worker || tools::launchedByMpiLauncher()) return worker(a);
  // The ranks run as children of mpirun: tell them where the module is, and let root run them.
  setenv("FUSEDET_MPI_MODULE", FUSEDET_MPI_MODULE_PATH, 1);
  if (geteuid() == 0) {
    setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
    setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  }
  auto one = launch(a, 1);
  auto two = launch(a, 2);
  const double t1 = std::stod(one.at("round_s")), t2 = std::stod(two.at("round_s"));
  std::printf("sharded boosting round, %s features x %s samples (%s positives), KITTI intensity windows, %d "
              "thread(s) per rank, %d rounds:\n",
              one.at("features").c_str(), one.at("samples").c_str(), one.at("positives").c_str(), a.threads,
              a.rounds);
  std::printf("  1 rank : %.4f s per round (matrix %.1f s, %s local samples)\n", t1, std::stod(one.at("matrix_s")),
              one.at("local").c_str());
  std::printf("  2 ranks: %.4f s per round (matrix %.1f s, %s local samples on rank 0), %.1f MB per rank per round\n",
              t2, std::stod(two.at("matrix_s")), two.at("local").c_str(), std::stod(two.at("bytes_per_round")) / 1e6);
  if (one.at("first_stump") != two.at("first_stump"))
    throw std::runtime_error("1 and 2 ranks chose different first stumps: " + one.at("first_stump") + " vs " +
                             two.at("first_stump"));
  std::printf("  same first stump (feature %s) for 1 and 2 ranks\n", one.at("first_stump").c_str());
  std::printf("bench: mpi_round_s_1 %.6f\n", t1);
  std::printf("bench: mpi_round_s_2 %.6f\n", t2);
  std::printf("bench: mpi_round_speedup_2 %.3f\n", t1 / t2);
  std::printf("bench: mpi_bytes_per_round %s\n", two.at("bytes_per_round").c_str());
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "bench_mpi_round: %s\n", e.what());
  return 1;
}
