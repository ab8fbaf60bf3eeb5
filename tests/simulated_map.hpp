// A simulated scene mapped as `mlmap build` maps scans, shared by the plane-detection
// tests that scan their scenes with the simulator.
#pragma once

#include "mlmap/map/ml_map.hpp"
#include "mlmap/sim/scene.hpp"
#include "mlmap/sim/simulator.hpp"

namespace mlmap::test {

// Every simulated scan of `scene` (true poses) inserted into one map of `cell_size` cells.
inline MLMap simulatedMap(const sim::Scene& scene, double cell_size) {
  MLMap map(cell_size);
  for (const sim::SimulatedScan& simulated : sim::simulate(scene)) map.insertScan(simulated.scan);
  return map;
}

}  // namespace mlmap::test
