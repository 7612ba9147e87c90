// tests/calibration/error_message.hpp — the message of the orbis::Error a call throws, for tests
// that check what a refusal says.
#pragma once

#include <functional>
#include <string>

#include "orbis/util/error.hpp"

namespace orbis::calibration {

// What f throws as orbis::Error, or "no error".
inline std::string messageOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace orbis::calibration
