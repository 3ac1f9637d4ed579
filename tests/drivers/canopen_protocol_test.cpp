// SPDX-License-Identifier: Apache-2.0
// CANopen facts from design.md §3 (bytes written out by hand here, not by the encoder under
// test) and the SDO client against scripted server responses: expedited, segmented with
// toggles, abort codes, timeouts.

#include <gtest/gtest.h>

#include "fusedet/drivers/canopen/inprocess_bus.h"
#include "fusedet/drivers/canopen/protocol.h"
#include "fusedet/drivers/canopen/sdo_client.h"
#include "fusedet/drivers/canopen/tilt_tpdo.h"

using namespace fusedet::drivers::canopen;
using namespace std::chrono_literals;

TEST(CanopenProtocol, CobIdsAndNmt) {
  EXPECT_EQ(cob::tpdo(1, 5), 0x185u);
  EXPECT_EQ(cob::tpdo(4, 5), 0x485u);
  EXPECT_EQ(cob::rpdo(1, 5), 0x205u);
  EXPECT_EQ(cob::rpdo(4, 127), 0x57Fu);
  EXPECT_EQ(nmtFrame(NmtCommand::kStart, 5).toString(), "000#0105");
  EXPECT_EQ(nmtFrame(NmtCommand::kResetNode, 0).toString(), "000#8100");
  EXPECT_EQ(nmtFrame(NmtCommand::kResetCommunication, 9).toString(), "000#8209");
  EXPECT_EQ(heartbeatFrame(5, NmtState::kPreOperational).toString(), "705#7F");
  EXPECT_EQ(syncFrame().toString(), "080#");
  EXPECT_EQ(*parseNmtState(0x85), NmtState::kOperational);  // toggle bit ignored
  EXPECT_FALSE(parseNmtState(0x33));
  auto c = splitCobId(0x585);
  EXPECT_EQ(c.function, 0x580u);
  EXPECT_EQ(c.node, 5);
}

TEST(CanopenProtocol, SdoCommandBytes) {
  EXPECT_EQ(sdo::downloadCommand(4), 0x23);
  EXPECT_EQ(sdo::downloadCommand(3), 0x27);
  EXPECT_EQ(sdo::downloadCommand(2), 0x2B);
  EXPECT_EQ(sdo::downloadCommand(1), 0x2F);
  EXPECT_EQ(sdo::uploadExpeditedResponse(4), 0x43);
  EXPECT_EQ(sdo::uploadExpeditedResponse(3), 0x47);
  EXPECT_EQ(sdo::uploadExpeditedResponse(2), 0x4B);
  EXPECT_EQ(sdo::uploadExpeditedResponse(1), 0x4F);
  EXPECT_EQ(sdoAbortFrame(0x585, 0x6041, 0, 0x06020000).toString(), "585#8041600000000206");
}

TEST(CanopenProtocol, AbortAndEmcyTexts) {
  EXPECT_EQ(abortCodeText(0x06020000), "0x06020000 object does not exist in the object dictionary");
  EXPECT_EQ(abortCodeText(0x05040000), "0x05040000 SDO protocol timed out");
  EXPECT_EQ(abortCodeText(0x12345678), "0x12345678 unknown abort code");
  auto e = parseEmcy(CanFrame::make(0x085, {0x11, 0x86, 0x21, 0, 0, 0, 0, 0}));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->code, 0x8611);
  EXPECT_EQ(describe(*e), "EMCY 0x8611 following error (error register: generic, device profile)");
  EXPECT_EQ(emcyCodeText(0x2311), "0x2311 current");  // class of the upper nibble
  EXPECT_FALSE(parseEmcy(CanFrame::make(0x085, {0x11})));
  EXPECT_EQ(emcyFrame(5, *e).toString(), "085#1186210000000000");
}

// Payload bytes little-endian; a count past the payload or beyond 4 is cut, never written past it.
TEST(CanopenProtocol, LittleEndianPayloadsStayInTheirBuffer) {
  std::array<std::uint8_t, 8> b{};
  writeLe(b, 1, 0x607A, 2);
  EXPECT_EQ(b[1], 0x7A);
  EXPECT_EQ(b[2], 0x60);
  EXPECT_EQ(readLe(b, 1, 2), 0x607Au);
  writeLe(b, 4, 0xDDCCBBAA, 4);
  EXPECT_EQ(readLe(b, 4, 4), 0xDDCCBBAAu);
  std::array<std::uint8_t, 10> guarded{};
  guarded.fill(0xEE);
  writeLe(std::span<std::uint8_t>(guarded).subspan(1, 8), 6, 0x44332211, 4);
  EXPECT_EQ(guarded[7], 0x11);
  EXPECT_EQ(guarded[8], 0x22);
  EXPECT_EQ(guarded[9], 0xEE) << "written past the span";
  guarded.fill(0xEE);
  writeLe(std::span<std::uint8_t>(guarded).subspan(1, 8), 0, 0x44332211, 7);
  EXPECT_EQ(guarded[4], 0x44);
  EXPECT_EQ(guarded[5], 0xEE) << "more than 4 bytes of a 32-bit value";
  writeLe(std::span<std::uint8_t>(guarded).subspan(1, 8), 9, 0x1, 1);  // past the end: nothing
  EXPECT_EQ(guarded[9], 0xEE);
}

TEST(CanopenProtocol, StatuswordStates) {
  EXPECT_EQ(decodeStatusword(0x0000), DriveState::kNotReadyToSwitchOn);
  EXPECT_EQ(decodeStatusword(0x0250), DriveState::kSwitchOnDisabled);
  EXPECT_EQ(decodeStatusword(0x0231), DriveState::kReadyToSwitchOn);
  EXPECT_EQ(decodeStatusword(0x0233), DriveState::kSwitchedOn);
  EXPECT_EQ(decodeStatusword(0x1637), DriveState::kOperationEnabled);
  EXPECT_EQ(decodeStatusword(0x0217), DriveState::kQuickStopActive);
  EXPECT_EQ(decodeStatusword(0x021F), DriveState::kFaultReactionActive);
  EXPECT_EQ(decodeStatusword(0x2208), DriveState::kFault);
}

namespace {
// A scripted SDO server: answers each request with the next canned frame.
struct Fixture {
  std::int64_t t = 1'000'000'000;
  InProcessBus bus{"t0", [this] { return fusedet::Stamp{t}; }};
  std::unique_ptr<InProcessBus::Endpoint> client = bus.connect(), server = bus.connect();
  SdoClient sdo{*client, 5, 100ms};

  std::string request() {
    auto f = server->receive(0us);
    return f ? f->toString() : "none";
  }
  void answer(std::initializer_list<std::uint8_t> bytes) {
    (void)server->send(CanFrame::make(0x585, bytes));
    while (auto f = client->receive(0us)) sdo.onFrame(*f);
  }
};
}  // namespace

TEST(SdoClient, ExpeditedDownloadAndUpload) {
  Fixture x;
  std::vector<std::string> results;
  auto keep = [&](fusedet::Result<SdoClient::Bytes> r) {
    if (!r) return results.push_back(r.error().message());
    std::string s;
    for (auto b : *r) s += std::to_string(b) + ",";
    results.push_back("ok:" + s);
  };
  x.sdo.download(0x1017, 0, 100, 2, keep);
  x.sdo.upload(0x6064, 0, keep);  // queued behind the download
  EXPECT_EQ(x.request(), "605#2B17100064000000");
  EXPECT_EQ(x.request(), "none");
  x.answer({0x60, 0x17, 0x10, 0x00, 0, 0, 0, 0});
  EXPECT_EQ(x.request(), "605#4064600000000000");
  x.answer({0x43, 0x64, 0x60, 0x00, 0x78, 0x56, 0x34, 0x12});
  ASSERT_EQ(results.size(), 2u);
  EXPECT_EQ(results[0], "ok:");
  EXPECT_EQ(results[1], "ok:120,86,52,18,");
  EXPECT_TRUE(x.sdo.idle());
  EXPECT_EQ(x.sdo.counters().transfers, 2u);
}

TEST(SdoClient, SegmentedUploadWithToggles) {
  Fixture x;
  std::string name;
  x.sdo.upload(0x1008, 0, [&](fusedet::Result<SdoClient::Bytes> r) {
    ASSERT_TRUE(r) << r.error().message();
    name.assign(r->begin(), r->end());
  });
  EXPECT_EQ(x.request(), "605#4008100000000000");
  x.answer({0x41, 0x08, 0x10, 0x00, 10, 0, 0, 0});  // segmented, 10 bytes
  EXPECT_EQ(x.request(), "605#6000000000000000");
  x.answer({0x00, 't', 'i', 'l', 't', '-', 's', 'i'});  // toggle 0, 7 bytes, more
  EXPECT_EQ(x.request(), "605#7000000000000000");
  x.answer({0x19, 'm', '!', '!', 0, 0, 0, 0});  // toggle 1, n = 7 - 4 = 3 bytes, last
  EXPECT_EQ(name, "tilt-sim!!");
}

TEST(SdoClient, WrongToggleAborts) {
  Fixture x;
  std::string error;
  x.sdo.upload(0x1008, 0, [&](fusedet::Result<SdoClient::Bytes> r) { error = r ? "ok" : r.error().message(); });
  (void)x.request();
  x.answer({0x41, 0x08, 0x10, 0x00, 0, 0, 0, 0});
  (void)x.request();
  x.answer({0x10, 'x', 0, 0, 0, 0, 0, 0});  // toggle 1 where 0 was due
  EXPECT_EQ(x.request(), "605#8008100000000305");
  EXPECT_NE(error.find("0x05030000 toggle bit not alternated"), std::string::npos) << error;
}

TEST(SdoClient, ServerAbortIsDecoded) {
  Fixture x;
  fusedet::Error error;
  x.sdo.download(0x6041, 0, 1, 2, [&](fusedet::Result<SdoClient::Bytes> r) { error = r.error(); });
  (void)x.request();
  x.answer({0x80, 0x41, 0x60, 0x00, 0x02, 0x00, 0x01, 0x06});
  EXPECT_EQ(&error.code.category(), &sdoAbortCategory());
  EXPECT_EQ(error.code.value(), 0x06010002);
  EXPECT_EQ(error.message(), "SDO download 0x6041:00 node 5: SDO abort 0x06010002 attempt to write a read only object");
  EXPECT_EQ(x.sdo.counters().aborts, 1u);
}

TEST(SdoClient, TimeoutSendsAbortAndStartsTheNext) {
  Fixture x;
  std::vector<std::string> results;
  x.sdo.upload(0x6041, 0, [&](fusedet::Result<SdoClient::Bytes> r) { results.push_back(r ? "ok" : r.error().message()); });
  x.sdo.upload(0x6064, 0, [&](fusedet::Result<SdoClient::Bytes> r) { results.push_back(r ? "ok" : r.error().message()); });
  (void)x.request();
  x.t += 99'000'000;
  x.sdo.poll(fusedet::Stamp{x.t});
  EXPECT_TRUE(results.empty());
  x.t += 2'000'000;
  x.sdo.poll(fusedet::Stamp{x.t});
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0], "SDO upload 0x6041:00 node 5: no response: Connection timed out");
  EXPECT_EQ(x.request(), "605#8041600000000405");  // abort 0x05040000 to the server
  EXPECT_EQ(x.request(), "605#4064600000000000");  // the next transfer started
  x.answer({0x80, 0x41, 0x60, 0x00, 0, 0, 0, 0});    // a late abort of the old one is ignored
  EXPECT_EQ(results.size(), 1u);
  x.answer({0x4B, 0x64, 0x60, 0x00, 1, 0, 0, 0});    // wrong size for 0x6064 but well-formed
  EXPECT_EQ(results.size(), 2u);
  EXPECT_EQ(x.sdo.counters().timeouts, 1u);
}

// Found by fuzzing (issue 37, tests/fuzz/can_frames.cpp): two TPDO1 stamps whose difference does
// not fit int64 (a log may carry any stamp) overflowed the velocity's time step (undefined
// behaviour; in practice a wrapped, negative step and a velocity with the wrong sign). A step
// that does not fit is no recent sample: velocity 0; the rule still works on the next ones.
TEST(TiltTpdo, StampsWhoseDifferenceOverflowsGiveNoVelocity) {
  const TiltUnits units{1000, 2.0, 0};
  TiltTpdoDecoder decoder(5, units);
  auto tpdo = [](std::int64_t stamp, std::int32_t counts) {
    CanFrame f = CanFrame::make(0x185, {0, 0, 0, 0, 0x37, 0x06});
    writeLe(f.data, 0, static_cast<std::uint32_t>(counts), 4);
    f.stamp = fusedet::Stamp{stamp};
    return f;
  };
  ASSERT_TRUE(decoder.isTpdo(tpdo(0, 0)));
  ASSERT_TRUE(decoder.decode(tpdo(-8825501086245354107, 0)));
  const auto far = decoder.decode(tpdo(3388976314039305862, 1000));
  ASSERT_TRUE(far);
  EXPECT_EQ(far->sample.velocity, 0.0);
  EXPECT_EQ(far->statusword, 0x0637);
  const auto next = decoder.decode(tpdo(3388976314039305862 + 100'000'000, 1100));
  ASSERT_TRUE(next);
  EXPECT_NEAR(next->sample.velocity, (units.toRad(1100) - units.toRad(1000)) / 0.1, 1e-9);
}
