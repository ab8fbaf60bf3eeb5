// `mlmap register --report FILE`: the per-scan figures of the registration as JSON
// (schema "mlmap.register.report/1"): per scan its start, result, inliers, the explained
// share, the residual spread against the measured noise, the ICP runs and whether it was
// verified; the refinement's edges and residuals.
#pragma once

#include <string>
#include <vector>

#include "mlmap/registration/sequence_registration.hpp"

namespace mlmap::cli {

struct ScanReport {
  std::size_t index = 0;
  std::string file;
  std::size_t points = 0;
  registration::VerifiedIcp result;
  bool levelled_on_floor = false;  // SequenceRegistration::levelledOnFloor
};

// Written atomically; `refinement` may be null (--no-refine).
void writeRegisterReport(const std::string& path, const std::vector<ScanReport>& scans,
                         const registration::RefinementResult* refinement);

// One line for stderr: "verified" or "NOT VERIFIED: why", with the figures behind it.
std::string verificationSummary(const registration::VerifiedIcp& result);

}  // namespace mlmap::cli
