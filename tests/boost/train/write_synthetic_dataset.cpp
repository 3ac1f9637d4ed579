// SPDX-License-Identifier: Apache-2.0
// write_synthetic_dataset DIR [N]: the trainer tests' synthetic scenes (synthetic_scenes.h) as a
// data set (core/dataset.h), so command-line tests can train on them.
#include <cstdio>
#include <cstdlib>
#include <exception>

#include "synthetic_scenes.h"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: write_synthetic_dataset DIR [N]\n");
    return 2;
  }
  try {
    const int n = argc > 2 ? std::atoi(argv[2]) : 8;
    for (const fusedet::DatasetItem& item : fusedet::synthetic::scenes(n, true))
      fusedet::writeDatasetItem(argv[1], item);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "write_synthetic_dataset: %s\n", e.what());
    return 1;
  }
  return 0;
}
