// SPDX-License-Identifier: Apache-2.0
// The track manager: M-of-N birth, death after the miss budget or the coast time, ids never
// repeated, association per class, gaps, dropped stacks and stamps shifted as a replay shifts them.
#include <gtest/gtest.h>

#include <set>

#include "fusedet/tracking/tracker.h"

using namespace fusedet;
using namespace fusedet::tracking;

namespace {
constexpr std::int64_t kStep = 100'000'000;  // 0.1 s

Observation at(const std::string& cls, double x, double y) {
  Observation o;
  o.className = cls;
  o.position = Eigen::Vector3d(x, y, 0);
  o.box = Box{x, y, 10, 10};
  return o;
}

TrackerParams params(int m, int n, int maxMisses) {
  TrackerParams p;
  p.birthHits = m;
  p.birthWindow = n;
  p.maxMisses = maxMisses;
  return p;
}

const TrackState& trackOf(const TrackedStack& s, std::size_t observation) {
  return s.tracks.at(static_cast<std::size_t>(s.trackOf.at(observation)));
}
}  // namespace

TEST(Tracker, BirthNeedsMOfN) {
  Tracker t(params(2, 3, 2));
  // Stack 0: born tentative. Stack 1: missed. Stack 2: detected -> 2 of 3: confirmed.
  TrackedStack s = t.update(Stamp{0}, {at("car", 10, 0)});
  ASSERT_EQ(s.tracks.size(), 1u);
  EXPECT_FALSE(s.tracks[0].confirmed);
  EXPECT_EQ(s.tracks[0].id, 1u);
  s = t.update(Stamp{kStep}, {});
  ASSERT_EQ(s.tracks.size(), 1u);
  EXPECT_TRUE(s.tracks[0].coasting);
  s = t.update(Stamp{2 * kStep}, {at("car", 10, 0)});
  ASSERT_EQ(s.tracks.size(), 1u);
  EXPECT_TRUE(s.tracks[0].confirmed);
  EXPECT_EQ(s.tracks[0].hits, 2);
  EXPECT_EQ(trackOf(s, 0).id, 1u);
}

TEST(Tracker, TentativeTrackDiesWhenItCannotReachM) {
  Tracker t(params(3, 4, 2));
  t.update(Stamp{0}, {at("car", 10, 0)});
  TrackedStack s = t.update(Stamp{kStep}, {});  // 1 hit, 2 stacks left: 3 still reachable
  EXPECT_EQ(s.tracks.size(), 1u);
  s = t.update(Stamp{2 * kStep}, {});  // 1 hit, 1 stack left: 2 < 3
  EXPECT_TRUE(s.tracks.empty());
}

TEST(Tracker, OneOfOneConfirmsAtOnce) {
  Tracker t(params(1, 1, 0));
  const TrackedStack s = t.update(Stamp{0}, {at("person", 3, 1)});
  ASSERT_EQ(s.tracks.size(), 1u);
  EXPECT_TRUE(s.tracks[0].confirmed);
}

TEST(Tracker, ConfirmedTrackDiesAfterTheMissBudget) {
  Tracker t(params(2, 2, 2));
  t.update(Stamp{0}, {at("car", 10, 0)});
  TrackedStack s = t.update(Stamp{kStep}, {at("car", 10, 0)});
  ASSERT_TRUE(s.tracks.at(0).confirmed);
  s = t.update(Stamp{2 * kStep}, {});
  ASSERT_EQ(s.tracks.size(), 1u);
  EXPECT_EQ(s.tracks[0].misses, 1);
  s = t.update(Stamp{3 * kStep}, {});
  ASSERT_EQ(s.tracks.size(), 1u);  // 2 misses: still within the budget
  EXPECT_TRUE(s.tracks[0].coasting);
  s = t.update(Stamp{4 * kStep}, {});
  EXPECT_TRUE(s.tracks.empty());
}

TEST(Tracker, IdsAreNeverRepeated) {
  Tracker t(params(1, 1, 0));
  std::set<std::uint64_t> seen;
  std::int64_t stamp = 0;
  for (int round = 0; round < 20; ++round) {
    // Objects appear for one stack and vanish; every new one gets a new id.
    const TrackedStack s = t.update(Stamp{stamp += kStep}, {at("car", round * 100.0, 0), at("bike", 0, round * 100.0)});
    for (const TrackState& tr : s.tracks) {
      if (tr.hits == 1 && tr.stacks == 1) {
        EXPECT_TRUE(seen.insert(tr.id).second) << tr.id;
      }
    }
    t.update(Stamp{stamp += kStep}, {});
    if (round == 10) t.reset();  // ids keep counting across a reset
  }
  EXPECT_EQ(seen.size(), 40u);
}

TEST(Tracker, AssociatesPerClassAndFollowsAMovingObject) {
  Tracker t(params(2, 3, 1));
  // A car moving at 5 m/s along x and a person standing where the car passes at stack 4.
  std::uint64_t carId = 0, personId = 0;
  for (int k = 0; k < 10; ++k) {
    const double carX = 0.5 * k;
    const TrackedStack s = t.update(Stamp{k * kStep}, {at("car", carX, 0), at("person", 2.0, 0)});
    if (k == 0) {
      carId = trackOf(s, 0).id;
      personId = trackOf(s, 1).id;
    }
    EXPECT_EQ(trackOf(s, 0).id, carId) << "stack " << k;
    EXPECT_EQ(trackOf(s, 1).id, personId) << "stack " << k;
  }
  Tracker again(params(2, 3, 1));
  TrackedStack s;
  for (int k = 0; k < 30; ++k) s = again.update(Stamp{k * kStep}, {at("car", 0.5 * k, 0)});
  EXPECT_NEAR(trackOf(s, 0).velocity.x(), 5.0, 0.05);
  EXPECT_NEAR(trackOf(s, 0).velocity.y(), 0.0, 0.05);
  EXPECT_NEAR(trackOf(s, 0).ageS, 2.9, 1e-9);
}

TEST(Tracker, CrossingObjectsKeepTheirIdsThroughTheOptimalAssignment) {
  // Two cars on parallel lanes 2 m apart, one overtaking: nearest-neighbour by position alone
  // would swap them where the first stack's prediction is ambiguous; the filter's velocities keep them.
  Tracker t(params(1, 1, 1));
  std::uint64_t a = 0, b = 0;
  for (int k = 0; k < 20; ++k) {
    const TrackedStack s = t.update(Stamp{k * kStep}, {at("car", 1.0 * k, 0), at("car", 5 + 0.2 * k, 2)});
    if (k == 0) {
      a = trackOf(s, 0).id;
      b = trackOf(s, 1).id;
    }
    EXPECT_EQ(trackOf(s, 0).id, a) << k;
    EXPECT_EQ(trackOf(s, 1).id, b) << k;
  }
}

TEST(Tracker, DroppedStacksKeepTheTrackAndItsVelocity) {
  // 2 m/s; stacks 5..9 never arrive (dropped): the prediction over 0.6 s meets the next detection.
  Tracker t(params(2, 3, 1));
  TrackedStack s;
  std::uint64_t id = 0;
  for (int k = 0; k < 20; ++k) {
    if (k >= 5 && k < 10) continue;
    s = t.update(Stamp{k * kStep}, {at("bike", 0.2 * k, 1)});
    if (k == 0) id = trackOf(s, 0).id;
    EXPECT_EQ(trackOf(s, 0).id, id) << k;
  }
  EXPECT_NEAR(trackOf(s, 0).velocity.x(), 2.0, 0.05);
  EXPECT_EQ(trackOf(s, 0).misses, 0);
}

TEST(Tracker, GapLongerThanTheCoastTimeEndsTracks) {
  TrackerParams p = params(1, 1, 5);
  p.maxCoastS = 1.0;
  Tracker t(p);
  t.update(Stamp{0}, {at("car", 0, 0)});
  // The next stack comes 1.5 s later without the car: the track is older than 1 s -> dies.
  TrackedStack s = t.update(Stamp{15 * kStep}, {});
  EXPECT_TRUE(s.tracks.empty());
  // A new car far away after the gap gets a new id.
  s = t.update(Stamp{16 * kStep}, {at("car", 50, 0)});
  EXPECT_EQ(trackOf(s, 0).id, 2u);
  // After a gap longer than the coast time even a detection at the track's place starts a new
  // track: the old one ended before the association.
  s = t.update(Stamp{40 * kStep}, {at("car", 50, 0)});
  EXPECT_EQ(trackOf(s, 0).id, 3u);
  EXPECT_EQ(s.tracks.size(), 1u);
}

TEST(Tracker, SameTracksWhateverTheStampOffsetAsAReplayRestamps) {
  auto run = [](std::int64_t offset) {
    Tracker t;
    std::vector<TrackedStack> out;
    for (int k = 0; k < 15; ++k)
      out.push_back(t.update(Stamp{offset + k * 3 * kStep}, {at("car", 0.8 * k, 0.1 * k), at("person", 5, -0.2 * k)}));
    return out;
  };
  const auto a = run(0), b = run(987'654'321'000);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    ASSERT_EQ(a[k].tracks.size(), b[k].tracks.size());
    EXPECT_EQ(a[k].trackOf, b[k].trackOf);
    for (std::size_t i = 0; i < a[k].tracks.size(); ++i) {
      EXPECT_EQ(a[k].tracks[i].id, b[k].tracks[i].id);
      EXPECT_EQ(a[k].tracks[i].confirmed, b[k].tracks[i].confirmed);
      EXPECT_NEAR((a[k].tracks[i].velocity - b[k].tracks[i].velocity).norm(), 0, 1e-9);
    }
  }
}

TEST(Tracker, StampGoingBackEndsEveryTrackButNotTheIds) {
  Tracker t(params(1, 1, 3));
  t.update(Stamp{10 * kStep}, {at("car", 0, 0)});
  TrackedStack s = t.update(Stamp{kStep}, {at("car", 0, 0)});  // the log started again
  ASSERT_EQ(s.tracks.size(), 1u);
  EXPECT_EQ(s.tracks[0].id, 2u);
  EXPECT_EQ(s.tracks[0].stacks, 1);
}

TEST(Tracker, DetectionsWithoutPositionAreNotTracked) {
  Tracker t;
  Observation noPosition;
  noPosition.className = "car";
  const TrackedStack s = t.update(Stamp{0}, {noPosition, at("car", 1, 1)});
  EXPECT_EQ(s.trackOf[0], -1);
  EXPECT_GE(s.trackOf[1], 0);
  EXPECT_EQ(s.tracks.size(), 1u);
}

TEST(Tracker, RejectsBadParameters) {
  EXPECT_THROW(Tracker(params(3, 2, 1)), std::invalid_argument);
  EXPECT_THROW(Tracker(params(0, 2, 1)), std::invalid_argument);
  EXPECT_THROW(Tracker(params(1, 2, -1)), std::invalid_argument);
  TrackerParams p;
  p.gate = 0;
  EXPECT_THROW(Tracker{p}, std::invalid_argument);
}
