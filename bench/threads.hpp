// The OpenMP threads a benchmark runs on, printed beside its figures.
#pragma once

#ifdef _OPENMP
#include <omp.h>
#endif

namespace mlmap::bench {

inline int threadCount() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

}  // namespace mlmap::bench
