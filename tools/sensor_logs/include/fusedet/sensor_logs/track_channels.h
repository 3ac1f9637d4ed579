// SPDX-License-Identifier: Apache-2.0
#pragma once
// A stack's tracks as sensor-log messages (docs/log-format.md, written by `fusedet log derive`):
//   /tracks        fusedet.Tracks        the socket's `tracks` line (fusedet/daemon/protocol.h tracksToJson) plus
//                                        the log timestamp (the stack's camera frame)
//   /tracks/scene  foxglove.SceneUpdate  one entity per live track in frame laser_base (the robot
//                                        frame the tracker works in): id "track-N", a sphere of
//                                        2 sigma, an arrow along the velocity, a text, metadata
// In the scene a confirmed, detected track is drawn in its class colour, a coasting one (not
// detected in this stack) in that colour at 30 % opacity, a tentative one grey; every message
// replaces the previous one's entities and each entity expires after `lifetimeS`.

#include <cstdint>
#include <vector>

#include "fusedet/daemon/pipeline.h"
#include "fusedet/drivers/log/channels.h"

namespace fusedet::sensor_logs {

// The JSON bytes of one /tracks message.
std::vector<std::uint8_t> tracksMessage(const daemon::StackResult& result);

// The /tracks/scene message. lifetimeS: the tracker's max_coast_s - a track whose last detection
// is older has died, so an entity never outlives its track when no further stack comes.
drivers::logs::SceneUpdateMessage trackScene(const daemon::StackResult& result, double lifetimeS);

}  // namespace fusedet::sensor_logs
