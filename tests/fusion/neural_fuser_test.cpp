// SPDX-License-Identifier: Apache-2.0
// The network as a layer source of the Fuser (fusion/neural/neural_layers.h, fuser.h): a KITTI
// frame imported with Yolo-Fastest-XL gets the score layers a direct run of the same network on the
// frame gives (cell for cell) and the network's record; without a network the stack is as before;
// the layers from a stored stack's camera layers (fusedet detect's path) equal the import's; the
// data set keeps them and the record; a missing network file is named; fuse() in two steps (the
// daemon's network thread) is fuse(); a failed run adds nothing and names the network and why.

#include <gtest/gtest.h>

#include <filesystem>
#include <limits>
#include <memory>
#include <opencv2/core.hpp>
#include <unistd.h>

#include "fusedet/core/dataset.h"
#include "fusedet/fusion/datasets/kitti_import.h"
#include "fusedet/fusion/camera_layers.h"
#include "fusedet/fusion/neural/neural_layers.h"

namespace fusedet::fusion {
namespace {
namespace fs = std::filesystem;

const fs::path kModels = FUSEDET_NETWORKS_DIR;
const fs::path kKitti = fs::path(FUSEDET_DATA_DIR) / "kitti";

NeuralLayerOptions darknetOptions() {
  NeuralLayerOptions o;  // the defaults: darknet, Yolo-Fastest-XL's files, 832 x 256
  o.directory = kModels;
  return o;
}

TEST(NeuralFuser, KittiImportAddsTheNetworksScoreLayersAndRecord) {
  const KittiFrame frame = readKittiFrame(kKitti, "000000");
  const auto neural = std::make_shared<const NeuralLayers>(darknetOptions());
  const DatasetItem plain = fuseKittiFrame(frame, "kitti", {});
  FuseTimings t;
  const DatasetItem item = fuseKittiFrame(frame, "kitti", {}, &t, neural);
  EXPECT_GT(t.neuralMs, 0.0);

  // Without a network: the seven layers and no record, as before.
  EXPECT_EQ(plain.stack.names(), Fuser::layerNames());
  EXPECT_TRUE(plain.stack.network.empty());
  // With it: the same seven, bit for bit, then the score layers.
  std::vector<std::string> names = Fuser::layerNames();
  for (const std::string& n : neural->layerNames()) names.push_back(n);
  EXPECT_EQ(item.stack.names(), names);
  EXPECT_EQ(kittiFuser(frame.calib, frame.image.cols, frame.image.rows, {}, neural).stackLayers(), names);
  for (const std::string& n : Fuser::layerNames())
    EXPECT_EQ(cv::norm(item.stack.at(n).data, plain.stack.at(n).data, cv::NORM_INF), 0.0) << n;

  // The network run on its own on the frame (KITTI images are rectified: the fuser's undistorted
  // image is the frame), its anchors made into layers at half resolution.
  Network direct(networkSpecFor(darknetOptions()));
  LayerStack expected(frame.image.cols, frame.image.rows);
  addScoreLayers(expected, direct.run(frame.image), 0.5);
  for (const ScoreLayerClass& c : defaultScoreLayers()) {
    const Layer& l = item.stack.at(c.layer);
    EXPECT_EQ(l.width(), 621);
    EXPECT_EQ(l.height(), 188);
    EXPECT_EQ(cv::norm(l.data, expected.at(c.layer).data, cv::NORM_INF), 0.0) << c.layer;
  }
  double carMax = 0;
  cv::minMaxLoc(item.stack.at("neural_car").data, nullptr, &carMax);
  EXPECT_GT(carMax, 0.3);  // frame 000000 holds a van the network calls a car (its own data)
  EXPECT_EQ(item.stack.network, direct.identity().record());
  EXPECT_EQ(item.stack.network.kind, "darknet");
  EXPECT_EQ(item.stack.network.fileNames, (std::vector<std::string>{"yolo-fastest-1.1-xl.cfg", "yolo-fastest-1.1-xl.weights"}));

  // fusedet detect's path: the layers made again from the stored stack's camera layers.
  LayerStack again = plain.stack;
  neural->add(again, cameraImage(plain.stack));
  for (const ScoreLayerClass& c : defaultScoreLayers())
    EXPECT_EQ(cv::norm(again.at(c.layer).data, item.stack.at(c.layer).data, cv::NORM_INF), 0.0) << c.layer;

  // The data set keeps the layers (16-bit quantised) and the record.
  const fs::path dir = fs::temp_directory_path() / ("fusedet_neural_fuser_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  writeDatasetItem(dir, item);
  const DatasetItem back = readDatasetItem(dir, item.id);
  EXPECT_EQ(back.stack.network, item.stack.network);
  EXPECT_LT(cv::norm(back.stack.at("neural_car").data, item.stack.at("neural_car").data, cv::NORM_INF), 1e-4);
  fs::remove_all(dir);
}

TEST(NeuralFuser, MissingOrWrongNetworkIsNamed) {
  NeuralLayerOptions o = darknetOptions();
  o.directory = kModels / "no-such-folder";
  try {
    NeuralLayers n(o);
    FAIL() << "loaded a network from a missing folder";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find((o.directory / "yolo-fastest-1.1-xl.cfg").string() + ": network file (darknet) not found"),
              std::string::npos)
        << e.what();
  }
  o = darknetOptions();
  o.input = {830, 256};
  EXPECT_THROW(NeuralLayers{o}, std::runtime_error);  // not a multiple of 32
  o = darknetOptions();
  o.scale = 0;
  EXPECT_THROW(NeuralLayers{o}, std::runtime_error);
  EXPECT_EQ(defaultNetworkFiles(NetworkKind::yolov5Onnx, "d"), (std::vector<fs::path>{"d/yolov5n_256x832.onnx"}));
  o = darknetOptions();
  o.files = {"yolo-fastest-1.1-xl.cfg", kModels / "yolo-fastest-1.1-xl.weights"};  // relative: in the folder
  EXPECT_EQ(networkSpecFor(o).files, defaultNetworkFiles(NetworkKind::darknet, kModels));
}

// fuse() in two steps (fusedetd's pipeline: the network on its own thread) gives the same stack.
TEST(NeuralFuser, FuseSensorsThenNetworkLayersIsFuse) {
  const KittiFrame frame = readKittiFrame(kKitti, "000000");
  const auto neural = std::make_shared<const NeuralLayers>(darknetOptions());
  const Fuser fuser = kittiFuser(frame.calib, frame.image.cols, frame.image.rows, {}, neural);
  const Sweep& sweep = frame.points;
  const LayerStack whole = fuser.fuse(frame.image, sweep);
  cv::Mat undistorted;
  LayerStack split = fuser.fuseSensors(frame.image, sweep, &undistorted);
  EXPECT_EQ(split.names(), Fuser::layerNames());
  EXPECT_TRUE(split.network.empty());
  fuser.addNetworkLayers(split, undistorted);
  ASSERT_EQ(split.names(), whole.names());
  for (const std::string& n : whole.names())
    EXPECT_EQ(cv::norm(split.at(n).data, whole.at(n).data, cv::NORM_INF), 0.0) << n;
  EXPECT_EQ(split.network, whole.network);
}

// A run that fails adds nothing and names the network and the problem: cv::dnn throwing, an
// output of another shape, a score that is not finite or not in [0, 1], a box that is not finite.
TEST(NeuralFuser, AFailedRunAddsNothingAndSaysWhy) {
  const KittiFrame frame = readKittiFrame(kKitti, "000000");
  const Network reference(networkSpecFor(darknetOptions()));
  const std::string identity = reference.identity().text();
  int mode = 0;
  const NeuralLayers layers(darknetOptions(), [&mode](Network& n, const cv::Mat& bgr) {
    if (mode == 1) CV_Error(cv::Error::StsBadSize, "injected blob size");
    Anchors a = n.run(bgr);
    if (mode == 2) a.scores = a.scores.colRange(0, 3).clone();
    if (mode == 3) a.scores.at<float>(7, 2) = std::numeric_limits<float>::quiet_NaN();
    if (mode == 4) a.scores.at<float>(7, 2) = 1.5f;
    if (mode == 5) a.boxes[3].w = std::numeric_limits<double>::infinity();
    return a;
  });
  const auto failure = [&](int m) {
    mode = m;
    LayerStack stack(frame.image.cols, frame.image.rows);
    try {
      layers.add(stack, frame.image);
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(stack.size(), 0u) << "nothing added";
      EXPECT_TRUE(stack.network.empty());
      return std::string(e.what());
    }
    return std::string("(added ") + std::to_string(stack.size()) + " layers)";
  };
  EXPECT_EQ(failure(0), "(added 3 layers)");
  const std::string prefix = "network " + identity + " on a 1242x375 image: ";
  EXPECT_EQ(failure(1).substr(0, prefix.size() + 16), prefix + "cv::dnn failed: ");
  EXPECT_NE(failure(1).find("injected blob size"), std::string::npos);
  EXPECT_EQ(failure(2), prefix + "output of 3120 anchor rows x 3 classes where it gave 3120 x 80 at load");
  EXPECT_EQ(failure(3), prefix + "output of a class score that is not finite");
  EXPECT_EQ(failure(4), prefix + "output of a class score outside [0, 1] (1.500000)");
  EXPECT_EQ(failure(5), prefix + "output of a box that is not finite");
}

}  // namespace
}  // namespace fusedet::fusion
