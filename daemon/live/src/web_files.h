// SPDX-License-Identifier: Apache-2.0
#pragma once
// Private: the page's files (daemon/web/), built into fusedetd (web_files.cpp is generated from
// them by live/embed_web.cmake at build time: the page works from any installation).

#include <string_view>

namespace fusedet::daemon::live {

struct WebFile {
  std::string_view contentType;
  std::string_view body;
};

// The file an HTTP target names ("/" = index.html; a query string is ignored); nullptr if none.
const WebFile* webFile(std::string_view target);

}  // namespace fusedet::daemon::live
