// SPDX-License-Identifier: Apache-2.0
// The live view's parts (daemon/live/): live.listen addresses, the Foxglove WebSocket protocol's
// messages, the channels a stack gives, and the server on a loopback port driven by a
// Boost.Beast client (HTTP page, handshake, serverInfo, advertise, subscribe, Message Data).
// The official Foxglove client and a browser: tests/daemon/live/ (label live).

#include <gtest/gtest.h>

#include <atomic>
#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>
#include <thread>

#include "fusedet/daemon/config.h"
#include "fusedet/daemon/live/foxglove_protocol.h"
#include "fusedet/daemon/live/listen_address.h"
#include "fusedet/daemon/live/live_channels.h"
#include "fusedet/daemon/live/live_server.h"

using namespace fusedet;
using namespace fusedet::daemon;
using namespace fusedet::daemon::live;
namespace net = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;

TEST(LiveListen, AddressesAndTheirErrors) {
  EXPECT_FALSE(parseListenAddress(""));
  const auto port = parseListenAddress("8765");
  ASSERT_TRUE(port);
  EXPECT_EQ(port->host, "127.0.0.1");
  EXPECT_EQ(port->port, 8765);
  EXPECT_TRUE(port->loopback());
  const auto any = parseListenAddress("0.0.0.0:80");
  ASSERT_TRUE(any);
  EXPECT_FALSE(any->loopback());
  EXPECT_EQ(any->text(), "0.0.0.0:80");
  const auto v6 = parseListenAddress("[::1]:9000");
  ASSERT_TRUE(v6);
  EXPECT_EQ(v6->host, "::1");
  EXPECT_TRUE(v6->loopback());
  EXPECT_EQ(v6->text(), "[::1]:9000");
  EXPECT_TRUE(parseListenAddress("127.3.4.5:1")->loopback());
  const auto local = parseListenAddress("unix:/run/fusedet/live.sock");
  ASSERT_TRUE(local);
  EXPECT_EQ(local->kind, ListenAddress::Kind::kUnix);
  EXPECT_EQ(local->path, "/run/fusedet/live.sock");
  for (const char* bad : {"robot.local:8765", "::1:8765", "127.0.0.1:70000", "127.0.0.1:", "unix:relative.sock", "80a"})
    EXPECT_THROW(parseListenAddress(bad), std::invalid_argument) << bad;
}

TEST(LiveListen, ConfigNamesTheKeyAndLine) {
  try {
    parseConfig("version: 1\nlive:\n  listen: robot.local:8765\n", "x.yaml");
    FAIL() << "accepted a host name";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("x.yaml:3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("live.listen"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not an IP address"), std::string::npos) << e.what();
  }
  EXPECT_EQ(Config{}.live.listen, "");  // off by default
}

TEST(FoxgloveProtocol, ServerMessagesAndClientOps) {
  const auto info = nlohmann::json::parse(serverInfoMessage("fusedetd", "7"));
  EXPECT_EQ(info["op"], "serverInfo");
  EXPECT_EQ(info["sessionId"], "7");
  EXPECT_TRUE(info["capabilities"].empty());
  const auto adv = nlohmann::json::parse(advertiseMessage({{3, "/t", "foxglove.X", "{}"}}));
  EXPECT_EQ(adv["channels"][0]["id"], 3);
  EXPECT_EQ(adv["channels"][0]["encoding"], "json");
  EXPECT_EQ(adv["channels"][0]["schemaEncoding"], "jsonschema");

  const ClientOp sub = parseClientOp(R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":4},{"id":9,"channelId":1}]})");
  ASSERT_TRUE(std::holds_alternative<Subscribe>(sub));
  const auto& list = std::get<Subscribe>(sub).subscriptions;
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[1].first, 9u);
  EXPECT_EQ(list[1].second, 1u);
  const ClientOp unsub = parseClientOp(R"({"op":"unsubscribe","subscriptionIds":[9]})");
  ASSERT_TRUE(std::holds_alternative<Unsubscribe>(unsub));
  EXPECT_EQ(std::get<Unsubscribe>(unsub).subscriptionIds, std::vector<std::uint32_t>{9});
  for (const char* bad : {"{", "[]", R"({"op":"advertise","channels":[]})", R"({"op":"subscribe","subscriptions":[{"id":-1,"channelId":1}]})",
                          R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":4294967296}]})", R"({"op":"unsubscribe"})"})
    EXPECT_TRUE(std::holds_alternative<Unknown>(parseClientOp(bad))) << bad;

  const auto h = messageDataHeader(0x01020304, 0x1122334455667788ull);
  const std::array<std::uint8_t, 13> want{0x01, 0x04, 0x03, 0x02, 0x01, 0x88, 0x77, 0x66, 0x55, 0x44, 0x33, 0x22, 0x11};
  EXPECT_EQ(h, want);
}

namespace {

ChannelSettings settings() {
  ChannelSettings s;
  s.projection.K << 500, 0, 320, 0, 500, 240, 0, 0, 1;
  s.projection.width = 640;
  s.projection.height = 480;
  s.layers = {"distance"};
  return s;
}

// A stack with one located car and a view: a 64x48 colour image and a distance layer.
std::shared_ptr<StackResult> stack(std::int64_t stampNs) {
  auto r = std::make_shared<StackResult>();
  r->frameStamp = Stamp{stampNs};
  LocatedDetection d;
  d.detection.className = "car";
  d.detection.score = 1.5;
  d.detection.box = Box{10, 20, 30, 40};
  Position p;
  p.camera = Eigen::Vector3d(-1, -0.5, 8);
  p.robot = Eigen::Vector3d(8, 1, 0.5);
  p.range = 10;
  d.position = p;
  r->detections.push_back(d);
  auto view = std::make_shared<StackView>();
  view->layers = LayerStack(64, 48);
  for (auto name : {layer::kRed, layer::kGreen, layer::kBlue})
    view->layers.set(Layer{std::string(name), cv::Mat(48, 64, CV_8U, cv::Scalar(100)), {}});
  cv::Mat distance(24, 32, CV_32F, cv::Scalar(5.0f));
  distance(cv::Rect(0, 0, 16, 24)) = 12.0f;
  view->layers.set(Layer{std::string(layer::kDistance), distance, {}});
  view->sweep = {{1, 2, 3, 0.5f, 0}, {4, 5, 6, 0.25f, 0}};
  r->view = view;
  return r;
}

nlohmann::json jsonOf(const std::vector<std::uint8_t>& b) { return nlohmann::json::parse(b.begin(), b.end()); }

}  // namespace

TEST(LiveChannels, EachChannelsMessageForAStack) {
  const LiveChannels channels(settings());
  std::vector<std::string> topics;
  for (const Channel& c : channels.channels()) topics.push_back(c.topic);
  EXPECT_EQ(topics, (std::vector<std::string>{"/camera/compressed", "/detections", "/detections/scene", "/sweep/points", "/tf",
                                              "/camera/calibration", "/tracks/scene", "/tracks", "/layers/distance", "/status"}));
  EXPECT_EQ(channels.statusChannel(), 10u);
  const auto r = stack(5'000'000'123);
  const auto image = jsonOf(*channels.encode(1, *r));
  EXPECT_EQ(image["format"], "jpeg");
  EXPECT_EQ(image["timestamp"]["sec"], 5);
  EXPECT_EQ(image["timestamp"]["nsec"], 123);
  const auto annotations = jsonOf(*channels.encode(2, *r));
  EXPECT_EQ(annotations["points"][0]["points"][2]["x"], 40.0);  // x + w
  EXPECT_EQ(annotations["points"][0]["points"][2]["y"], 60.0);  // y + h
  const auto scene = jsonOf(*channels.encode(3, *r));
  const auto& cube = scene["entities"][0]["cubes"][0];
  EXPECT_EQ(cube["pose"]["position"]["x"], 8.0);
  EXPECT_DOUBLE_EQ(cube["size"]["x"].get<double>(), 30.0 / 500 * 10);  // box width / fx * range
  EXPECT_DOUBLE_EQ(cube["size"]["z"].get<double>(), 40.0 / 500 * 10);
  EXPECT_TRUE(scene["entities"][0]["spheres"].empty());
  const auto cloud = jsonOf(*channels.encode(4, *r));
  EXPECT_EQ(cloud["frame_id"], "laser_base");
  EXPECT_EQ(cloud["data"].get<std::string>().size(), 44u);  // 2 points x 16 bytes, base64
  const auto calibration = jsonOf(*channels.encode(6, *r));
  EXPECT_EQ(calibration["K"][0], 500.0);
  EXPECT_EQ(calibration["width"], 640);
  EXPECT_TRUE(channels.encode(9, *r));  // /layers/distance
  EXPECT_FALSE(channels.encode(10, *r));  // status: only encodeStatus
  EXPECT_FALSE(channels.encode(11, *r));
  StackResult noView = *r;
  noView.view.reset();
  EXPECT_FALSE(channels.encode(1, noView));
  EXPECT_FALSE(channels.encode(4, noView));
  EXPECT_TRUE(channels.encode(2, noView));
}

TEST(LiveServer, PageHandshakeSubscribeAndMessageData) {
  LiveServer server(*parseListenAddress("127.0.0.1:0"), LiveLimits{2, 1 << 20}, LiveChannels(settings()),
                    [] { return nlohmann::json{{"mode", "test"}}; });
  server.start();
  const std::uint16_t port = server.address().port;
  ASSERT_NE(port, 0);
  net::io_context io;
  const net::ip::tcp::endpoint endpoint(net::ip::make_address("127.0.0.1"), port);
  {  // the page
    beast::tcp_stream s(io);
    s.connect(endpoint);
    http::request<http::empty_body> req(http::verb::get, "/", 11);
    req.set(http::field::host, "localhost");
    http::write(s, req);
    beast::flat_buffer b;
    http::response<http::string_body> res;
    http::read(s, b, res);
    EXPECT_EQ(res.result(), http::status::ok);
    EXPECT_NE(res.body().find("live.js"), std::string::npos);
    http::request<http::empty_body> missing(http::verb::get, "/../etc/passwd", 11);
    missing.set(http::field::host, "localhost");
    http::write(s, missing);
    http::response<http::string_body> res2;
    http::read(s, b, res2);
    EXPECT_EQ(res2.result(), http::status::not_found);
  }
  {  // a WebSocket client without the subprotocol is refused
    websocket::stream<net::ip::tcp::socket> ws(io);
    ws.next_layer().connect(endpoint);
    EXPECT_THROW(ws.handshake("localhost", "/"), beast::system_error);
  }
  websocket::stream<net::ip::tcp::socket> ws(io);
  ws.next_layer().connect(endpoint);
  ws.set_option(websocket::stream_base::decorator(
      [](websocket::request_type& req) { req.set(http::field::sec_websocket_protocol, "foxglove.websocket.v1"); }));
  websocket::response_type response;
  ws.handshake(response, "localhost", "/");
  EXPECT_EQ(response[http::field::sec_websocket_protocol], "foxglove.websocket.v1");
  beast::flat_buffer b;
  ws.read(b);
  EXPECT_EQ(nlohmann::json::parse(beast::buffers_to_string(b.data()))["op"], "serverInfo");
  b.consume(b.size());
  ws.read(b);
  const auto adv = nlohmann::json::parse(beast::buffers_to_string(b.data()));
  b.consume(b.size());
  ASSERT_EQ(adv["op"], "advertise");
  EXPECT_EQ(adv["channels"][1]["topic"], "/detections");
  ws.text(true);
  ws.write(net::buffer(std::string(R"({"op":"subscribe","subscriptions":[{"id":7,"channelId":2}]})")));
  ws.write(net::buffer(std::string(R"({"op":"subscribe","subscriptions":[{"id":8,"channelId":99}]})")));
  // The subscription reaches the live thread some time after the write: publish until a frame comes.
  std::atomic<bool> received{false};
  std::thread publisher([&] {
    for (int i = 0; i < 200 && !received; ++i) {
      server.publish(stack(1'000'000'000 + i));
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  });
  // The warning about channel 99 and a Message Data frame, in either order.
  nlohmann::json warning;
  std::string frame;
  for (int i = 0; i < 2; ++i) {
    ws.read(b);
    if (ws.got_binary()) frame = beast::buffers_to_string(b.data());
    else warning = nlohmann::json::parse(beast::buffers_to_string(b.data()));
    b.consume(b.size());
  }
  received = true;
  publisher.join();
  EXPECT_EQ(warning["op"], "status");
  EXPECT_EQ(warning["message"], "subscribe: no channel 99");
  ASSERT_GT(frame.size(), 13u);
  EXPECT_EQ(frame[0], 0x01);
  std::uint32_t sub = 0;
  std::uint64_t stamp = 0;
  for (int i = 3; i >= 0; --i) sub = (sub << 8) | static_cast<std::uint8_t>(frame[static_cast<std::size_t>(1 + i)]);
  for (int i = 7; i >= 0; --i) stamp = (stamp << 8) | static_cast<std::uint8_t>(frame[static_cast<std::size_t>(5 + i)]);
  EXPECT_EQ(sub, 7u);
  const auto message = nlohmann::json::parse(frame.substr(13));
  EXPECT_EQ(stamp, message["timestamp"]["sec"].get<std::uint64_t>() * 1'000'000'000u + message["timestamp"]["nsec"].get<std::uint64_t>());
  EXPECT_EQ(message["texts"][0]["text"], "car 1.50");
  const LiveCounters c = server.counters();
  EXPECT_EQ(c.viewers, 1u);
  EXPECT_EQ(c.accepted, 1u);
  EXPECT_EQ(c.refused, 1u);  // the one without the subprotocol
  EXPECT_GE(c.encoded[1], 1u);
  EXPECT_EQ(c.encoded[0], 0u);  // nobody subscribed to the image: never encoded
  server.stop();
}
