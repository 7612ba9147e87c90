// orbis/util/json.hpp — a minimal JSON object writer for machine-readable program output.
//
// Contract: builds one JSON value in insertion order; numbers are written with enough digits
// to round-trip a double; non-finite numbers become null (JSON has no NaN). Not a parser.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

namespace orbis {

// Builds one JSON value by appending objects, arrays, keys and values in order.
class JsonWriter {
 public:
  // @{
  // Opens or closes an object or an array.
  JsonWriter& beginObject() { separate(); out_ += '{'; first_.push_back(true); return *this; }
  JsonWriter& endObject() { out_ += '}'; first_.pop_back(); return *this; }
  JsonWriter& beginArray() { separate(); out_ += '['; first_.push_back(true); return *this; }
  JsonWriter& endArray() { out_ += ']'; first_.pop_back(); return *this; }
  // @}

  // Writes an object's key; the next value is its value.
  JsonWriter& key(std::string_view k) {
    separate();
    writeString(k);
    out_ += ':';
    afterKey_ = true;
    return *this;
  }
  // @{
  // Writes a value (non-finite numbers as null).
  JsonWriter& value(double v) {
    separate();
    if (!std::isfinite(v)) { out_ += "null"; return *this; }
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    out_ += buf;
    return *this;
  }
  JsonWriter& value(std::int64_t v) { separate(); out_ += std::to_string(v); return *this; }
  JsonWriter& value(int v) { return value(static_cast<std::int64_t>(v)); }
  JsonWriter& value(std::size_t v) { separate(); out_ += std::to_string(v); return *this; }
  JsonWriter& value(bool v) { separate(); out_ += v ? "true" : "false"; return *this; }
  JsonWriter& value(std::string_view v) { separate(); writeString(v); return *this; }
  JsonWriter& value(const char* v) { return value(std::string_view(v)); }
  JsonWriter& null() { separate(); out_ += "null"; return *this; }
  // @}

  // Writes a key and its value.
  template <typename T>
  JsonWriter& field(std::string_view k, const T& v) { key(k); return value(v); }

  // The JSON text so far.
  const std::string& str() const { return out_; }

 private:
  void separate() {
    if (afterKey_) { afterKey_ = false; return; }
    if (!first_.empty()) {
      if (!first_.back()) out_ += ',';
      first_.back() = false;
    }
  }
  void writeString(std::string_view s) {
    out_ += '"';
    for (char c : s) {
      switch (c) {
        case '"': out_ += "\\\""; break;
        case '\\': out_ += "\\\\"; break;
        case '\n': out_ += "\\n"; break;
        case '\t': out_ += "\\t"; break;
        case '\r': out_ += "\\r"; break;
        default:
          if (static_cast<unsigned char>(c) < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\u%04x", c);
            out_ += buf;
          } else {
            out_ += c;
          }
      }
    }
    out_ += '"';
  }
  std::string out_;
  std::vector<bool> first_;
  bool afterKey_ = false;
};

}  // namespace orbis
