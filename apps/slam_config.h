// The SLAM core's sections of a `dynorb run` config (place_recognition, loop_closing, tracking,
// mapping; optional, the defaults are ORB-SLAM2's RGB-D values) and the SystemOptions a run is
// made with: the camera and ORB settings of the config, the command line's seed, run mode and
// front-end threads, and the sections' bound options.
#pragma once

#include <string>

#include "dynorb/io/config.h"
#include "dynorb/io/config_schema.h"
#include "dynorb/system/system.h"
#include "run_pipeline.h"

namespace dynorb {

// Binds the four sections to *t, *m, *sys (its place recognition and loop closing) and
// *vocabulary_path in *schema; each section validates its options once loaded.
void BindSlamSections(TrackerOptions* t, LocalMapperOptions* m, SystemOptions* sys,
                      std::string* vocabulary_path, ConfigSchema* schema);

// `bound` (the sections' SystemOptions) with the tracker, mapper, camera, ORB and command-line
// settings filled in.
SystemOptions MakeSystemOptions(const SystemConfig& config, const RunRequest& cli,
                                const TrackerOptions& tracker, const LocalMapperOptions& mapper,
                                const SystemOptions& bound);

}  // namespace dynorb
