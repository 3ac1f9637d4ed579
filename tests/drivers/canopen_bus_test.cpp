// SPDX-License-Identifier: Apache-2.0
// CAN frames, error-frame texts, the in-process bus and the SocketCAN parts that need no kernel
// CAN support (frame conversion, clear errors for missing or non-CAN interfaces).

#include <gtest/gtest.h>
#include <linux/can.h>
#include <linux/can/error.h>

#include <thread>

#include "fusedet/drivers/canopen/can_frame.h"
#include "fusedet/drivers/canopen/inprocess_bus.h"
#include "fusedet/drivers/canopen/socketcan_bus.h"

using namespace fusedet::drivers::canopen;
using namespace std::chrono_literals;

TEST(CanFrame, CandumpStyleText) {
  EXPECT_EQ(CanFrame::make(0x123, {0xDE, 0xAD, 0xBE, 0xEF}).toString(), "123#DEADBEEF");
  EXPECT_EQ(CanFrame::make(0x080, {}).toString(), "080#");
  CanFrame ext = CanFrame::make(0x1ABCDEF, {0x01});
  EXPECT_TRUE(ext.extended);
  EXPECT_EQ(ext.toString(), "01ABCDEF#01");
  CanFrame rtr = CanFrame::make(0x705, {});
  rtr.rtr = true;
  rtr.len = 1;
  EXPECT_EQ(rtr.toString(), "705#R1");
  CanFrame e;
  e.error = true;
  e.id = err::kBusOff;
  e.len = 8;
  EXPECT_EQ(e.toString(), "20000040#0000000000000000");
}

TEST(CanFrame, ErrorFrameTexts) {
  CanFrame e;
  e.error = true;
  e.id = err::kController | err::kBusError;
  e.data[1] = 0x10 | 0x20;  // rx + tx error passive
  EXPECT_EQ(describeErrorFrame(e), "controller: rx error passive tx error passive, bus error");
  e.id = err::kBusOff;
  EXPECT_EQ(describeErrorFrame(e), "bus-off");
  e.id = err::kProtocol;
  e.data[2] = 0x04;
  EXPECT_EQ(describeErrorFrame(e), "protocol violation: bit stuffing");
  e.id = err::kNoAck;
  EXPECT_NE(describeErrorFrame(e).find("no acknowledgement"), std::string::npos);
  EXPECT_EQ(describeErrorFrame(CanFrame::make(0x100, {})), "");
}

TEST(InProcessBus, DeliversToOthersWithFiltersAndStamps) {
  std::int64_t t = 5'000'000'000;
  InProcessBus bus("test0", [&] { return fusedet::Stamp{t}; });
  auto a = bus.connect(), b = bus.connect(), c = bus.connect();
  ASSERT_TRUE(c->setFilters({{0x700, 0x780}}));  // heartbeats only
  std::vector<std::pair<CanFrame, FrameDirection>> seen;
  a->setFrameHook([&](const CanFrame& f, FrameDirection d) { seen.push_back({f, d}); });
  ASSERT_TRUE(a->send(CanFrame::make(0x605, {0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0})));
  t += 1000;
  ASSERT_TRUE(a->send(CanFrame::make(0x705, {0x05})));
  EXPECT_EQ(a->pending(), 0u);  // no loopback
  auto f1 = b->receive(0us);
  ASSERT_TRUE(f1);
  EXPECT_EQ(f1->toString(), "605#4000100000000000");
  EXPECT_EQ(f1->stamp.ns, 5'000'000'000);
  auto f2 = b->receive(0us);
  ASSERT_TRUE(f2);
  EXPECT_EQ(f2->stamp.ns, 5'000'001'000);
  auto g = c->receive(0us);
  ASSERT_TRUE(g);
  EXPECT_EQ(g->id, 0x705u);
  EXPECT_FALSE(c->receive(0us));
  auto timeout = b->receive(1ms);
  ASSERT_FALSE(timeout);
  EXPECT_EQ(timeout.error().code, std::errc::timed_out);
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_EQ(seen[0].second, FrameDirection::kTx);
  EXPECT_EQ(a->counters().framesTx, 2u);
  EXPECT_EQ(b->counters().framesRx, 2u);
  EXPECT_EQ(b->counters().timeouts, 1u);
}

TEST(InProcessBus, BusOffRefusesAndHearsNothing) {
  InProcessBus bus;
  auto a = bus.connect(), b = bus.connect();
  a->setBusOff(true);
  auto r = a->send(CanFrame::make(0x080, {}));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, std::errc::network_down);
  ASSERT_TRUE(b->send(CanFrame::make(0x080, {})));
  EXPECT_EQ(a->pending(), 0u);
  a->setBusOff(false);
  ASSERT_TRUE(a->send(CanFrame::make(0x080, {})));
  EXPECT_TRUE(b->receive(0us));
  EXPECT_EQ(a->counters().txFailures, 1u);
}

TEST(InProcessBus, BlockingReceiveWakesOnSend) {
  InProcessBus bus;
  auto a = bus.connect(), b = bus.connect();
  std::thread sender([&] {
    std::this_thread::sleep_for(20ms);
    (void)a->send(CanFrame::make(0x181, {1, 2}));
  });
  auto f = b->receive(30s);  // generous: the machine may be loaded
  sender.join();
  ASSERT_TRUE(f);
  EXPECT_EQ(f->toString(), "181#0102");
}

TEST(SocketCan, KernelFrameConversion) {
  can_frame k{};
  toKernelFrame(CanFrame::make(0x1ABCDEF, {1, 2, 3}), k);
  EXPECT_EQ(k.can_id, 0x1ABCDEFu | CAN_EFF_FLAG);
  EXPECT_EQ(k.can_dlc, 3);
  CanFrame back = fromKernelFrame(k);
  EXPECT_TRUE(back.sameContent(CanFrame::make(0x1ABCDEF, {1, 2, 3})));
  can_frame e{};
  e.can_id = CAN_ERR_FLAG | CAN_ERR_BUSOFF;
  e.can_dlc = 8;
  CanFrame ef = fromKernelFrame(e);
  EXPECT_TRUE(ef.error);
  EXPECT_FALSE(ef.extended);
  EXPECT_EQ(describeErrorFrame(ef), "bus-off");
  can_frame r{};
  r.can_id = 0x705 | CAN_RTR_FLAG;
  r.can_dlc = 1;
  CanFrame rf = fromKernelFrame(r);
  EXPECT_TRUE(rf.rtr);
  EXPECT_EQ(rf.id, 0x705u);
  EXPECT_EQ(rf.toString(), "705#R1");
}

TEST(SocketCan, MissingInterfaceIsAClearError) {
  SocketCanBus bus;
  auto r = bus.open("nosuchcan7");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, std::errc::no_such_device);
  EXPECT_NE(r.error().message().find("no CAN interface 'nosuchcan7'"), std::string::npos) << r.error().message();
  EXPECT_NE(r.error().message().find("type vcan"), std::string::npos);
  EXPECT_FALSE(bus.isOpen());
  auto s = bus.send(CanFrame::make(0x080, {}));
  EXPECT_FALSE(s);
  auto bad = bus.open("a-name-longer-than-ifnamsiz");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, std::errc::invalid_argument);
}

TEST(SocketCan, NonCanInterfaceIsRefused) {
  // "lo" exists everywhere but is not a CAN interface: either the kernel has no CAN support
  // (socket fails) or bind refuses it. Both must be clear errors, never a working bus.
  SocketCanBus bus;
  auto r = bus.open("lo");
  ASSERT_FALSE(r);
  const std::string m = r.error().message();
  EXPECT_TRUE(m.find("no CAN support") != std::string::npos || m.find("not a CAN interface") != std::string::npos ||
              m.find("lo") != std::string::npos)
      << m;
}
