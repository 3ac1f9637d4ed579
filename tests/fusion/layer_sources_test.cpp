// SPDX-License-Identifier: Apache-2.0
// Layer sources (fusedet/fusion/layer_sources.h): every paper pool layer has a source, and
// weight shares sum per source.
#include <gtest/gtest.h>

#include "fusedet/fusion/layer_sources.h"

using namespace fusedet;
using namespace fusedet::fusion;

TEST(LayerSources, PaperLayersAreCameraOrLaser) {
  EXPECT_EQ(layerSource("red"), LayerSource::camera);
  EXPECT_EQ(layerSource("hue_distance"), LayerSource::camera);
  EXPECT_EQ(layerSource("intensity"), LayerSource::camera);
  EXPECT_EQ(layerSource("distance"), LayerSource::laser);
  EXPECT_EQ(layerSource("remission"), LayerSource::laser);
  EXPECT_EQ(layerSource("grad_mag"), LayerSource::unknown);  // no derived channel is a pool layer
  EXPECT_EQ(toString(LayerSource::unknown), "other");
}

TEST(LayerSources, PaperPoolLayersAreTheSevenOfTheSensors) {
  EXPECT_EQ(paperPoolLayers().size(), 7u);
  for (const std::string& l : paperPoolLayers()) EXPECT_NE(layerSource(l), LayerSource::unknown) << l;
}

TEST(LayerSources, NetworkLayersAreTheirOwnSource) {
  ASSERT_EQ(networkPoolLayers().size(), 3u);
  for (const std::string& l : networkPoolLayers()) EXPECT_EQ(layerSource(l), LayerSource::network) << l;
  EXPECT_EQ(toString(LayerSource::network), "network");
  const auto by = sharesBySource({{"neural_person", 0.2}, {"neural_car", 0.3}, {"distance", 0.5}});
  ASSERT_EQ(by.size(), 2u);
  EXPECT_NEAR(by.at("network"), 0.5, 1e-12);
  EXPECT_NEAR(by.at("laser"), 0.5, 1e-12);
}

TEST(LayerSources, SharesSumPerSource) {
  const std::map<std::string, double> shares = {{"red", 0.1},       {"hue_distance", 0.05}, {"distance", 0.25},
                                                {"remission", 0.5}, {"mystery", 0.1}};
  const auto by = sharesBySource(shares);
  ASSERT_EQ(by.size(), 3u);
  EXPECT_NEAR(by.at("camera"), 0.15, 1e-12);
  EXPECT_NEAR(by.at("laser"), 0.75, 1e-12);
  EXPECT_NEAR(by.at("other"), 0.1, 1e-12);
}
