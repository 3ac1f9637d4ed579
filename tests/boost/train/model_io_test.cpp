// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/model_io.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <unistd.h>

#include "../random_edits.h"

using namespace fusedet;
using namespace fusedet::boosting;

namespace {

Cascade sample() {
  Cascade c;
  c.className = "car";
  c.windowWidth = 40;
  c.windowHeight = 24;
  c.layers = {"intensity", "hue_distance"};
  c.referenceHue = 25;
  const int a = c.addFeature(Feature{FeatureType::kCornerTopLeft, Box{0.25, 0, 0.5, 0.5}, 1});
  const int b = c.addFeature(Feature{FeatureType::kEdgeHorizontal, Box{0, 0.1, 1.0 / 3, 0.7}, 0});
  c.stages.push_back(Stage{{Stump{a, 0.125, -0.8, 0.5}, Stump{b, -3.5, 0.25, -0.75}}, -0.41});
  c.stages.push_back(Stage{{Stump{b, 1e-7, -1, 1}}, 0.1});
  return c;
}

std::string errorOf(const std::string& text) {
  try {
    modelFromText(text, "m.json");
  } catch (const ModelError& e) {
    return e.what();
  }
  return "";
}

std::string replace(std::string s, const std::string& from, const std::string& to) {
  const auto p = s.find(from);
  EXPECT_NE(p, std::string::npos) << from;
  if (p != std::string::npos) s.replace(p, from.size(), to);
  return s;
}

}  // namespace

TEST(ModelIo, RoundTripIsExactAndTextIsStable) {
  const Cascade c = sample();
  const std::string text = modelToText(c, {{"seed", "1"}});
  const Cascade back = modelFromText(text, "m.json");
  EXPECT_EQ(back.className, "car");
  EXPECT_EQ(back.windowWidth, 40);
  EXPECT_EQ(back.layers, c.layers);
  EXPECT_EQ(*back.referenceHue, 25);
  ASSERT_EQ(back.stages.size(), 2u);
  EXPECT_EQ(back.stages[0].threshold, -0.41);
  const Stump& s = back.stages[0].stumps[1];
  EXPECT_EQ(back.features[size_t(s.feature)], c.features[1]);
  EXPECT_EQ(s.threshold, -3.5);
  EXPECT_EQ(back.stages[1].stumps[0].threshold, 1e-7);
  // Shared features stay shared.
  EXPECT_EQ(back.stages[1].stumps[0].feature, s.feature);
  EXPECT_EQ(modelToText(back, {{"seed", "1"}}), text);
  EXPECT_NE(text.find("\"version\": 1"), std::string::npos);
  EXPECT_NE(text.find("\"type\":\"g\""), std::string::npos);
}

TEST(ModelIo, TheNetworkOfNeuralLayersIsRecordedAndChecked) {
  Cascade c = sample();
  EXPECT_EQ(modelToText(c).find("\"network\""), std::string::npos);  // no neural layers: no key
  c.layers = {"intensity", "neural_car"};
  c.network = NetworkRecord{"darknet", 832, 256, {"x.cfg", "x.weights"}, {std::string(64, 'a'), std::string(64, 'b')}};
  const std::string text = modelToText(c);
  Cascade back = modelFromText(text, "m.json");
  EXPECT_EQ(back.network, c.network);
  EXPECT_EQ(modelToText(back), text);
  // A stack of another network (or none) is refused before any window is scanned, naming both.
  LayerStack stack(64, 48);
  stack.set(Layer{"intensity", cv::Mat(48, 64, CV_8U, cv::Scalar(9)), {}});
  stack.set(Layer{"neural_car", cv::Mat(24, 32, CV_32F, cv::Scalar(0.5)), {}});
  stack.source = "kitti/000007";
  stack.network = c.network;
  EXPECT_NO_THROW(requireStackNetwork(back, stack));
  stack.network.inputHeight = 384;
  try {
    requireStackNetwork(back, stack);
    FAIL() << "a stack of another network was accepted";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("m.json (class 'car')"), std::string::npos) << what;
    EXPECT_NE(what.find(c.network.text()), std::string::npos) << what;
    EXPECT_NE(what.find(stack.network.text()), std::string::npos) << what;
    EXPECT_NE(what.find("kitti/000007"), std::string::npos) << what;
  }
  EXPECT_NE(errorOf(replace(text, "darknet 832x256", "darknet 832")).find("m.json: network: "), std::string::npos);
}

TEST(ModelIo, RemovedMinimumDetectionHeightIsRefusedWithWhatToDo) {
  // No model writes "min_height" any more; a file holding it (train --min-height-from-positives,
  // removed) would scan differently now, so it is refused, naming the field and what to do.
  const std::string text = modelToText(sample());
  EXPECT_EQ(text.find("min_height"), std::string::npos);
  const std::string old = replace(text, "\"layers\":", "\"min_height\": 27,\n  \"layers\":");
  ASSERT_NE(old, text);
  const std::string e = errorOf(old);
  EXPECT_NE(e.find("m.json: min_height: "), std::string::npos) << e;
  EXPECT_NE(e.find("--min-height-from-positives"), std::string::npos) << e;
  EXPECT_NE(e.find("retrain the model with `fusedet train`"), std::string::npos) << e;
}

TEST(ModelIo, SaveAndLoadFile) {
  const auto dir = std::filesystem::temp_directory_path() / "fusedet_model_io_test";
  std::filesystem::create_directories(dir);
  const auto file = dir / "car.json";
  saveModel(sample(), file);
  const Cascade c = loadModel(file);
  EXPECT_EQ(c.source, file.string());
  EXPECT_EQ(c.weakCount(), 3u);
  try {
    loadModel(dir / "missing.json");
    FAIL();
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.json: cannot open (no such file)"), std::string::npos) << e.what();
  }
}

// Files of format versions whose options were removed (they measured no gain across drives) are
// refused with the file, the version, the option and what to do - here as the removed code wrote them.
TEST(ModelIo, RemovedFormatVersionsAreRefusedWithWhatToDo) {
  struct Removed {
    int version;
    std::string option, text;
  };
  // A model file as every version wrote it: `fields` after the reference hue, then `stages`, then `tail`.
  auto file = [](int version, const std::string& fields, const std::string& stages, const std::string& tail) {
    return "{\n  \"format\": \"fusedet-cascade\",\n  \"version\": " + std::to_string(version) +
           ",\n  \"class\": \"car\",\n  \"window\": {\"width\":40,\"height\":24},\n"
           "  \"layers\": [\"intensity\",\"distance\"],\n  \"reference_hue\": null,\n" +
           fields + "  \"stages\": [\n" + stages + "\n  ]" + tail + "\n}\n";
  };
  const std::string stumps =
      "    {\"threshold\":-0.41,\"stumps\":[\n      {\"type\":\"g\",\"rect\":[0.25,0,0.5,0.5],\"layer\":\"distance\","
      "\"threshold\":0.12,\"left\":-0.8,\"right\":0.5}\n    ]}";
  const std::string treeStages =
      "    {\"threshold\":-0.41,\"trees\":[\n      {\"nodes\":[{\"type\":\"g\",\"rect\":[0.25,0,0.5,0.5],"
      "\"layer\":\"distance\",\"threshold\":0.12,\"left\":0,\"right\":-1}],\"leaves\":[-0.8,0.5]}\n    ]}";
  const std::vector<Removed> removed = {
      {2, "contrast normalisation", file(2, "  \"contrast_normalised\": [\"intensity\"],\n", stumps, "")},
      {3, "soft cascade", file(3, "  \"cascade\": \"soft\",\n", stumps, "")},
      {4, "side-view (aspect) cascades",
       file(4, "", stumps, ",\n  \"aspect_cascades\": [\n" + file(1, "", stumps, "") + "  ]")},
      {5, "tree weak learners", file(5, "", treeStages, "")},
  };
  // The same model as version 1 (no removed field) loads: only the version is refused.
  EXPECT_NO_THROW(modelFromText(file(1, "", stumps, ""), "v1.json"));
  const auto dir = std::filesystem::temp_directory_path() / ("fusedet_model_removed_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  for (const Removed& r : removed) {
    const auto path = dir / ("v" + std::to_string(r.version) + ".json");
    std::ofstream(path) << r.text;
    try {
      loadModel(path);
      ADD_FAILURE() << "version " << r.version << " loaded";
    } catch (const ModelError& e) {
      const std::string want = path.string() + ": version: model format version " + std::to_string(r.version) + " (" +
                               r.option + ") was removed in fusedet 0.1.0";
      EXPECT_EQ(std::string(e.what()).rfind(want, 0), 0u) << e.what();
      EXPECT_NE(std::string(e.what()).find("retrain the model with `fusedet train`"), std::string::npos) << e.what();
    }
  }
  std::filesystem::remove_all(dir);
  // Nor can such a model be made in memory: trees belong to imported OpenCV cascades only.
  Cascade treeModel = sample();
  for (Stage& st : treeModel.stages) st.stumps.clear();
  treeModel.treeStages.assign(2, {Tree{{TreeNode{0, 0.5, 0, -1}}, {-1, 1}}});
  try {
    treeModel.validate();
    ADD_FAILURE() << "a tree model of ours validated";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("decision trees are only supported in imported OpenCV cascades"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(modelToText(treeModel), ModelError);
}

// The "training" pairs come back as written (the fold-model cache reads "train_seconds" from them);
// a model without them has none; a file that is not JSON is a clear error.
TEST(ModelIo, TrainingInfoIsReadBack) {
  const auto dir = std::filesystem::temp_directory_path() / ("fusedet_model_info_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const ModelInfo info = {{"train_seconds", "12.5"}, {"stop_reason", "stage limit 4 reached"}};
  saveModel(sample(), dir / "with.json", info);
  EXPECT_EQ(loadModelInfo(dir / "with.json"), info);
  saveModel(sample(), dir / "without.json");
  EXPECT_TRUE(loadModelInfo(dir / "without.json").empty());
  std::ofstream(dir / "garbage.json") << "{\"training\": {\"train_seconds\": 3";
  try {
    loadModelInfo(dir / "garbage.json");
    FAIL() << "no exception";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("garbage.json: not valid JSON"), std::string::npos) << e.what();
  }
  EXPECT_THROW(loadModelInfo(dir / "missing.json"), ModelError);
  std::filesystem::remove_all(dir);
}

TEST(ModelIo, ErrorsNameThePlaceAndTheReason) {
  const std::string good = modelToText(sample());
  EXPECT_EQ(errorOf(good), "");
  EXPECT_NE(errorOf(good.substr(0, good.size() / 2)).find("m.json: line "), std::string::npos);
  EXPECT_NE(errorOf(replace(good, "\"threshold\":0.125", "\"threshold\":\"x\""))
                .find("m.json: stages[0].stumps[0].threshold: expected a number, got string"),
            std::string::npos);
  EXPECT_NE(errorOf(replace(good, "\"type\":\"g\"", "\"type\":\"k\""))
                .find("stages[0].stumps[0].type: unknown feature type 'k'"),
            std::string::npos);
  EXPECT_NE(errorOf(replace(good, "\"version\": 1", "\"version\": 7"))
                .find("version: unsupported version 7 (this build reads 1)"),
            std::string::npos);
  EXPECT_NE(errorOf(replace(good, "\"layer\":\"hue_distance\"", "\"layer\":\"sonar\""))
                .find("stages[0].stumps[0].layer: layer 'sonar' is not in \"layers\""),
            std::string::npos);
  EXPECT_NE(errorOf(replace(good, "[0.25,0.0,0.5,0.5]", "[0.75,0.0,0.5,0.5]")).find("stages[0].stumps[0]: "),
            std::string::npos);
  EXPECT_NE(errorOf(replace(good, "\"reference_hue\": 25.0", "\"reference_hue\": null")).find("reference hue"),
            std::string::npos);
  EXPECT_NE(errorOf(replace(good, "\"fusedet-cascade\"", "\"opencv\"")).find("format: 'opencv' is not"),
            std::string::npos);
  EXPECT_NE(errorOf("[1,2]").find("expected a JSON object"), std::string::npos);
  EXPECT_NE(errorOf(replace(good, "\"threshold\":0.125", "\"threshold\":1e999")).find("m.json: not a valid model"),
            std::string::npos);
}

TEST(ModelIo, FuzzedFilesNeverCrash) {
  const std::string good = modelToText(sample());
  std::mt19937 rng(11);
  int loaded = 0, rejected = 0;
  for (int it = 0; it < 3000; ++it) {
    const std::string s = fuzz::randomlyEdited(good, rng, "{}[],:\"0-e9.");
    try {
      modelFromText(s, "fuzz.json");
      ++loaded;
    } catch (const ModelError&) {
      ++rejected;
    }
  }
  EXPECT_GT(rejected, 0);
  EXPECT_EQ(loaded + rejected, 3000);
}
