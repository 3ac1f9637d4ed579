// SPDX-License-Identifier: Apache-2.0
#pragma once
// describeFrame: one line of CANopen meaning for a frame (what `fusedet tilt monitor` prints),
// e.g. "SDO request node 5: upload 0x6041:00" or "EMCY node 5: EMCY 0x8611 following error (...)".

#include <string>

#include "fusedet/drivers/canopen/can_frame.h"

namespace fusedet::drivers::canopen {

std::string describeFrame(const CanFrame& f);

}  // namespace fusedet::drivers::canopen
