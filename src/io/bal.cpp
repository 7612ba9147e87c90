#include "orbis/io/bal.hpp"

#include "orbis/util/error.hpp"

#include <cctype>
#include <charconv>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

namespace orbis {

namespace {

// Whitespace-separated numbers with the line each came from, for error messages.
class TokenReader {
 public:
  TokenReader(std::string text, std::string path) : text_(std::move(text)), path_(std::move(path)) {}

  template <class T>
  T next(const char* what) {
    skipSpace();
    if (pos_ >= text_.size()) throw lineError(path_, line_, std::string("unexpected end of file, expected ") + what);
    const char* first = text_.data() + pos_;
    const char* last = text_.data() + text_.size();
    T value{};
    const auto [end, ec] = std::from_chars(first, last, value);
    if (ec != std::errc() || (end != last && !std::isspace(static_cast<unsigned char>(*end)))) {
      std::size_t n = 0;
      while (first + n < last && !std::isspace(static_cast<unsigned char>(first[n])) && n < 32) ++n;
      throw lineError(path_, line_, std::string("expected ") + what + ", found '" + std::string(first, n) + "'");
    }
    pos_ = static_cast<std::size_t>(end - text_.data());
    return value;
  }
  std::size_t line() const { return line_; }
  bool atEnd() {
    skipSpace();
    return pos_ >= text_.size();
  }

 private:
  void skipSpace() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) {
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
  }
  std::string text_;
  std::string path_;
  std::size_t pos_ = 0;
  std::size_t line_ = 1;
};

}  // namespace

BalProblem readBal(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw fileError(file.string(), "cannot open BAL problem file");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  const std::size_t bytes = buffer.str().size();
  TokenReader reader(buffer.str(), file.string());

  const long numCameras = reader.next<long>("the number of cameras");
  const long numPoints = reader.next<long>("the number of points");
  const long numObservations = reader.next<long>("the number of observations");
  if (numCameras <= 0 || numPoints <= 0 || numObservations <= 0) {
    throw lineError(file.string(), 1, "expected positive counts of cameras, points and observations");
  }
  // Each number takes at least one byte: counts the file cannot hold are refused before anything
  // is allocated for them (a short file with plausible counts gets the more precise error below).
  const auto fits = [&](long count, long numbersEach) { return static_cast<std::size_t>(count) <= bytes / numbersEach; };
  if (!fits(numObservations, 4) || !fits(numCameras, 9) || !fits(numPoints, 3) ||
      static_cast<std::size_t>(4 * numObservations + 9 * numCameras + 3 * numPoints) > bytes) {
    throw lineError(file.string(), 1, "the counts (" + std::to_string(numCameras) + " cameras, " + std::to_string(numPoints) +
                                          " points, " + std::to_string(numObservations) +
                                          " observations) need more numbers than the file's " + std::to_string(bytes) +
                                          " bytes can hold");
  }
  BalProblem problem;
  problem.cameras.resize(numCameras);
  problem.points.resize(numPoints);
  problem.observations.resize(numObservations);
  for (auto& o : problem.observations) {
    o.camera = reader.next<int>("a camera index");
    o.point = reader.next<int>("a point index");
    if (o.camera < 0 || o.camera >= numCameras) {
      throw lineError(file.string(), reader.line(), "camera index " + std::to_string(o.camera) + " out of range");
    }
    if (o.point < 0 || o.point >= numPoints) {
      throw lineError(file.string(), reader.line(), "point index " + std::to_string(o.point) + " out of range");
    }
    o.x = reader.next<double>("an observation x");
    o.y = reader.next<double>("an observation y");
  }
  for (auto& c : problem.cameras) {
    for (int k = 0; k < 9; ++k) c[k] = reader.next<double>("a camera parameter");
  }
  for (auto& p : problem.points) {
    for (int k = 0; k < 3; ++k) p[k] = reader.next<double>("a point coordinate");
  }
  if (!reader.atEnd()) throw lineError(file.string(), reader.line(), "unexpected data after the last point");
  return problem;
}

void writeBal(const std::filesystem::path& file, const BalProblem& problem) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> out(std::fopen(file.c_str(), "w"), &std::fclose);
  if (!out) throw fileError(file.string(), "cannot open for writing");
  std::FILE* f = out.get();
  std::fprintf(f, "%zu %zu %zu\n", problem.cameras.size(), problem.points.size(), problem.observations.size());
  for (const auto& o : problem.observations) std::fprintf(f, "%d %d %.17g %.17g\n", o.camera, o.point, o.x, o.y);
  for (const auto& c : problem.cameras) {
    for (int k = 0; k < 9; ++k) std::fprintf(f, "%.17g\n", c[k]);
  }
  for (const auto& p : problem.points) {
    for (int k = 0; k < 3; ++k) std::fprintf(f, "%.17g\n", p[k]);
  }
  if (std::ferror(f)) throw fileError(file.string(), "write failed");
}

}  // namespace orbis
