// SPDX-License-Identifier: Apache-2.0
// The candump -l log format: vectors written by hand from can-utils' format, round trips,
// bad lines with clear errors, and a fuzz run of the reader.

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <limits>
#include <random>

#include "fusedet/drivers/canopen/candump_log.h"

using namespace fusedet::drivers::canopen;

TEST(Candump, FormatsLikeCandump) {
  CanFrame f = CanFrame::make(0x605, {0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0});
  f.stamp = fusedet::Stamp{1234'567891'000};
  EXPECT_EQ(formatCandumpLine(f, "can0"), "(0000001234.567891) can0 605#4041600000000000\n");
  CanFrame sync = CanFrame::make(0x080, {});
  sync.stamp = fusedet::Stamp{999};  // below a microsecond
  EXPECT_EQ(formatCandumpLine(sync, "vcan0"), "(0000000000.000000) vcan0 080#\n");
}

TEST(Candump, ParsesEveryKind) {
  auto a = parseCandumpLine("(1700000000.123456) can0 123#DEADBEEF\n");
  ASSERT_TRUE(a) << a.error().message();
  EXPECT_EQ(a->interface, "can0");
  EXPECT_EQ(a->frame.stamp.ns, 1700000000'123456000);
  EXPECT_EQ(a->frame.toString(), "123#DEADBEEF");
  auto ext = parseCandumpLine("(1.000001) vcan1 1ABCDEF0#01.02");
  ASSERT_TRUE(ext);
  EXPECT_TRUE(ext->frame.extended);
  EXPECT_EQ(ext->frame.id, 0x1ABCDEF0u);
  EXPECT_EQ(ext->frame.len, 2);
  auto rtr = parseCandumpLine("(2.5) can0 705#R1");
  ASSERT_TRUE(rtr);
  EXPECT_TRUE(rtr->frame.rtr);
  EXPECT_EQ(rtr->frame.len, 1);
  EXPECT_EQ(rtr->frame.stamp.ns, 2'500'000'000);  // a decimal fraction, whatever its length
  auto err = parseCandumpLine("(3.000000) can0 20000040#0000000000000000");
  ASSERT_TRUE(err);
  EXPECT_TRUE(err->frame.error);
  EXPECT_EQ(err->frame.id, 0x40u);
  auto empty = parseCandumpLine("(3.000000) can0 080#");
  ASSERT_TRUE(empty);
  EXPECT_EQ(empty->frame.len, 0);
}

TEST(Candump, BadLinesSayWhatIsWrong) {
  auto why = [](const char* line) {
    auto r = parseCandumpLine(line);
    return r ? std::string("accepted") : r.error().context;
  };
  EXPECT_EQ(why("123#00"), "expected '(' and a time stamp");
  EXPECT_EQ(why("(1.0 can0 123#00"), "time stamp without ')'");
  EXPECT_EQ(why("(x.0) can0 123#00"), "time stamp has a non-digit");
  EXPECT_EQ(why("(1.0) can0 12#00"), "CAN id must have 3 or 8 hex digits");
  EXPECT_EQ(why("(1.0) can0 800#00"), "11-bit CAN id out of range");
  EXPECT_EQ(why("(1.0) can0 123#0"), "odd number of hex digits in the data");
  EXPECT_EQ(why("(1.0) can0 123#000102030405060708"), "more than 8 data bytes");
  EXPECT_EQ(why("(1.0) can0 123##100"), "CAN FD frame (##) not supported");
  EXPECT_EQ(why("(1.0) can0 123#GG"), "data is not hex");
  EXPECT_EQ(why("(1.0) can0 123#R9"), "remote request length must be one digit 0..8");
  EXPECT_EQ(why("(1.0) can0"), "expected an interface name and a space");
}

// UBSan found it (issue 37): a seconds value whose nanoseconds exceed int64 overflowed; the
// reader accepted the line with a wrapped, meaningless stamp. The largest stamp still reads.
TEST(Candump, StampsBeyondSixtyFourBitNanosecondsAreRefused) {
  auto why = [](const char* line) {
    auto r = parseCandumpLine(line);
    return r ? std::string("accepted") : r.error().context;
  };
  const std::string tooLate = "time stamp beyond 9223372036.854775807 s (64-bit nanoseconds)";
  EXPECT_EQ(why("(17000000800.000000) can0 123#00"), tooLate);  // the fuzzed line that overflowed
  EXPECT_EQ(why("(999999999999.999999999) can0 123#00"), tooLate);
  EXPECT_EQ(why("(9223372036.854775808) can0 123#00"), tooLate);
  auto last = parseCandumpLine("(9223372036.854775807) can0 123#00");
  ASSERT_TRUE(last) << last.error().message();
  EXPECT_EQ(last->frame.stamp.ns, std::numeric_limits<std::int64_t>::max());
}

TEST(Candump, WriteReadRoundTrip) {
  const std::string path = ::testing::TempDir() + "/roundtrip.log";
  std::vector<CanFrame> frames;
  std::mt19937 rng(7);
  for (int i = 0; i < 500; ++i) {
    CanFrame f;
    f.extended = rng() % 4 == 0;
    f.id = f.extended ? rng() & 0x1FFFFFFF : rng() & 0x7FF;
    f.rtr = rng() % 10 == 0;
    f.len = static_cast<std::uint8_t>(rng() % 9);
    for (auto& b : f.data) b = f.rtr ? 0 : static_cast<std::uint8_t>(rng());
    for (std::size_t j = f.len; j < 8; ++j) f.data[j] = 0;
    f.stamp = fusedet::Stamp{1000'000'000'000 + i * 1'234'000LL};
    frames.push_back(f);
  }
  {
    CandumpWriter w;
    ASSERT_TRUE(w.open(path, "can0"));
    for (const auto& f : frames) w.write(f);
    ASSERT_TRUE(w.close());
  }
  auto back = readCandumpLog(path);
  ASSERT_TRUE(back) << back.error().message();
  ASSERT_EQ(back->size(), frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_TRUE((*back)[i].frame.sameContent(frames[i])) << i << " " << frames[i].toString();
    EXPECT_EQ((*back)[i].frame.stamp.ns, frames[i].stamp.ns);
  }
}

TEST(Candump, ReaderNamesFileAndLine) {
  const std::string path = ::testing::TempDir() + "/bad.log";
  {
    std::ofstream o(path);
    o << "(1.000000) can0 123#00\n\n(1.000001) can0 12Z#00\n";
  }
  auto r = readCandumpLog(path);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message().find("bad.log:3: CAN id is not hex"), std::string::npos) << r.error().message();
  auto missing = readCandumpLog(::testing::TempDir() + "/no-such.log");
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message().find("cannot open"), std::string::npos);
}

TEST(Candump, FuzzedLinesNeverCrashAndAcceptedOnesRoundTrip) {
  std::mt19937 rng(11);
  const std::string seed = "(1700000000.123456) can0 12345678#DEADBEEF01020304";
  const std::string alphabet = "0123456789abcdefABCDEFRr#.() \n\txyz";
  int accepted = 0;
  for (int i = 0; i < 200000; ++i) {
    std::string s = seed;
    const int edits = 1 + static_cast<int>(rng() % 6);
    for (int e = 0; e < edits; ++e) {
      const std::size_t at = rng() % (s.size() + 1);
      switch (rng() % 4) {
        case 0: if (at < s.size()) s.erase(at, 1); break;
        case 1: s.insert(at, 1, alphabet[rng() % alphabet.size()]); break;
        case 2: if (at < s.size()) s[at] = static_cast<char>(rng()); break;
        default: s = s.substr(0, at); break;
      }
    }
    auto r = parseCandumpLine(s);
    if (!r) {
      EXPECT_FALSE(r.error().message().empty());
      continue;
    }
    ++accepted;
    // Whatever is accepted is a valid frame that formats and parses back the same.
    EXPECT_LE(r->frame.len, 8);
    auto again = parseCandumpLine(formatCandumpLine(r->frame, r->interface));
    ASSERT_TRUE(again) << s;
    EXPECT_TRUE(again->frame.sameContent(r->frame)) << s;
  }
  EXPECT_GT(accepted, 100);  // the mutations keep some lines valid, so both paths are exercised
}
