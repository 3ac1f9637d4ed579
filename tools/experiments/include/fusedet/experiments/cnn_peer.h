// SPDX-License-Identifier: Apache-2.0
#pragma once
// The CNN alone as a peer (issue 30): a pretrained COCO detector (fusedet/fusion/neural/) run on
// the camera image of labelled frames, its detections (fusedet/fusion/neural/coco_detections.h)
// scored per class with boost/evaluate's KITTI rules - the frames and rules the cascades are
// scored on. Camera only, nothing trained.

#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "fusedet/boost/evaluation.h"
#include "fusedet/boost/outcomes_file.h"
#include "fusedet/boost/precision_recall.h"
#include "fusedet/core/label.h"
#include "fusedet/fusion/neural/coco_detections.h"
#include "fusedet/fusion/neural/network.h"

namespace fusedet::boosting {

struct PeerFrame {
  std::string id;                // "kitti/000042", as the data set names the frame
  std::filesystem::path image;   // the camera image (8-bit colour)
  Labels labels;
};

struct CnnPeerRun {
  fusion::NetworkIdentity network;
  std::map<std::string, std::vector<FrameOutcome>> frames;  // class -> per frame, in input order
  std::map<std::string, Counts> counts;                     // class -> counts at the operating point
  std::map<std::string, MatchConfig> rules;                 // class -> how its detections were matched
  double msPerFrame = 0;     // mean wall time of the network run and decoding (image reading excluded)
  double cpuMsPerFrame = 0;  // the same in CPU time of the process (wall time also counts waiting for a core)
};

// Runs `network` once per frame and matches its detections of every class in `classes` with
// `matchFor(class)`. `progress` (optional) sees each frame's index after it is scored. Throws
// naming the image that cannot be read.
CnnPeerRun runCnnPeer(fusion::Network& network, const std::vector<PeerFrame>& frames,
                      const std::vector<std::string>& classes,
                      const std::function<MatchConfig(const std::string&)>& matchFor,
                      const fusion::CocoDetectionRule& rule = {},
                      const std::function<void(std::size_t)>& progress = {});

// The run as outcome sets (outcomes_file.h), one per class: protocol "untrained" (the network never
// saw a frame: every frame is held out), configuration `config`, the frames' ids, so that
// `fusedet compare` pairs it frame by frame with a cascade run on the same frames and rules.
RunOutcomes cnnPeerOutcomes(const CnnPeerRun& run, const std::vector<PeerFrame>& frames, const std::string& config,
                            const std::string& command);

}  // namespace fusedet::boosting
