#include "colmap_ext/util/memory.h"

#include <malloc.h>

namespace portcal {

void KeepImageBuffersInTheHeap() {
  // Setting either disables glibc's dynamic threshold, which would only
  // raise it after the first few buffers had been mapped and faulted in.
  mallopt(M_MMAP_THRESHOLD, 64 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
}

}  // namespace portcal
