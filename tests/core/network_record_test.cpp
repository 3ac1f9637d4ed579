// SPDX-License-Identifier: Apache-2.0
// NetworkRecord (core/network_record.h): its text form back and forth, bad text refused naming
// what is wrong, and requireSameNetwork naming both networks when they differ.

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "fusedet/core/network_record.h"

using namespace fusedet;

namespace {

const std::string kA(64, 'a'), kB(64, 'b');

NetworkRecord darknet() { return NetworkRecord{"darknet", 832, 256, {"net.cfg", "net.weights"}, {kA, kB}}; }

std::string thrown(const NetworkRecord& wanted, const NetworkRecord& made) {
  try {
    requireSameNetwork(wanted, "car.json", made, "the stack 'kitti/000001'");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(NetworkRecord, TextRoundTrips) {
  const NetworkRecord r = darknet();
  EXPECT_EQ(r.text(), "darknet 832x256 net.cfg sha256:" + kA + " net.weights sha256:" + kB);
  EXPECT_EQ(parseNetworkRecord(r.text()), r);
  EXPECT_TRUE(parseNetworkRecord("").empty());
  EXPECT_EQ(NetworkRecord{}.text(), "");
}

TEST(NetworkRecord, BadTextIsRefusedNamingTheProblem) {
  const auto message = [](const std::string& text) {
    try {
      (void)parseNetworkRecord(text);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message("darknet 832 net.cfg sha256:" + kA).find("'832' is not an input size"), std::string::npos);
  EXPECT_NE(message("darknet 832x256 net.cfg md5:" + kA).find("'md5:"), std::string::npos);
  EXPECT_NE(message("darknet 832x256 net.cfg sha256:ABC").find("64 lower-case hex"), std::string::npos);
  EXPECT_NE(message("darknet 832x256 net.cfg").find("wrong number of words"), std::string::npos);
}

TEST(NetworkRecord, NetworkLayersAreNamedNeural) {
  EXPECT_TRUE(isNetworkLayer("neural_car"));
  EXPECT_FALSE(isNetworkLayer("distance"));
  EXPECT_FALSE(isNetworkLayer("neural"));
  EXPECT_TRUE(usesNetworkLayers({"red", "neural_person"}));
  EXPECT_FALSE(usesNetworkLayers({"red", "distance"}));
}

TEST(NetworkRecord, AnotherNetworkIsAnErrorNamingBoth) {
  EXPECT_EQ(thrown(darknet(), darknet()), "");
  NetworkRecord wider = darknet();
  wider.inputWidth = 1248;
  const std::string e = thrown(darknet(), wider);
  EXPECT_NE(e.find("car.json"), std::string::npos) << e;
  EXPECT_NE(e.find(darknet().text()), std::string::npos) << e;
  EXPECT_NE(e.find(wider.text()), std::string::npos) << e;
  EXPECT_NE(e.find("kitti/000001"), std::string::npos) << e;
  NetworkRecord otherWeights = darknet();
  otherWeights.sha256[1] = kA;
  EXPECT_NE(thrown(darknet(), otherWeights).find(otherWeights.text()), std::string::npos);
  EXPECT_NE(thrown(darknet(), NetworkRecord{}).find("has no network"), std::string::npos);
  EXPECT_NE(thrown(NetworkRecord{}, darknet()).find("records no network"), std::string::npos);
}
