#include "dynorb/synth/renderer.h"

#include <gtest/gtest.h>

#include "dynorb/core/pinhole_camera.h"

namespace dynorb::synth {
namespace {

TEST(Renderer, Placeholder) { EXPECT_TRUE(true); }

}  // namespace
}  // namespace dynorb::synth
