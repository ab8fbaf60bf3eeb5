#include "register_report.hpp"

#include <cstdio>
#include <nlohmann/json.hpp>

#include "mlmap/io/atomic_file.hpp"

namespace mlmap::cli {
namespace {

nlohmann::json poseJson(const Pose& pose) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) {
    rows.push_back({pose.matrix()(r, 0), pose.matrix()(r, 1), pose.matrix()(r, 2), pose.matrix()(r, 3)});
  }
  return rows;
}

// Floors, ceilings and table tops, or walls and the rest: their matched points, the share
// of those explained and their residuals' robust spread.
nlohmann::json surfaceFitJson(const registration::SurfaceFit& fit) {
  return {{"matched", fit.matched},
          {"explained_share", fit.matched > 0 ? static_cast<double>(fit.explained) / static_cast<double>(fit.matched) : 0.0},
          {"residual_spread_m", fit.spread}};
}

}  // namespace

std::string verificationSummary(const registration::VerifiedIcp& result) {
  // Per kind of surface where both were matched: which of them the residuals come from.
  char kinds[96] = "";
  if (result.check.level.matched > 0 && result.check.upright.matched > 0) {
    std::snprintf(kinds, sizeof kinds, "; walls %.2f, floors and ceilings %.2f", 100.0 * result.check.upright.spread,
                  100.0 * result.check.level.spread);
  }
  char text[320];
  std::snprintf(text, sizeof text, "%s: %.0f %% explained, residual spread %.2f cm (expected %.2f cm%s), %d ICP run%s%s",
                result.verified        ? "verified"
                : result.unconstrained ? "UNCONSTRAINED (a direction is free)"
                : result.no_overlap    ? "NO OVERLAP"
                                       : "NOT VERIFIED",
                100.0 * result.check.explained_share,
                100.0 * result.check.spread, 100.0 * result.check.sigma, kinds, result.attempts,
                result.attempts == 1 ? "" : "s", result.icp.degenerate ? ", degenerate geometry" : "");
  return text;
}

void writeRegisterReport(const std::string& path, const std::vector<ScanReport>& scans,
                         const registration::RefinementResult* refinement) {
  nlohmann::json out;
  out["schema"] = "mlmap.register.report/1";
  out["scans"] = nlohmann::json::array();
  for (const ScanReport& scan : scans) {
    const registration::VerifiedIcp& r = scan.result;
    out["scans"].push_back({{"index", scan.index},
                            {"file", scan.file},
                            {"points", scan.points},
                            {"target", scan.index == 0 ? "none (first scan: anchors the map)" : "map of the scans before"},
                            {"start", poseJson(r.start)},
                            {"kept_start", poseJson(r.kept_start)},
                            {"result", poseJson(r.icp.pose)},
                            {"source_points", r.icp.source_points},
                            {"inliers", r.icp.inliers},
                            {"rms_residual_m", r.icp.rms_residual},
                            {"explained_share", r.check.explained_share},
                            {"residual_spread_m", r.check.spread},
                            {"level_surfaces", surfaceFitJson(r.check.level)},
                            {"upright_surfaces", surfaceFitJson(r.check.upright)},
                            {"expected_residual_m", r.check.sigma},
                            {"noise_m", r.noise},
                            {"source_noise_m", r.source_noise},
                            {"icp_runs", r.attempts},
                            {"retries", r.attempts > 0 ? r.attempts - 1 : 0},
                            {"ambiguous", r.ambiguous},
                            {"rival_runs", r.rival_runs},
                            {"rival_explained_share", r.rival_share},
                            {"rival_turn_deg", r.rival_turn_deg},
                            {"iterations", r.icp.iterations},
                            {"converged", r.icp.converged},
                            {"degenerate", r.icp.degenerate},
                            {"eigenvalue_ratio", r.icp.eigenvalue_ratio},
                            {"constrained_eigenvalue_ratio", r.check.eigenvalue_ratio},
                            {"rotation_eigenvalue_ratio", r.check.rotation_ratio},
                            {"slide_profile", {{"direction", {r.check.profile.direction.x(), r.check.profile.direction.y(),
                                                              r.check.profile.direction.z()}},
                                               {"facing_points", r.check.profile.facing},
                                               {"explained_at_result", r.check.profile.at_result},
                                               {"explained_away", r.check.profile.away},
                                               {"best_shift_m", r.check.profile.best_shift},
                                               {"peaked", r.check.profile.peaked}}},
                            {"slide_retries", r.slides},
                            {"slide_fit_m", r.slide_fit},
                            {"verified", r.verified},
                            {"unconstrained", r.unconstrained},
                            {"levelled_on_floor", scan.levelled_on_floor},
                            {"no_overlap", r.no_overlap},
                            {"reason", r.reason}});
  }
  if (refinement != nullptr) {
    out["refinement"] = {{"pair_edges", refinement->pair_edges},
                         {"loop_edges", refinement->loop_edges},
                         {"rejected_pairs", refinement->rejected_pairs},
                         {"unconstrained_pairs", refinement->unconstrained_pairs},
                         {"graph_cost_initial", refinement->graph.initial_cost},
                         {"graph_cost_final", refinement->graph.final_cost},
                         {"scan_residual_before_m2", refinement->residual_before},
                         {"scan_residual_after_m2", refinement->residual_after},
                         {"residual_change_sigmas", refinement->residual_change_sigmas},
                         {"scans_worse", refinement->scans_worse},
                         {"rounds_applied", refinement->rounds_applied}};
  }
  io::writeAtomically(path, [&](std::ostream& stream) { stream << out.dump(1) << '\n'; });
}

}  // namespace mlmap::cli
