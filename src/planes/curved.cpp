#include "curved.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

namespace mlmap {
namespace {

// Patches closer to level than this are not looked at: their horizontal direction is
// ill-defined, and buildings' curved surfaces (pillars, bins, round walls) stand upright.
constexpr double kMaxLevelCos = std::numbers::sqrt2 / 2.0;  // 45°
// The parabola must explain at least this share of the points' squared distance from the
// plane (0.6 of it left at most). Facets on the simulated lab's and corridor's pillars and
// bins leave 0.20-0.52. On the 16 real maps of bench/real_data.py, of the patches that bend
// significantly by more than κ / 3, those on marked flat surfaces leave 0.72-0.76 (fr079's
// lower wall y4.52 at 5 cm: 61 blocks, a 9.9° bend; tilted_steps' slanted wall at 10 cm);
// without this test both were dropped. 3DTK's curved hall wall leaves 0.76-0.86 (its 3-4 cm
// of noise hide the bend) and keeps its facets at 5 cm; at 10 cm its largest (18.8 m²,
// 0.40) goes.
constexpr double kMaxLeftShare = 0.6;
// F statistic of the parabola's term over the patch's blocks (1 and B - 3 degrees of
// freedom): at 10, by chance in well under 1 % of flat patches of 12 blocks or more.
constexpr double kMinF = 10.0;
// A patch whose blocks bend is judged again without the blocks whose points lie beyond its
// band (ε) where those are at most this share of it: a flat wall's end where it meets
// another face (a door frame, a wall's lower face 9 cm in front) holds a few blocks of that
// face, which bend a parabola as a pillar does (OctoMap's fr079 with half its points at 5 cm
// cells: a 1.2 m² wall, 4 of its 58 blocks 9 cm off it, was dropped; tests/test_planes_curved.cpp
// holds one with 4 of 24). Where more lie off it the patch is no one surface there and is
// judged whole: 3DTK's hall at 5 and 10 cm cells, the largest bent patches 83-85 % off (with
// them judged on the rest, a 1,892-block patch stayed and the crease split cut it into 15).
constexpr double kMaxOffBandShare = 0.2;

struct Bend {
  double left_share = 1.0;  // squared distance left by the parabola / left by the plane
  double f = 0.0;           // F of the parabola's term over the blocks
  double turn = 0.0;        // rad, the normal's turn across the patch
};

// One block's points as the bend sees them.
struct Sample {
  double u = 0.0;  // m, across the patch, of the points' mean
  double d = 0.0;  // m, from the plane
  double weight = 0.0;  // points
  Eigen::Matrix3d scatter;  // Σ (p − mean)(p − mean)ᵀ
};

// The points' squared distances from their blocks' means along the normal of the curve
// d(u) there: a block on a bent surface holds an arc whose chord leans with the surface, so
// the plane's normal would count that lean as noise.
double withinSum(const std::vector<Sample>& samples, const Eigen::Vector3d& normal, const Eigen::Vector3d& across,
                 double slope, double slope_change) {
  double within = 0.0;
  for (const Sample& sample : samples) {
    const Eigen::Vector3d local = (normal - (slope + slope_change * sample.u) * across).normalized();
    within += local.dot(sample.scatter * local);
  }
  return within;
}

// The patch's blocks as the bend sees them, about its plane; none for a map without point
// moments.
std::vector<Sample> samplesOf(const BlockGrid& grid, const std::vector<std::uint32_t>& blocks, const Plane& plane,
                              const Eigen::Vector3d& normal, const Eigen::Vector3d& across) {
  std::vector<Sample> samples;
  samples.reserve(blocks.size());
  for (const std::uint32_t id : blocks) {
    const PointStats stats = grid.pointsOf(id);
    if (stats.empty()) return {};
    const Eigen::Vector3d mean = grid.pointsFrameOf(id) + stats.mean() - plane.centroid;
    samples.push_back({across.dot(mean), normal.dot(mean), static_cast<double>(stats.count), stats.scatterMatrix()});
  }
  return samples;
}

// The bend of a patch across its horizontal direction, from those of its blocks' samples
// within `band` (m) of its plane; left_share 1 where they are too few.
Bend bendOf(const std::vector<Sample>& all, const Eigen::Vector3d& normal, const Eigen::Vector3d& across, double band) {
  Bend bend;
  std::vector<Sample> samples;
  samples.reserve(all.size());
  Eigen::Matrix3d normal_matrix = Eigen::Matrix3d::Zero();  // Σ w [1 u u²]ᵀ[1 u u²]
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();            // Σ w [1 u u²]ᵀ d
  double sum_dd = 0.0;                                      // Σ w d²
  double low = std::numeric_limits<double>::infinity();
  double high = -low;
  for (const Sample& sample : all) {
    if (std::abs(sample.d) > band) continue;
    const Eigen::Vector3d terms(1.0, sample.u, sample.u * sample.u);
    normal_matrix += sample.weight * terms * terms.transpose();
    rhs += sample.weight * sample.d * terms;
    sum_dd += sample.weight * sample.d * sample.d;
    low = std::min(low, sample.u);
    high = std::max(high, sample.u);
    samples.push_back(sample);
  }
  if (samples.size() < 6) return bend;
  // Weighted least squares: what each fit leaves of the means is Σ w d² − bᵀ (Σ w t d).
  const Eigen::Vector2d line = normal_matrix.topLeftCorner<2, 2>().ldlt().solve(rhs.head<2>());
  const Eigen::Vector3d parabola = normal_matrix.ldlt().solve(rhs);
  if (!line.allFinite() || !parabola.allFinite()) return bend;
  const double left_line =
      std::max(0.0, sum_dd - line.dot(rhs.head<2>())) + withinSum(samples, normal, across, line(1), 0.0);
  const double left_parabola =
      std::max(0.0, sum_dd - parabola.dot(rhs)) + withinSum(samples, normal, across, parabola(1), 2.0 * parabola(2));
  if (!(left_line > 0.0)) return bend;
  bend.left_share = left_parabola / left_line;
  bend.f = left_parabola > 0.0
               ? (left_line - left_parabola) / (left_parabola / static_cast<double>(samples.size() - 3))
               : std::numeric_limits<double>::infinity();
  // d = a + b u + c u²: the slope moves by 2 c over each metre across, 2 |c| W in all.
  bend.turn = 2.0 * std::abs(parabola(2)) * (high - low);
  return bend;
}

bool isBent(const Bend& bend, double kappa_rad) {
  return bend.left_share <= kMaxLeftShare && bend.f >= kMinF && bend.turn > kappa_rad / 3.0;
}

}  // namespace

std::size_t dropCurved(const BlockGrid& grid, PatchSet& set, double kappa_rad, double band) {
  const std::size_t count = set.planes.size();
  std::vector<bool> drop(count, false);
  std::size_t dropped = 0;
  for (std::size_t k = 0; k < count; ++k) {
    const Plane& plane = set.planes[k];
    if (std::abs(plane.normal.normalized().z()) > kMaxLevelCos) continue;
    const Eigen::Vector3d normal = plane.normal.normalized();
    const Eigen::Vector3d across = Eigen::Vector3d(-normal.y(), normal.x(), 0.0).normalized();
    const std::vector<Sample> samples = samplesOf(grid, set.blocks[k], plane, normal, across);
    Bend bend = bendOf(samples, normal, across, std::numeric_limits<double>::infinity());
    if (isBent(bend, kappa_rad)) {
      const auto off_band = std::count_if(samples.begin(), samples.end(),
                                          [&](const Sample& sample) { return std::abs(sample.d) > band; });
      if (static_cast<double>(off_band) <= kMaxOffBandShare * static_cast<double>(samples.size()))
        bend = bendOf(samples, normal, across, band);
    }
    if (isBent(bend, kappa_rad)) {
      drop[k] = true;
      ++dropped;
    }
  }
  dropPatches(set, drop);
  return dropped;
}

}  // namespace mlmap
