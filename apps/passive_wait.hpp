// OpenMP threads that sleep while they wait, unless the user chose otherwise.
#pragma once

namespace mlmap::cli {

// Call first thing in main(): without OMP_WAIT_POLICY or GOMP_SPINCOUNT in the
// environment, sets OMP_WAIT_POLICY=passive and starts the program again with it.
void preferPassiveWaiting(char** argv);

}  // namespace mlmap::cli
