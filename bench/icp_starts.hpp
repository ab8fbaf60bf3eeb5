// `mlmap_bench icp-starts JOBS.json`: mlmap's pairwise ICP on given scan pairs from given
// starts (the stress benchmark's runs, see icp_starts.cpp and bench/icp_stress.py).
#pragma once

namespace mlmap::bench {

// argv[0] is "icp-starts"; prints JSON on stdout, returns the exit code.
int runIcpStarts(int argc, char** argv);

}  // namespace mlmap::bench
