// SPDX-License-Identifier: Apache-2.0
#include "fusedet/tracking/tracker.h"

#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "fusedet/tracking/assignment.h"

namespace fusedet::tracking {

void validate(const TrackerParams& p) {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("tracker: ") + what);
  };
  require(p.noise.accelerationSigma > 0 && std::isfinite(p.noise.accelerationSigma), "acceleration sigma must be > 0");
  require(p.noise.measurementSigma > 0 && std::isfinite(p.noise.measurementSigma), "measurement sigma must be > 0");
  require(p.noise.initialVelocitySigma > 0 && std::isfinite(p.noise.initialVelocitySigma), "initial velocity sigma must be > 0");
  require(p.gate > 0 && std::isfinite(p.gate), "gate must be > 0");
  require(p.birthHits >= 1, "birth hits must be >= 1");
  require(p.birthWindow >= p.birthHits, "birth window must be >= birth hits");
  require(p.maxMisses >= 0, "max misses must be >= 0");
  require(p.maxCoastS > 0 && std::isfinite(p.maxCoastS), "max coast time must be > 0");
}

Tracker::Tracker(TrackerParams params) : params_(params) { validate(params_); }

void Tracker::reset() {
  tracks_.clear();
  last_.reset();
}

void Tracker::associate(const std::vector<Observation>& obs, std::vector<int>& trackOfObservation) const {
  // Per class: tracks x observations of that class with a position.
  std::map<std::string, std::pair<std::vector<int>, std::vector<int>>> byClass;
  for (std::size_t t = 0; t < tracks_.size(); ++t) byClass[tracks_[t].state.className].first.push_back(static_cast<int>(t));
  for (std::size_t o = 0; o < obs.size(); ++o)
    if (obs[o].position) byClass[obs[o].className].second.push_back(static_cast<int>(o));
  constexpr double kForbidden = std::numeric_limits<double>::infinity();
  for (const auto& [name, members] : byClass) {
    const auto& [ts, os] = members;
    if (ts.empty() || os.empty()) continue;
    Eigen::MatrixXd cost(static_cast<Eigen::Index>(ts.size()), static_cast<Eigen::Index>(os.size()));
    for (std::size_t i = 0; i < ts.size(); ++i)
      for (std::size_t j = 0; j < os.size(); ++j) {
        const double d2 = tracks_[static_cast<std::size_t>(ts[i])].filter.mahalanobis2(*obs[static_cast<std::size_t>(os[j])].position);
        cost(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = d2 <= params_.gate ? d2 : kForbidden;
      }
    const std::vector<int> match = assign(cost, params_.gate / 2);
    for (std::size_t i = 0; i < ts.size(); ++i)
      if (match[i] >= 0) trackOfObservation[static_cast<std::size_t>(os[static_cast<std::size_t>(match[i])])] = ts[i];
  }
}

void Tracker::publish(Track& t) {
  t.state.position = t.filter.position();
  t.state.velocity = t.filter.velocity();
  t.state.positionSigma = std::sqrt(t.filter.covariance().topLeftCorner<3, 3>().trace() / 3);
}

TrackedStack Tracker::update(Stamp stamp, const std::vector<Observation>& observations) {
  if (last_ && stamp < *last_) reset();
  const double dt = last_ ? static_cast<double>(stamp - *last_) * 1e-9 : 0.0;
  last_ = stamp;
  // A track whose last detection is older than the coast time ends before it could take one.
  std::erase_if(tracks_, [&](const Track& t) {
    return static_cast<double>(stamp - t.state.lastDetected) * 1e-9 > params_.maxCoastS;
  });
  for (Track& t : tracks_) t.filter.predict(dt);

  std::vector<int> trackOfObservation(observations.size(), -1);  // index into tracks_
  associate(observations, trackOfObservation);

  std::vector<char> detected(tracks_.size(), 0);
  for (std::size_t o = 0; o < observations.size(); ++o) {
    const int t = trackOfObservation[o];
    if (t < 0) continue;
    Track& track = tracks_[static_cast<std::size_t>(t)];
    track.filter.update(*observations[o].position);
    track.state.box = observations[o].box;
    track.state.lastDetected = stamp;
    ++track.state.hits;
    track.state.misses = 0;
    detected[static_cast<std::size_t>(t)] = 1;
  }
  for (std::size_t t = 0; t < tracks_.size(); ++t) {
    TrackState& s = tracks_[t].state;
    ++s.stacks;
    s.coasting = !detected[t];
    if (s.coasting) ++s.misses;
    s.ageS = static_cast<double>(stamp - s.born) * 1e-9;
    if (!s.confirmed && s.stacks <= params_.birthWindow && s.hits >= params_.birthHits) s.confirmed = true;
  }

  // Deaths. Observations keep pointing at their track: remap indices after erasing.
  std::vector<int> newIndex(tracks_.size(), -1);
  std::vector<Track> alive;
  alive.reserve(tracks_.size() + observations.size());
  for (std::size_t t = 0; t < tracks_.size(); ++t) {
    const TrackState& s = tracks_[t].state;
    const bool dies = s.confirmed ? s.misses > params_.maxMisses
                                  : s.hits + (params_.birthWindow - s.stacks) < params_.birthHits;
    if (dies) continue;
    newIndex[t] = static_cast<int>(alive.size());
    alive.push_back(std::move(tracks_[t]));
  }
  tracks_ = std::move(alive);
  for (int& t : trackOfObservation)
    if (t >= 0) t = newIndex[static_cast<std::size_t>(t)];

  // Births: every unmatched observation with a position (ids ascending, so tracks_ stays sorted).
  for (std::size_t o = 0; o < observations.size(); ++o) {
    if (trackOfObservation[o] >= 0 || !observations[o].position) continue;
    Track t{TrackState{}, ConstantVelocityKalman(*observations[o].position, params_.noise)};
    t.state.id = nextId_++;
    t.state.className = observations[o].className;
    t.state.born = t.state.lastDetected = stamp;
    t.state.stacks = t.state.hits = 1;
    t.state.box = observations[o].box;
    t.state.confirmed = params_.birthHits <= 1;
    trackOfObservation[o] = static_cast<int>(tracks_.size());
    tracks_.push_back(std::move(t));
  }

  TrackedStack out;
  out.trackOf = std::move(trackOfObservation);
  out.tracks.reserve(tracks_.size());
  for (Track& t : tracks_) {
    publish(t);
    out.tracks.push_back(t.state);
  }
  return out;
}

}  // namespace fusedet::tracking
