// SPDX-License-Identifier: Apache-2.0
#pragma once
// The daemon's config keys as lists, so that parse, dump, the reload list and the documented YAML
// (config/fusedet.yaml) cannot drift apart: tests/daemon/config_keys_test.cpp checks them equal.

#include <string>
#include <vector>

#include "fusedet/daemon/config.h"

namespace fusedet::daemon {

// Every key parseConfig() reads, as paths ("socket.max_clients"; "detection.classes" stands for
// its per-class entries): the same set as dumpConfig() writes and config/fusedet.yaml documents.
std::vector<std::string> configKeys();

// THE reload list: the keys (or whole sections) a running fusedetd takes over on SIGHUP; the
// documented YAML's header names the same keys.
const std::vector<std::string>& reloadableConfigKeys();
// `running` with the reloadable keys of `next` (every other key stays as it runs).
Config withReloaded(const Config& running, const Config& next);

}  // namespace fusedet::daemon
