// The passes of Algorithm 1's detector after the search (detector.hpp), beyond the paper:
// the patches grown into their surfaces' sparse parts, the sparse surfaces no patch
// reached, and every patch described on its own points.
#include <algorithm>

#include "detector.hpp"
#include "mlmap/planes/classify.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace mlmap {

// Each patch into its own slot: the same planes at any thread count.
void Detector::describePatches() {
#ifdef _OPENMP
  const int requested = patchPassThreads(grid_, config_.threads);
  const int threads = requested > 0 ? requested : omp_get_max_threads();
#endif
  const double kappa = radians(config_.kappa_deg);
  const auto count = static_cast<std::int64_t>(patches_.planes.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) if (count > 1)
  for (std::int64_t n = 0; n < count; ++n) {
    const auto k = static_cast<std::size_t>(n);
    Patch patch;
    patch.blocks = std::move(patches_.blocks[k]);
    patch.surface = undescribed_[k].surface;
    patch.raster_step = patches_.outline_frames[k].step;
    Plane described = describePatch(grid_, patch, undescribed_[k].reference, kappa, fit_noise_);
    Plane& plane = patches_.planes[k];
    described.id = plane.id;
    described.source = plane.source;
    described.candidates = plane.candidates;
    plane = std::move(described);
    patches_.blocks[k] = std::move(patch.blocks);
  }
}

// After the search: the patches take the blocks of their surfaces' sparse parts
// (sparse_growth.hpp), in the order they were found.
void Detector::growIntoSparse(std::size_t first) {
  if (config_.sparse_gap <= 0.0) return;
  // Planes within the classes' tolerance of level or plumb (floors, ceilings, tables, walls).
  const SparseGrowth growth{config_.sparse_gap, radians(config_.kappa_deg), radians(ClassifyConfig{}.horizontal_deg),
                             config_.ladder_gap};
  std::vector<CandidatePlane> references;
  std::vector<double> surfaces;
  for (const Undescribed& patch : undescribed_) {
    references.push_back(patch.reference);
    surfaces.push_back(patch.surface);
  }
  growPatches(grid_, directions_, scorer_, references, surfaces, patches_, growth, first);
  for (std::size_t k = 0; k < undescribed_.size(); ++k) undescribed_[k].surface = surfaces[k];
}

// After the sparse growth: the sparse surfaces no patch reached (sparse_search.hpp),
// each a patch of its own; the coplanar merge joins those that touch a patch. Their
// blocks hold a point or two each, as noisy as the scanner's range, so their tolerance is
// the build's σ_m (max_epsilon) where that is wider than ε: ε follows the map's σ, read
// from dense blocks (their points averaged) on floors seen at grazing angles, which lie
// far thinner than a wall seen head on. Simulated halls with 3 cm of range noise: σ read
// 1.4 cm, ε 5 cm, and the far end wall 12-14 m off (2,300 single-point blocks whose
// neighbourhoods lie 2.1-3.9 cm thick, median 2.7) was on no patch. With it
// (bench/planes_sweep.py at 5 cm cells, halls 1-2 and offices 1-4, and the fresh halls
// 5-8) 9 variants gained a surface, the far wall in those looked at, and none lost one.
void Detector::findSparse() {
  if (config_.sparse_gap <= 0.0) return;
  const SparseSearch search{.max_gap = config_.sparse_gap,
                            .epsilon = std::max(config_.epsilon, config_.max_epsilon),
                            .max_tilt_rad = radians(ClassifyConfig{}.horizontal_deg),
                            .ladder_gap = config_.ladder_gap,
                            .min_blocks = static_cast<std::size_t>(std::max(config_.min_patch_blocks, 1)),
                            .min_area = config_.min_patch_area};
  for (SparseSurface& found : findSparseSurfaces(grid_, directions_, patches_.labels, search)) {
    ++accepted_;
    Plane plane;
    undescribed_.push_back(Undescribed{found.plane, found.patch.surface});
    plane.id = static_cast<std::int32_t>(patches_.planes.size() + 1);
    plane.source = accepted_;
    plane.candidates = 0;
    for (const std::uint32_t id : found.patch.blocks) patches_.labels[id] = plane.id;
    patches_.outline_runs.emplace_back();
    patches_.outline_frames.push_back(OutlineFrame{found.plane.normal.cast<double>(), found.plane.point.cast<double>(),
                                                   true, found.patch.raster_step});
    patches_.blocks.push_back(std::move(found.patch.blocks));
    patches_.planes.push_back(std::move(plane));
  }
}

}  // namespace mlmap
