// Process-wide allocator settings.
#pragma once

namespace portcal {

// Keeps the image-sized buffers that every image's decoding and detection
// allocates and frees (a few MB each) in the heap instead of glibc's
// default of a fresh mmap each time: each fresh mapping is page-faulted in
// again, which took a fifth of target_extractor's time on 1080p images
// (docs/benchmarks_target_detection.md). Buffers above 64 MB are still mapped; freed memory
// beyond 256 MB is returned to the system.
void KeepImageBuffersInTheHeap();

}  // namespace portcal
