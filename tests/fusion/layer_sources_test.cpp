// Layer sources (fusion/layer_sources.h): every layer the importer writes has a source, and
// weight shares sum per source.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "fusedet/fusion/channel_layers.h"
#include "fusedet/fusion/layer_sources.h"

using namespace fusedet;
using namespace fusedet::fusion;

TEST(LayerSources, PaperLayersAreCameraOrLaser) {
  EXPECT_EQ(layerSource("red"), LayerSource::camera);
  EXPECT_EQ(layerSource("hue_distance"), LayerSource::camera);
  EXPECT_EQ(layerSource("intensity"), LayerSource::camera);
  EXPECT_EQ(layerSource("distance"), LayerSource::laser);
  EXPECT_EQ(layerSource("remission"), LayerSource::laser);
  EXPECT_EQ(layerSource("grad_3"), LayerSource::cameraDerived);
  EXPECT_EQ(layerSource("grad_mag"), LayerSource::cameraDerived);
  EXPECT_EQ(layerSource("height"), LayerSource::laserDerived);
  EXPECT_EQ(layerSource("distance_grad"), LayerSource::laserDerived);
  EXPECT_EQ(layerSource("grad_6"), LayerSource::unknown);  // there are six bins, 0..5
  EXPECT_EQ(toString(LayerSource::unknown), "other");
}

TEST(LayerSources, ChannelListMatchesWhatTheChannelCodeAdds) {
  // The stack the channel functions really build (not a copy of the name list) names exactly
  // extraChannelLayers().
  LayerStack s;
  s.setReferenceSize(16, 8);
  cv::Mat grey(8, 16, CV_8UC1);
  cv::randu(grey, 0, 255);
  s.set(Layer{"intensity", grey, {}});
  cv::Mat dist(8, 16, CV_32FC1, cv::Scalar(10.0f));
  s.set(Layer{"distance", dist, cv::Mat(8, 16, CV_8UC1, cv::Scalar(255))});
  addGradientChannels(s);
  addLaserChannels(s, (Eigen::Matrix3d() << 10, 0, 8, 0, 10, 4, 0, 0, 1).finished());
  for (const std::string& l : extraChannelLayers()) EXPECT_TRUE(s.has(l)) << l;
  EXPECT_EQ(s.size(), 2 + extraChannelLayers().size());
  EXPECT_EQ(paperPoolLayers().size(), 7u);
  for (const std::string& l : paperPoolLayers()) EXPECT_NE(layerSource(l), LayerSource::unknown) << l;
}

TEST(LayerSources, SharesSumPerSource) {
  const std::map<std::string, double> shares = {{"red", 0.1},    {"hue_distance", 0.05}, {"distance", 0.25},
                                                {"grad_0", 0.2}, {"grad_mag", 0.1},      {"height", 0.25},
                                                {"mystery", 0.05}};
  const auto by = sharesBySource(shares);
  ASSERT_EQ(by.size(), 5u);
  EXPECT_NEAR(by.at("camera"), 0.15, 1e-12);
  EXPECT_NEAR(by.at("laser"), 0.25, 1e-12);
  EXPECT_NEAR(by.at("camera (derived)"), 0.3, 1e-12);
  EXPECT_NEAR(by.at("laser (derived)"), 0.25, 1e-12);
  EXPECT_NEAR(by.at("other"), 0.05, 1e-12);
}
