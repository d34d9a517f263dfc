// Test helper: expects a callable to throw InputError whose message contains a given text.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "dynorb/core/error.h"

namespace dynorb::testing {

template <typename Fn>
void ExpectInputError(Fn&& fn, const std::string& needle) {
  try {
    fn();
    ADD_FAILURE() << "no InputError; expected one containing: " << needle;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos)
        << "message: " << e.what() << "\nexpected to contain: " << needle;
  }
}

}  // namespace dynorb::testing
