// SPDX-License-Identifier: Apache-2.0
#pragma once
// Synthetic training scenes shared by the trainer tests and the dataset writer of the MPI tests.

#include <opencv2/core.hpp>

#include <random>
#include <string>
#include <vector>

#include "fusedet/boost/cascade_trainer.h"
#include "fusedet/boost/evaluation.h"
#include "fusedet/core/dataset.h"

namespace fusedet::synthetic {

// Synthetic scenes: noisy background, "cars" = 36x24 boxes with a bright upper half and a dark
// lower half (hue 200 inside, 40 outside), "vans" = uniformly bright boxes (a hard negative),
// a DontCare region in some scenes.
inline DatasetItem scene(unsigned seed, int cars, bool withHue) {
  std::mt19937 rng(seed);
  cv::Mat img(120, 200, CV_8U);
  // The background's noise from a generator of the scene's own: cv::randu() draws from OpenCV's
  // per-thread generator, whose state is whatever ran before in the process, so a test's scenes
  // (and what its cascade detects) depended on the tests before it in the same program.
  cv::RNG noise(seed);
  noise.fill(img, cv::RNG::UNIFORM, 60, 140);
  cv::Mat hue(120, 200, CV_32F, cv::Scalar(40.f));
  DatasetItem item;
  item.id = "synthetic/" + std::to_string(seed);
  item.group = "synthetic";
  std::uniform_int_distribution<int> x(0, 200 - 40), y(0, 120 - 28);
  std::vector<cv::Rect> placed;
  auto free = [&](const cv::Rect& r) {
    for (const auto& p : placed)
      if ((r & p).area() > 0) return false;
    return true;
  };
  for (int k = 0, tries = 0; k < cars + 1 && tries < 100; ++tries) {
    const int w = 34 + int(rng() % 5), h = 24;
    cv::Rect r(x(rng), y(rng), w, h);
    if (!free(r)) continue;
    placed.push_back(r);
    Label l;
    l.box = Box{double(r.x), double(r.y), double(r.width), double(r.height)};
    if (k < cars) {
      img(cv::Rect(r.x, r.y, r.width, r.height / 2)) += cv::Scalar(70);
      img(cv::Rect(r.x, r.y + r.height / 2, r.width, r.height / 2)) -= cv::Scalar(50);
      hue(r).setTo(200.f);
      l.className = "car";
      l.sourceClass = "Car";
    } else {
      img(r) += cv::Scalar(60);
      l.className = "van";
      l.sourceClass = "Van";
    }
    item.labels.push_back(l);
    ++k;
  }
  if (seed % 3 == 0) {
    Label dc;
    dc.box = Box{0, 0, 30, 30};
    dc.ignore = true;
    dc.sourceClass = "DontCare";
    item.labels.push_back(dc);
  }
  item.stack = LayerStack(200, 120);
  item.stack.set(Layer{"intensity", img, {}});
  if (withHue) item.stack.set(Layer{"hue", hue, {}});
  return item;
}

inline std::vector<DatasetItem> scenes(int n, bool withHue) {
  std::vector<DatasetItem> items;
  for (int i = 0; i < n; ++i) items.push_back(scene(100 + unsigned(i), i % 4 == 3 ? 0 : 2, withHue));
  return items;
}

// A small, fast training configuration for these scenes (grid 6, 12 px windows, 3 stages).
inline boosting::TrainingConfig smallConfig() {
  boosting::TrainingConfig c;
  c.className = "car";
  c.pool.grid = 6;
  c.pool.layers = {"intensity"};
  c.samples.baseWindowHeight = 12;
  c.samples.minPositiveHeight = 20;
  c.samples.scan.scaleFactor = 1.25;
  c.samples.scan.step = 2;
  c.maxStages = 3;
  c.negativesPerStage = 300;
  c.stage.maxWeak = 20;
  c.seed = 5;
  return c;
}

// Cars of 20 px and more, no ignore rules; every window position, single-window groups kept.
inline boosting::MatchConfig carMatch() {
  boosting::MatchConfig match;
  match.className = "car";
  match.minHeight = 20;
  match.minDetectionHeight = 0;
  return match;
}

// smallConfig() on both layers the hue scenes have, 2 stages, one thread: the quick training
// of the determinism, cache and sharding tests.
inline boosting::TrainingConfig twoLayerConfig() {
  boosting::TrainingConfig c = smallConfig();
  c.pool.layers = {"intensity", "hue_distance"};
  c.maxStages = 2;
  c.threads = 1;
  return c;
}

}  // namespace fusedet::synthetic
