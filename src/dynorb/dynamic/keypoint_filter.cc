// KeypointFilter is an interface; this file anchors the module library.
#include "dynorb/dynamic/keypoint_filter.h"
