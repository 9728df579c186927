#pragma once

// Shared test helper: assert that a call throws a given exception type whose message contains a
// fragment (our error messages name the field and the rule, so tests check the words).

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace devsurf::testing {

template <class Exception = std::invalid_argument, class F>
void expectThrowMentioning(F call, const std::string& fragment) {
  try {
    call();
    ADD_FAILURE() << "expected an exception mentioning \"" << fragment << "\"";
  } catch (const Exception& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << "message was: " << e.what();
  }
}

}  // namespace devsurf::testing
