// src/viewer/json_out.hpp — JSON text built by appending, for the viewer's messages.
//
// Contract: JsonOut appends numbers (fixed decimals), integers, keys (with the comma a list or
// object needs before them), separators and raw text to one string; take() hands it over. No
// escaping: keys and raw text must be JSON already (the viewer writes numbers, fixed names and
// base64).
#pragma once

#include <charconv>
#include <string>
#include <string_view>

#include "orbis/geometry/se3.hpp"

namespace orbis::viewer_detail {

// Appends JSON numbers and lists to one string, without a DOM: the messages are large and built
// several times a second.
class JsonOut {
 public:
  JsonOut& raw(std::string_view s) {
    text_ += s;
    return *this;
  }
  JsonOut& number(double v, int decimals = 4) {
    char buffer[48];
    const auto r = std::to_chars(buffer, buffer + sizeof buffer, v, std::chars_format::fixed, decimals);
    text_.append(buffer, r.ptr);
    return *this;
  }
  JsonOut& integer(long long v) {
    char buffer[24];
    const auto r = std::to_chars(buffer, buffer + sizeof buffer, v);
    text_.append(buffer, r.ptr);
    return *this;
  }
  JsonOut& key(std::string_view name) {
    if (!text_.empty() && text_.back() != '{' && text_.back() != '[') text_ += ',';
    text_ += '"';
    text_ += name;
    text_ += "\":";
    return *this;
  }
  JsonOut& separator() {
    if (text_.back() != '[' && text_.back() != '{') text_ += ',';
    return *this;
  }
  JsonOut& pose(const SE3d& Twc) {
    const Eigen::Matrix3d R = Twc.rotationMatrix();
    const Eigen::Vector3d t = Twc.translation();
    raw("[");
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) {
        if (r || c) raw(",");
        number(c < 3 ? R(r, c) : t(r), 5);
      }
    return raw("]");
  }
  std::string take() { return std::move(text_); }

 private:
  std::string text_;
};

}  // namespace orbis::viewer_detail
