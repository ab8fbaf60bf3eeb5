// libgomp's default is to spin up to 300 000 times at every barrier and at the end of
// every parallel region. On a machine whose cores other jobs share, a spinning thread
// takes the core the working one needs: `mlmap planes` with 2 threads ran 2.4x slower
// than with 1 (2 cm lab beside another CPU-bound job, issue 21), and as fast as 1
// thread with OMP_WAIT_POLICY=passive.
//
// libgomp reads OMP_WAIT_POLICY once, in its constructor, before main() runs, and offers
// no call to change the policy later. A setenv() in main() comes too late, and one in
// the executable's .preinit_array is lost: glibc sets `environ` from the process's own
// list after that array runs (measured on Debian 12's glibc 2.36). So the CLI starts
// itself again (execv of /proc/self/exe, a few milliseconds) with the variable set; if
// that fails it carries on with the default.
#include "passive_wait.hpp"

#include <unistd.h>

#include <cstdlib>

namespace mlmap::cli {

void preferPassiveWaiting(char** argv) {
#ifdef _OPENMP
  if (std::getenv("OMP_WAIT_POLICY") != nullptr || std::getenv("GOMP_SPINCOUNT") != nullptr) return;
  if (setenv("OMP_WAIT_POLICY", "passive", 1) != 0) return;
  ::execv("/proc/self/exe", argv);
#else
  (void)argv;
#endif
}

}  // namespace mlmap::cli
