// Internal to eRMSM, beyond the paper: a patch is one flat surface, not a compromise
// across a shallow crease. Where faces meet at a few degrees to ten or twenty (plane_seg's
// cinder blocks, tilted 13° in turn; a floor rising to a platform), ε's floor (5 cm) and
// κ (25°) let one candidate take several faces, and the blocks' direction windows (2 cells
// either side) straddle the creases of faces eight cells across, so no rule of the search
// tells the faces apart. The points do: each block keeps their moments, and the plane
// through a block's points and its patch neighbours' (a window one cell either side)
// turns with its face.
#pragma once

#include <vector>

#include "patch_set.hpp"

namespace mlmap {

struct CreaseConfig {
  double noise = 0.0;        // m, σ (measured): patches whose points' RMS stays within 1.5 σ are left alone
  double epsilon = 0.0;      // m, ε: two faces' planes closer than this at their centroids are one
  double kappa_rad = 0.0;    // κ: faces grow while their windows turn less than κ / 3
  int min_blocks = 6;        // a face needs at least this many blocks ...
  double min_area = 0.15;    // m² ... and this much surface
};

// Splits each patch that is a compromise across creases. Only patches rougher than 1.5 σ
// (their points' RMS about their plane) are looked at. Faces grow from the flattest
// windows over neighbours whose windows turn less than κ / 3; faces too small (under
// the patch minimum in blocks, half the minimum area: a face's rim windows straddle its
// creases), not spread both ways, or flatter than σ / 3 (one scan line's sweep plane)
// are dropped; every block goes to the face its points lie nearest, or to none where they
// lie more than 3 σ (RMS) off every face; faces that then touch and turn less than κ / 3
// are one (a warped or layered surface). The split stands when two touching faces turn
// more than κ / 3 (a crease), the faces' squared residuals are at most a quarter of the
// patch's over the same blocks (their RMS half), and at most 15 % of the patch's points lie
// on no face. Blocks on no face, and connected pieces of a face too small for half the
// minimum area, go back to no patch. A rough wall patch that no crease splits is split
// where it is two parallel faces a step apart (step_faces.hpp). The first face keeps the
// patch's id, the others are appended; their outlines are left pending. Returns, per
// plane, the index of the patch it was split from (-1 for none); empty where none was.
std::vector<int> splitCreases(const BlockGrid& grid, PatchSet& set, const CreaseConfig& config);

}  // namespace mlmap
