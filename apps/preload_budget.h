// `dynorb run --preload` keeps every decoded frame in memory; these say how much, and refuse a
// run that would take more than half of the machine's memory (one clear error instead of swapping
// or being killed half-way).
#pragma once

#include <cstddef>

namespace dynorb {

// Bytes of `frames` decoded width x height frames: 8-bit BGR + float depth, plus two 8-bit
// ground-truth masks (moving objects, objects standing still) when the dataset has them.
double PreloadBytes(size_t frames, int width, int height, bool with_masks);

// The machine's physical memory in bytes; 0 when it cannot be read.
double PhysicalMemoryBytes();

// Throws InputError ("--preload needs about X GB for N frames, more than half of this machine's
// memory (Y GB); ...") when `bytes` > machine_bytes / 2. machine_bytes <= 0 (unknown): accepted.
void CheckPreloadFits(size_t frames, double bytes, double machine_bytes);

}  // namespace dynorb
