// Internal to the OcTree layer: the OpenMP team size and thread number, 1 and 0 when
// built without OpenMP.
#pragma once

#ifdef _OPENMP
#include <omp.h>
#endif

namespace mlmap::detail {

inline int threadCount() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

inline int threadIndex() {
#ifdef _OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}

}  // namespace mlmap::detail
