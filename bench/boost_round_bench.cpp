// SPDX-License-Identifier: Apache-2.0
// One boosting round (the best regression stump over the whole pool) on the same precomputed
// feature matrix, three ways in one run with the same thread count:
//   ours:      8-bit bins per feature (built once per stage), weighted histograms + split scan,
//              exact refinement of the best candidates (fusedet/boost/stump.h);
//   XGBoost:   C API, tree_method=hist, max_depth=1, reg:squarederror on y = +-1 with the same
//              sample weights, lambda = 0, eta = 1 (its leaf is then the weighted mean of y, the
//              same least-squares stump);
//   ml::Boost: OpenCV, Gentle, max depth 1, one weak classifier.
// Each stump is judged by the same number: sum_i w_i (y_i - f(x_i))^2 from its own predictions.
// Reference case (the issue's): 162,336 features x 3,000 samples, 2 threads.
// Equal terms, stated in the output: every peer's set-up is timed apart from its round (ours:
// binning once per stage; XGBoost: QuantileDMatrix, built with as many threads as our binning;
// ml::Boost: TrainData creation and a training with zero weak trees, each timed directly; its round
// from whole trainings with 1 and 2 trees, see below). ml::Boost is single-threaded by construction,
// so its ratio is also given per thread (our round's CPU time over all our threads) beside the
// wall-clock one.

#include <opencv2/core.hpp>
#include <opencv2/ml.hpp>
#include <tbb/global_control.h>
#include <xgboost/c_api.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "fusedet/boost/feature_matrix.h"
#include "fusedet/core/cpu_time.h"
#include "fusedet/boost/stump.h"
#include "boost_round_data.h"

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}
// CPU seconds of every thread of the process: the work done, whatever else runs on the machine.
double processCpu() { return fusedet::processCpuMs() / 1000.0; }

// Process CPU and wall seconds of one call.
struct CpuWall {
  double cpu = 0, wall = 0;
};
template <class F>
CpuWall timed(F&& f) {
  const double c0 = processCpu();
  const auto t0 = Clock::now();
  f();
  return CpuWall{processCpu() - c0, since(t0)};
}

// ml::Boost's measured trainings: train[k] = every repetition of a training with k weak trees.
struct MlBoostTimes {
  CpuWall create;
  std::vector<CpuWall> train[3];
  CpuWall median(int trees) const {
    std::vector<double> c, w;
    for (const CpuWall& t : train[trees]) {
      c.push_back(t.cpu);
      w.push_back(t.wall);
    }
    auto mid = [](std::vector<double>& v) {  // median; the mean of the middle two for an even count
      std::sort(v.begin(), v.end());
      return (v[(v.size() - 1) / 2] + v[v.size() / 2]) / 2;
    };
    return {mid(c), mid(w)};
  }
  CpuWall setup() const { return {create.cpu + median(0).cpu, create.wall + median(0).wall}; }
  CpuWall round() const {
    return {(median(2).cpu - median(0).cpu) / 2, (median(2).wall - median(0).wall) / 2};
  }
};

// Resident set size and its peak, MB (from /proc/self/status).
double procStatusMb(const char* key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(key, 0) == 0) return std::strtod(line.c_str() + std::strlen(key), nullptr) / 1024.0;
  return 0;
}
double rssMb() { return procStatusMb("VmRSS:"); }

void xgCheck(int rc, const char* what) {
  if (rc != 0) throw std::runtime_error(std::string(what) + ": " + XGBGetLastError());
}

double weightedError(const std::vector<float>& pred, const std::vector<float>& y,
                     const std::vector<float>& w) {
  double e = 0;
  for (std::size_t i = 0; i < pred.size(); ++i) {
    const double d = double(y[i]) - pred[i];
    e += w[i] * d * d;
  }
  return e;
}

// Row batches of the shared matrix for XGBoost's iterator-fed QuantileDMatrix.
struct XgBatches {
  const bench::RoundData* d;
  const std::vector<float>* y;
  const std::vector<float>* w;
  DMatrixHandle proxy;
  std::size_t row;
  std::size_t batch;

  static std::string arrayInterface(const float* data, std::size_t rows, std::size_t cols) {
    return R"({"data": [)" + std::to_string(reinterpret_cast<std::uintptr_t>(data)) +
           R"(, true], "shape": [)" + std::to_string(rows) + ", " + std::to_string(cols) +
           R"(], "typestr": "<f4", "version": 3})";
  }
  static void reset(DataIterHandle h) { static_cast<XgBatches*>(h)->row = 0; }
  static int next(DataIterHandle h) {
    auto* it = static_cast<XgBatches*>(h);
    if (it->row >= it->d->samples) return 0;
    const std::size_t rows = std::min(it->batch, it->d->samples - it->row);
    const std::string ai = arrayInterface(it->d->values.data() + it->row * it->d->features, rows, it->d->features);
    xgCheck(XGProxyDMatrixSetDataDense(it->proxy, ai.c_str()), "XGProxyDMatrixSetDataDense");
    xgCheck(XGDMatrixSetFloatInfo(it->proxy, "label", it->y->data() + it->row, rows), "label");
    xgCheck(XGDMatrixSetFloatInfo(it->proxy, "weight", it->w->data() + it->row, rows), "weight");
    it->row += rows;
    return 1;
  }
};

struct Args {
  std::size_t features = 162336, samples = 3000;
  int threads = 2, rounds = 5;
  int mlReps = 2;  // repetitions of ml::Boost's 0-, 1- and 2-tree trainings
  bool skipMlBoost = false;
  bool skipXgboost = false;
  bool oursOnly = false;  // tuning: no peers, no headline ratios
  std::string source = "kitti";
  std::size_t maxFrames = 0;
  std::size_t xgBatch = 3000;  // rows per iterator batch of XGBoost's QuantileDMatrix
  int xgBuildThreads = 0;      // threads of its QuantileDMatrix construction; 0 = --threads (as our binning)
};

// Command line (CLI11); exits after --help (0) or a bad argument (non-zero).
Args parse(int argc, char** argv) {
  Args a;
  CLI::App app{
      "bench_boost_round - one boosting round, ours vs XGBoost (hist) vs cv::ml::Boost, same matrix and threads.\n"
      "Matrix: OpenCV's default pool (24-unit grid, types a-e) on intensity windows of the shared KITTI drives\n"
      "(--source kitti) or a generated one (--source synthetic). XGBoost's matrix is built with --threads threads\n"
      "(as our binning) unless --xgb-build-threads says otherwise. ml::Boost's set-up is timed directly\n"
      "(TrainData::create + train() with 0 weak trees); its trainings with 1 and 2 trees are timed whole,\n"
      "--mlboost-reps times each, interleaved; its round = (2-tree - 0-tree training) / 2 of the medians.\n"
      "Every timing is printed."};
  bool smoke = false;
  app.add_flag("--smoke", smoke, "tiny run for ctest: 3000 features x 400 samples, 3 frames per drive, 2 rounds");
  app.add_option("--features", a.features, "features (pool size)")->capture_default_str();
  app.add_option("--samples", a.samples, "samples")->capture_default_str();
  app.add_option("--threads", a.threads, "threads of ours and XGBoost")->capture_default_str();
  app.add_option("--rounds", a.rounds, "rounds timed (ours, XGBoost)")->capture_default_str();
  app.add_option("--source", a.source, "kitti or synthetic")->capture_default_str();
  app.add_option("--xgb-batch", a.xgBatch, "rows per batch fed to XGBoost's QuantileDMatrix")->capture_default_str();
  app.add_option("--xgb-build-threads", a.xgBuildThreads, "threads of XGBoost's matrix (0 = --threads)")
      ->capture_default_str();
  app.add_option("--mlboost-reps", a.mlReps, "repetitions of ml::Boost's 0-, 1- and 2-tree trainings")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_flag("--skip-mlboost", a.skipMlBoost, "leave ml::Boost out");
  app.add_flag("--skip-xgboost", a.skipXgboost, "leave XGBoost out (its matrix peaks at ~17 GB RSS at full size)");
  app.add_flag("--ours-only", a.oursOnly, "tuning: ours only, no peers, no headline ratios");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    std::exit(app.exit(e));
  }
  if (smoke) {
    a.features = 3000;
    a.samples = 400;
    a.rounds = 2;
    a.maxFrames = 3;
  }
  return a;
}

}  // namespace

int main(int argc, char** argv) try {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // progress lines appear as they happen
  Args a = parse(argc, argv);
  if (a.xgBuildThreads <= 0) a.xgBuildThreads = a.threads;
  tbb::global_control tbbThreads(tbb::global_control::max_allowed_parallelism,
                                 static_cast<std::size_t>(a.threads));
  cv::setNumThreads(a.threads);

  // ---- the shared precomputed matrix: row-major samples x features (what all three accept) ----
  auto t0 = Clock::now();
  if (a.source != "synthetic" && a.source != "kitti") throw std::runtime_error("unknown --source " + a.source);
  const bench::RoundData d = a.source == "synthetic"
                                 ? bench::syntheticRoundData(a.features, a.samples)
                                 : bench::kittiRoundData(a.features, a.samples, a.maxFrames);
  const std::size_t F = d.features, N = d.samples, P = d.positives;
  std::printf("matrix: %zu features x %zu samples (%zu positives), source %s, %d threads, built in %.2f s\n",
              F, N, P, d.description.c_str(), a.threads, since(t0));
  std::printf("memory: float matrix %.0f MB, RSS %.0f MB\n", double(F) * N * 4 / 1e6, rssMb());
  // First-round weights: uniform within each class, each class half the total (as the trainer).
  std::vector<float> w(N), y(N);
  for (std::size_t i = 0; i < N; ++i) {
    y[i] = i < P ? 1.f : -1.f;
    w[i] = i < P ? 0.5f / float(P) : 0.5f / float(N - P);
  }

  // ---- ours ----
  const double rss0 = rssMb();
  t0 = Clock::now();
  const fusedet::boosting::FeatureMatrix m = fusedet::boosting::buildFeatureMatrix(
      F, N,
      [&](std::size_t first, std::size_t count, std::span<float> out) {
        for (std::size_t i = 0; i < N; ++i) {
          const float* row = d.values.data() + i * F + first;
          for (std::size_t k = 0; k < count; ++k) out[k * N + i] = row[k];
        }
      },
      a.threads);
  const double binSeconds = since(t0);
  std::printf("ours: binning (once per stage) %.3f s, bins %.0f MB (8-bit), RSS +%.0f MB\n",
              binSeconds, double(m.bytes()) / 1e6, rssMb() - rss0);
  auto raw = [&](std::size_t f, std::span<float> out) {
    for (std::size_t i = 0; i < N; ++i) out[i] = d.values[i * F + f];
  };
  fusedet::boosting::StumpSearchOptions opt;
  opt.threads = a.threads;

  if (a.oursOnly) {
    std::vector<double> t;
    for (int r = 0; r < a.rounds; ++r) {
      t0 = Clock::now();
      const auto st = fusedet::boosting::findBestStump(m, P, w, raw, opt);
      t.push_back(since(t0));
      if (r == 0) std::printf("ours: feature %zu error %.6f\n", st.feature, st.error);
    }
    for (double x : t) std::printf("%.3f ", x);
    std::printf("\n");
    std::sort(t.begin(), t.end());
    std::printf("ours: round %.4f s (median of %d, min %.4f)\n", t[t.size() / 2], a.rounds, t.front());
    return 0;
  }

  // ---- XGBoost: setup ----
  // QuantileDMatrix fed by an iterator over row batches (XGBoost's path for hist that keeps no CSR
  // copy of the values). Its sketches still take ~70 KB per feature while it is built.
  // --skip-xgboost leaves it out (b stays null): its matrix peaks at ~17 GB RSS at full size.
  XgBatches it{&d, &y, &w, nullptr, 0, a.xgBatch};
  DMatrixHandle dm = nullptr;
  BoosterHandle b = nullptr;
  double xgSetup = 0;
  if (!a.skipXgboost) {
    const double rssX = rssMb();
    xgCheck(XGProxyDMatrixCreate(&it.proxy), "XGProxyDMatrixCreate");
    const std::string cfg =
        R"({"missing": NaN, "nthread": )" + std::to_string(a.xgBuildThreads) + R"(, "max_bin": 256})";
    t0 = Clock::now();
    xgCheck(XGQuantileDMatrixCreateFromCallback(&it, it.proxy, nullptr, &XgBatches::reset, &XgBatches::next,
                                                cfg.c_str(), &dm),
            "XGQuantileDMatrixCreateFromCallback");
    xgSetup = since(t0);
    const double xgPeak = procStatusMb("VmHWM:");
    xgCheck(XGBoosterCreate(&dm, 1, &b), "XGBoosterCreate");
    const std::string nthread = std::to_string(a.threads);
    const char* params[][2] = {{"tree_method", "hist"}, {"max_depth", "1"},    {"eta", "1"},
                               {"lambda", "0"},         {"alpha", "0"},        {"gamma", "0"},
                               {"min_child_weight", "0"}, {"max_bin", "256"},  {"base_score", "0"},
                               {"objective", "reg:squarederror"}, {"nthread", nthread.c_str()},
                               {"verbosity", "0"}};
    for (auto& p : params) xgCheck(XGBoosterSetParam(b, p[0], p[1]), p[0]);
    std::printf("xgboost: QuantileDMatrix (sketch + bin index) %.2f s with %d threads (our binning: %d), RSS +%.0f MB "
                "(peak RSS so far %.0f MB)\n",
                xgSetup, a.xgBuildThreads, a.threads, rssMb() - rssX, xgPeak);
  }

  // ---- rounds, interleaved: the machine's load hits both alike ----
  std::vector<double> ourTimes, ourCpu, xgTimes;
  fusedet::boosting::FittedStump ours;
  for (int r = 0; r < a.rounds; ++r) {
    t0 = Clock::now();
    const double c0 = processCpu();
    ours = fusedet::boosting::findBestStump(m, P, w, raw, opt);
    ourCpu.push_back(processCpu() - c0);
    ourTimes.push_back(since(t0));
    if (!b) continue;
    t0 = Clock::now();
    xgCheck(XGBoosterUpdateOneIter(b, r, dm), "XGBoosterUpdateOneIter");
    xgTimes.push_back(since(t0));
  }
  const double xgFirstRound = b ? xgTimes.front() : 0;
  std::sort(ourTimes.begin(), ourTimes.end());
  std::sort(xgTimes.begin(), xgTimes.end());
  const double oursSeconds = ourTimes[ourTimes.size() / 2];
  std::sort(ourCpu.begin(), ourCpu.end());
  const double oursCpuSeconds = ourCpu[ourCpu.size() / 2];  // CPU of all our threads in one round
  const double xgRound = b ? xgTimes[xgTimes.size() / 2] : 0;
  std::vector<float> pred(N);
  for (std::size_t i = 0; i < N; ++i) pred[i] = float(ours(d.values[i * F + ours.feature]));
  const double oursError = weightedError(pred, y, w);
  std::printf("ours: round %.4f s (median of %d, min %.4f), feature %zu threshold %.6g leaves %.4f/%.4f, "
              "error %.6f\n",
              oursSeconds, a.rounds, ourTimes.front(), ours.feature, double(ours.threshold), ours.left,
              ours.right, oursError);
  // XGBoost's first tree alone (the same weights as ours), from its own predictions.
  double xgError = 0;
  if (b) {
    const char* pcfg = R"({"type": 0, "training": false, "iteration_begin": 0, "iteration_end": 1, "strict_shape": false, "missing": NaN, "cache_id": 0})";
    bst_ulong const* shape = nullptr;
    bst_ulong dim = 0;
    const float* out = nullptr;
    const std::string all = XgBatches::arrayInterface(d.values.data(), N, F);
    xgCheck(XGBoosterPredictFromDense(b, all.c_str(), pcfg, nullptr, &shape, &dim, &out), "predict");
    std::vector<float> xp(out, out + N);
    xgError = weightedError(xp, y, w);
    std::printf("xgboost: round %.4f s (median of %d, min %.4f, first %.4f), error of the first tree %.6f\n",
                xgRound, a.rounds, xgTimes.front(), xgFirstRound, xgError);
    XGBoosterFree(b);
    XGDMatrixFree(dm);
    XGDMatrixFree(it.proxy);
  }

  // ---- cv::ml::Boost ----
  // Single-threaded by construction. Every time printed is measured, none found by subtraction:
  //   set-up: TrainData::create, then train() with zero weak trees - OpenCV's Boost::train runs
  //     startTraining (work data, responses to +-1, weight normalisation), no tree, endTraining.
  //     OpenCV 4 keeps no presorted index (each split sorts the node's values per feature, inside
  //     the round), so this is all the set-up it has;
  //   training with 1 and with 2 weak trees, whole. A round cannot be called apart from the set-up
  //   through OpenCV's API, so its round is (train(2) - train(0)) / 2 of medians over --mlboost-reps
  //   repetitions, run interleaved (0, 1, 2 trees, 0, 1, 2, ...) so load drift hits all alike; both
  //   rounds (train(1) - train(0), train(2) - train(1)) are printed to show they agree.
  // Timed in process CPU seconds (its one thread's work; robust against a loaded machine) and wall.
  MlBoostTimes ml;
  double mlError = 0;
  if (!a.skipMlBoost) {
    const double rssM = rssMb();
    cv::Mat X(static_cast<int>(N), static_cast<int>(F), CV_32F, const_cast<float*>(d.values.data()));
    cv::Mat labels(static_cast<int>(N), 1, CV_32S);
    for (std::size_t i = 0; i < N; ++i) labels.at<int>(static_cast<int>(i)) = i < P ? 1 : 0;
    cv::Mat weights(static_cast<int>(N), 1, CV_32F, w.data());
    cv::Mat varType(static_cast<int>(F) + 1, 1, CV_8U, cv::Scalar(cv::ml::VAR_ORDERED));
    varType.at<uchar>(static_cast<int>(F)) = cv::ml::VAR_CATEGORICAL;
    cv::Ptr<cv::ml::TrainData> td;
    ml.create = timed([&] {
      td = cv::ml::TrainData::create(X, cv::ml::ROW_SAMPLE, labels, cv::noArray(), cv::noArray(), weights, varType);
    });
    auto makeBoost = [](int weak) {
      auto boost = cv::ml::Boost::create();
      boost->setBoostType(cv::ml::Boost::GENTLE);
      boost->setWeakCount(weak);
      boost->setMaxDepth(1);
      boost->setWeightTrimRate(0);
      boost->setMinSampleCount(1);
      boost->setUseSurrogates(false);
      boost->setCVFolds(0);
      return boost;
    };
    cv::Ptr<cv::ml::Boost> oneTree;
    for (int r = 0; r < a.mlReps; ++r)
      for (int trees = 0; trees <= 2; ++trees) {
        auto boost = makeBoost(trees);
        ml.train[trees].push_back(timed([&] { boost->train(td); }));
        if (trees == 1) oneTree = boost;
        std::printf("ml::Boost: train() with %d weak tree(s), repetition %d: CPU %.4f s, wall %.4f s\n", trees, r + 1,
                    ml.train[trees].back().cpu, ml.train[trees].back().wall);
      }
    if (oneTree->getRoots().size() != 1) throw std::runtime_error("ml::Boost did not train its one tree");
    const double rssAfter = rssMb();
    std::vector<float> mp(N);
    for (std::size_t i = 0; i < N; ++i)
      mp[i] = oneTree->predict(X.row(static_cast<int>(i)), cv::noArray(),
                               int(cv::ml::DTrees::PREDICT_SUM) | int(cv::ml::StatModel::RAW_OUTPUT));
    // OpenCV's Gentle leaves are the weighted mean of y in {-1, +1}; PREDICT_SUM|RAW_OUTPUT is
    // their sum (without PREDICT_SUM, Boost returns the class index).
    mlError = weightedError(mp, y, w);
    {
      std::vector<float> u(mp);
      std::sort(u.begin(), u.end());
      u.erase(std::unique(u.begin(), u.end()), u.end());
      std::printf("ml::Boost: %zu distinct outputs, first %.4f last %.4f\n", u.size(), u.front(), u.back());
    }
    std::printf("ml::Boost (1 thread by construction), medians of %d, CPU s (wall s): TrainData::create %.4f (%.4f), "
                "train() with 0 weak trees = the rest of its set-up %.4f (%.4f), with 1 %.3f (%.3f), with 2 %.3f "
                "(%.3f)\n",
                a.mlReps, ml.create.cpu, ml.create.wall, ml.median(0).cpu, ml.median(0).wall, ml.median(1).cpu,
                ml.median(1).wall, ml.median(2).cpu, ml.median(2).wall);
    std::printf("ml::Boost: set-up %.4f s CPU (create + 0-tree training); round = (2-tree - 0-tree training) / 2 = "
                "%.3f s CPU (wall %.3f); first round %.3f, second round %.3f; error %.6f, RSS +%.0f MB\n",
                ml.setup().cpu, ml.round().cpu, ml.round().wall, ml.median(1).cpu - ml.median(0).cpu,
                ml.median(2).cpu - ml.median(1).cpu, mlError, rssAfter - rssM);
  }
  std::printf("memory: peak RSS %.0f MB\n", procStatusMb("VmHWM:"));

  std::printf("bench: round_seconds %.4f\n", oursSeconds);
  std::printf("bench: binning_seconds_per_stage %.3f\n", binSeconds);
  if (b) {
    std::printf("bench: speedup_vs_xgboost %.2f\n", xgRound / oursSeconds);
    std::printf("bench: speedup_vs_xgboost_incl_setup %.2f\n", (xgSetup + xgRound) / (binSeconds + oursSeconds));
  }
  if (!a.skipMlBoost) {
    std::printf("equal terms: rounds against rounds, set-ups timed apart (none by subtraction); ours and XGBoost on "
                "%d threads, ml::Boost on 1 by construction: wall-clock ratio = its round's wall time / ours; "
                "per-thread ratio = its round's CPU time / our round's CPU time over all our threads (%.4f s)\n",
                a.threads, oursCpuSeconds);
    std::printf("bench: mlboost_round_seconds %.3f\n", ml.round().cpu);
    std::printf("bench: mlboost_setup_seconds %.4f\n", ml.setup().cpu);
    std::printf("bench: speedup_vs_mlboost %.2f\n", ml.round().wall / oursSeconds);
    std::printf("bench: speedup_vs_mlboost_per_thread %.2f\n", ml.round().cpu / oursCpuSeconds);
    std::printf("bench: speedup_vs_mlboost_incl_setup %.2f\n",
                (ml.setup().wall + ml.round().wall) / (binSeconds + oursSeconds));
  }
  if (b) std::printf("bench: stump_error_ratio_vs_xgboost %.5f\n", oursError / xgError);
  if (!a.skipMlBoost) std::printf("bench: stump_error_ratio_vs_mlboost %.5f\n", oursError / mlError);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "boost_round_bench: error: %s\n", e.what());
  return 1;
}
