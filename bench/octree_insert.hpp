// mlmap_bench octree: the OcTree layer alone on scan files, in the JSON style of the
// peers' octomap_insert and bonxai_insert (../shared/peers), for bench/octree_bench.py.
#pragma once

namespace mlmap::bench {

int runOctreeInsert(int argc, char** argv);

}  // namespace mlmap::bench
