// `mlmap_bench icp SCENE_DIR`: mlmap's pairwise ICP on the consecutive scan pairs of a
// simulated scene, timed as the ICP peers time themselves (see icp_pairs.cpp).
#pragma once

namespace mlmap::bench {

// argv[0] is "icp"; prints JSON on stdout, returns the exit code.
int runIcpPairs(int argc, char** argv);

}  // namespace mlmap::bench
