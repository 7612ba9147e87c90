// Frame sources (adapters/frame_source.hpp) on small generated inputs: rendered frames written
// as image folders and encoded to videos inside the test, the live mailbox's newest-frame-wins
// policy with a slow consumer, and every bad input.
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <thread>

#include "orbis/adapters/frame_source.hpp"
#include "orbis/synth/sequence.hpp"
#include "orbis/util/error.hpp"

namespace fs = std::filesystem;
using orbis::Error;
using orbis::FrameSource;
using orbis::SourceFrame;
using orbis::SourceOptions;

namespace {

std::vector<cv::Mat> renderFrames(int count, int width = 160, int height = 120) {
  orbis::synth::SynthOptions o;
  o.frames = 150;
  o.width = width;
  o.height = height;
  o.fx = 0.8 * width;
  o.seed = 7;
  o.supersample = 1;
  orbis::synth::SyntheticSequence sequence(o);
  std::vector<cv::Mat> frames;
  for (int i = 0; i < count; ++i) frames.push_back(sequence.render(i, false, false).left);
  return frames;
}

std::vector<SourceFrame> readAll(FrameSource& source) {
  std::vector<SourceFrame> frames;
  while (auto f = source.next()) frames.push_back(std::move(*f));
  return frames;
}

double meanAbsDiff(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat ga = a, gb = b;
  if (a.channels() == 3) cv::cvtColor(a, ga, cv::COLOR_BGR2GRAY);
  if (b.channels() == 3) cv::cvtColor(b, gb, cv::COLOR_BGR2GRAY);
  cv::Mat diff;
  cv::absdiff(ga, gb, diff);
  return cv::mean(diff)[0];
}

class FrameSourceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() /
            ("orbis_sources_" + std::to_string(::getpid()) + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  void TearDown() override { fs::remove_all(root_); }

  // frame1.png ... frameN.png: name order differs from plain string order past frame9.
  fs::path writeFolder(const std::vector<cv::Mat>& frames, const std::string& name = "images") {
    const fs::path dir = root_ / name;
    fs::create_directories(dir);
    for (std::size_t i = 0; i < frames.size(); ++i)
      cv::imwrite((dir / ("frame" + std::to_string(i + 1) + ".png")).string(), frames[i]);
    return dir;
  }
  // Encodes grey frames as colour video; returns empty when this OpenCV cannot write the codec.
  fs::path writeVideo(const std::vector<cv::Mat>& frames, const std::string& file, const char* fourcc, double fps) {
    const fs::path path = root_ / file;
    cv::VideoWriter writer(path.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc(fourcc[0], fourcc[1], fourcc[2], fourcc[3]),
                           fps, frames.front().size(), true);
    if (!writer.isOpened()) return {};
    for (const cv::Mat& f : frames) {
      cv::Mat bgr;
      cv::cvtColor(f, bgr, cv::COLOR_GRAY2BGR);
      writer.write(bgr);
    }
    return path;
  }
  fs::path root_;
};

TEST_F(FrameSourceTest, ImageFolderInNameOrderAtTheGivenRate) {
  const auto frames = renderFrames(12);
  const fs::path dir = writeFolder(frames);
  SourceOptions options;
  options.fps = 10;
  auto source = orbis::openImageFolderSource(dir, options);
  EXPECT_FALSE(source->live());
  EXPECT_EQ(source->sensor(), orbis::SensorKind::Monocular);
  ASSERT_EQ(source->expectedFrames(), std::optional<std::size_t>(12));
  const auto read = readAll(*source);
  ASSERT_EQ(read.size(), 12u);
  for (std::size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].index, i);
    EXPECT_DOUBLE_EQ(read[i].timestamp, static_cast<double>(i) / 10.0);
    EXPECT_EQ(meanAbsDiff(read[i].image, frames[i]), 0.0) << "frame " << i << " out of name order";
  }
  EXPECT_TRUE(source->warnings().empty());
}

TEST_F(FrameSourceTest, ImageFolderTimesFromTheListInNanosecondsOrAssumed) {
  const auto frames = renderFrames(4);
  const fs::path dir = writeFolder(frames);
  {
    auto source = orbis::openImageFolderSource(dir);
    const auto read = readAll(*source);
    ASSERT_EQ(read.size(), 4u);
    EXPECT_DOUBLE_EQ(read[3].timestamp, 3.0 / 30.0);
    ASSERT_EQ(source->warnings().size(), 1u) << "an assumed frame rate must be said";
    EXPECT_NE(source->warnings()[0].find("30 fps"), std::string::npos);
  }
  std::ofstream(dir / "times.txt") << "# ns\n1403636579763555584\n1403636579813555456\n1403636579863555584\n1403636579913555456\n";
  auto source = orbis::openImageFolderSource(dir);
  const auto read = readAll(*source);
  ASSERT_EQ(read.size(), 4u);
  EXPECT_NEAR(read[0].timestamp, 1403636579.763555584, 1e-6);
  EXPECT_NEAR(read[3].timestamp - read[0].timestamp, 0.15, 1e-6);
  EXPECT_TRUE(source->warnings().empty());
}

TEST_F(FrameSourceTest, ImageFolderTimesFromTimestampNames) {
  const auto frames = renderFrames(3);
  const fs::path dir = root_ / "tum";
  fs::create_directories(dir);
  // Fractions of different widths: ordered by value, not by digits.
  const char* names[] = {"1311868164.25.png", "1311868164.3.png", "1311868164.430940.png"};
  for (int i = 0; i < 3; ++i) cv::imwrite((dir / names[i]).string(), frames[i]);
  const auto read = readAll(*orbis::openImageFolderSource(dir));
  ASSERT_EQ(read.size(), 3u);
  EXPECT_DOUBLE_EQ(read[1].timestamp, 1311868164.3);
  EXPECT_EQ(meanAbsDiff(read[1].image, frames[1]), 0.0);
}

TEST_F(FrameSourceTest, SideBySideAndTopBottomStereoAreSplit) {
  const auto frames = renderFrames(2);
  std::vector<cv::Mat> packed;
  for (const cv::Mat& f : frames) {
    cv::Mat pair;
    cv::hconcat(f, 255 - f, pair);
    packed.push_back(pair);
  }
  SourceOptions options;
  options.stereo = orbis::StereoPacking::SideBySide;
  auto source = orbis::openImageFolderSource(writeFolder(packed), options);
  EXPECT_EQ(source->sensor(), orbis::SensorKind::Stereo);
  const auto read = readAll(*source);
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(meanAbsDiff(read[1].image, frames[1]), 0.0);
  EXPECT_EQ(meanAbsDiff(read[1].right, 255 - frames[1]), 0.0);

  std::vector<cv::Mat> stacked;
  for (const cv::Mat& f : frames) {
    cv::Mat pair;
    cv::vconcat(f, 255 - f, pair);
    stacked.push_back(pair);
  }
  options.stereo = orbis::StereoPacking::TopBottom;
  const auto tb = readAll(*orbis::openImageFolderSource(writeFolder(stacked, "tb"), options));
  ASSERT_EQ(tb.size(), 2u);
  EXPECT_EQ(meanAbsDiff(tb[0].right, 255 - frames[0]), 0.0);
  EXPECT_THROW(orbis::parseStereoPacking("diagonal"), Error);
}

TEST_F(FrameSourceTest, StereoFromTwoFoldersPairsFrameByFrame) {
  const auto frames = renderFrames(3);
  std::vector<cv::Mat> inverted;
  for (const cv::Mat& f : frames) inverted.push_back(255 - f);
  SourceOptions options;
  options.fps = 20;
  auto pair = orbis::makeStereoPairSource(orbis::openImageFolderSource(writeFolder(frames, "left"), options),
                                          orbis::openImageFolderSource(writeFolder(inverted, "right"), options));
  EXPECT_EQ(pair->sensor(), orbis::SensorKind::Stereo);
  const auto read = readAll(*pair);
  ASSERT_EQ(read.size(), 3u);
  EXPECT_EQ(meanAbsDiff(read[2].right, inverted[2]), 0.0);
  EXPECT_DOUBLE_EQ(read[2].timestamp, 0.1);
  EXPECT_TRUE(pair->endReason().empty());
}

TEST_F(FrameSourceTest, RgbdFoldersPairedByTimestamp) {
  const auto frames = renderFrames(3);
  const fs::path colour = writeFolder(frames, "colour");
  const fs::path depth = root_ / "depth";
  fs::create_directories(depth);
  for (int i = 0; i < 3; ++i)
    cv::imwrite((depth / ("d" + std::to_string(i) + ".png")).string(), cv::Mat(frames[0].size(), CV_16UC1, cv::Scalar(1000 * (i + 1))));
  std::ofstream(colour / "times.txt") << "1.000\n1.033\n1.066\n";
  std::ofstream(depth / "times.txt") << "1.001\n1.035\n1.200\n";  // the third depth map is too late
  auto source = orbis::openRgbdFolderSource(colour, depth);
  EXPECT_EQ(source->sensor(), orbis::SensorKind::Rgbd);
  const auto read = readAll(*source);
  ASSERT_EQ(read.size(), 3u);
  EXPECT_EQ(read[1].depth.at<std::uint16_t>(0, 0), 2000);
  EXPECT_TRUE(read[2].depth.empty());
  EXPECT_FALSE(read[2].warnings.empty());
}

TEST_F(FrameSourceTest, MjpegVideoDecodesWithContainerTimes) {
  const auto frames = renderFrames(10);
  const fs::path video = writeVideo(frames, "clip.avi", "MJPG", 15.0);
  ASSERT_FALSE(video.empty()) << "OpenCV cannot write MJPG/avi";
  auto source = orbis::openVideoSource(video.string());
  EXPECT_FALSE(source->live());
  EXPECT_EQ(source->name(), "video:" + video.string());
  const auto read = readAll(*source);
  ASSERT_EQ(read.size(), 10u);
  for (std::size_t i = 0; i < read.size(); ++i) {
    EXPECT_NEAR(read[i].timestamp, static_cast<double>(i) / 15.0, 1e-3);
    EXPECT_LT(meanAbsDiff(read[i].image, frames[i]), 4.0) << "frame " << i;
  }
  EXPECT_TRUE(source->endReason().empty());
}

TEST_F(FrameSourceTest, VideoTimesFromFpsOrAList) {
  const auto frames = renderFrames(5);
  const fs::path video = writeVideo(frames, "clip.avi", "MJPG", 15.0);
  ASSERT_FALSE(video.empty());
  SourceOptions options;
  options.fps = 5;
  options.grey = true;
  auto read = readAll(*orbis::openVideoSource(video.string(), options));
  ASSERT_EQ(read.size(), 5u);
  EXPECT_DOUBLE_EQ(read[4].timestamp, 0.8);
  EXPECT_EQ(read[4].image.channels(), 1);

  // A list shorter than the video ends it there, and says so.
  std::ofstream(root_ / "rgb.txt") << "# timestamp filename\n100.5 rgb/a.png\n100.6 rgb/b.png\n100.7 rgb/c.png\n";
  options = {};
  options.timesFile = root_ / "rgb.txt";
  auto source = orbis::openVideoSource(video.string(), options);
  read = readAll(*source);
  ASSERT_EQ(read.size(), 3u);
  EXPECT_DOUBLE_EQ(read[2].timestamp, 100.7);
  EXPECT_NE(source->endReason().find("more frames than"), std::string::npos);
}

TEST_F(FrameSourceTest, Mpeg4VideoDecodesWhenTheCodecIsThere) {
  const auto frames = renderFrames(6);
  const fs::path video = writeVideo(frames, "clip.mp4", "mp4v", 30.0);
  if (video.empty()) GTEST_SKIP() << "this OpenCV writes no mp4v";
  const auto read = readAll(*orbis::openVideoSource(video.string()));
  ASSERT_EQ(read.size(), 6u);
  EXPECT_NEAR(read[5].timestamp, 5.0 / 30.0, 1e-3);
  EXPECT_LT(meanAbsDiff(read[5].image, frames[5]), 8.0);
}

TEST_F(FrameSourceTest, BadInputsNameWhatIsWrong) {
  const auto expectError = [](const auto& open, const std::string& named, const std::string& problem) {
    try {
      open();
      ADD_FAILURE() << "no error for " << named;
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(named), std::string::npos) << what;
      EXPECT_NE(what.find(problem), std::string::npos) << what;
    }
  };
  const fs::path missing = root_ / "missing";
  expectError([&] { orbis::openImageFolderSource(missing); }, missing.string(), "no such folder");
  fs::create_directories(root_ / "empty");
  std::ofstream(root_ / "empty" / "notes.txt") << "no images here\n";
  expectError([&] { orbis::openImageFolderSource(root_ / "empty"); }, (root_ / "empty").string(), "holds no image");
  const fs::path garbage = root_ / "garbage.mp4";
  std::ofstream(garbage) << "this is not a video at all";
  expectError([&] { orbis::openImageFolderSource(garbage); }, garbage.string(), "is not a folder");
  expectError([&] { orbis::openVideoSource((root_ / "none.mp4").string()); }, "none.mp4", "no such video file");
  expectError([&] { orbis::openVideoSource(garbage.string()); }, garbage.string(), "cannot be opened as a video");
  expectError([&] { orbis::openVideoSource(root_.string()); }, root_.string(), "is a folder");
  expectError([&] { orbis::openCameraSource("/dev/video97"); }, "/dev/video97", "no such camera");
  expectError([&] { orbis::openCameraSource("97"); }, "/dev/video97", "no such camera");

  // A timestamp list with a bad line, or too short for the images.
  const fs::path dir = writeFolder(renderFrames(3));
  std::ofstream(dir / "times.txt") << "0.1\nsoon\n0.3\n";
  expectError([&] { orbis::openImageFolderSource(dir); }, "times.txt, line 2", "expected a timestamp");
  std::ofstream(dir / "times.txt") << "0.1\n0.2\n";
  expectError([&] { orbis::openImageFolderSource(dir); }, "times.txt", "lists 2 timestamps for the 3 images");

  // An undecodable image is an error of its frame only: the next one still comes.
  fs::remove(dir / "times.txt");
  std::ofstream(dir / "frame2.png") << "truncated";
  auto source = orbis::openImageFolderSource(dir);
  EXPECT_TRUE(source->next().has_value());
  expectError([&] { source->next(); }, "frame2.png", "cannot be read as an image");
  EXPECT_TRUE(source->next().has_value());
}

// A source that makes `count` frames as fast as it is asked, 1 ms apart in time.
class CountingSource final : public FrameSource {
 public:
  explicit CountingSource(std::size_t count, std::chrono::milliseconds before = {}) : count_(count), before_(before) {}
  std::optional<SourceFrame> next() override {
    std::this_thread::sleep_for(before_);
    if (i_ >= count_) return std::nullopt;
    SourceFrame f;
    f.index = i_;
    f.timestamp = 0.001 * static_cast<double>(i_++);
    f.image = cv::Mat(4, 4, CV_8UC1, cv::Scalar(0));
    return f;
  }
  std::string name() const override { return "counting"; }

 private:
  std::size_t count_, i_ = 0;
  std::chrono::milliseconds before_;
};

TEST(LiveSourceTest, SlowConsumerGetsTheNewestFrameAndTheDropsAreCounted) {
  auto live = orbis::makeLiveSource(std::make_unique<CountingSource>(200), false);
  EXPECT_TRUE(live->live());
  std::vector<std::size_t> delivered;
  while (auto f = live->next()) {
    delivered.push_back(f->index);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));  // tracking slower than the camera
  }
  ASSERT_FALSE(delivered.empty());
  EXPECT_GT(live->dropped(), 0u);
  EXPECT_EQ(delivered.size() + live->dropped(), 200u) << "every frame is either delivered or counted as dropped";
  EXPECT_EQ(delivered.back(), 199u) << "the newest frame wins";
  for (std::size_t k = 1; k < delivered.size(); ++k) EXPECT_GT(delivered[k], delivered[k - 1]);
  EXPECT_TRUE(live->endReason().empty());
}

TEST(LiveSourceTest, PacedPlaybackDeliversInOrderAndAccountsForEveryFrame) {
  auto live = orbis::makeLiveSource(std::make_unique<CountingSource>(20), true);
  std::size_t delivered = 0;
  std::optional<std::size_t> last;
  while (auto f = live->next()) {
    if (last) EXPECT_GT(f->index, *last);
    last = f->index;
    ++delivered;
  }
  EXPECT_EQ(delivered + live->dropped(), 20u);
}

TEST(LiveSourceTest, AStalledSourceEndsWithAReasonAndCancelEndsAtOnce) {
  {
    auto live = orbis::makeLiveSource(std::make_unique<CountingSource>(1, std::chrono::milliseconds(600)), false, 0.2);
    EXPECT_FALSE(live->next().has_value());
    EXPECT_NE(live->endReason().find("counting delivered no frame for 0.2 s"), std::string::npos) << live->endReason();
  }
  auto live = orbis::makeLiveSource(std::make_unique<CountingSource>(1, std::chrono::milliseconds(600)), false, 60);
  std::atomic<bool> cancelled{true};
  live->setCancelCheck([&] { return cancelled.load(); });
  EXPECT_FALSE(live->next().has_value());
}

}  // namespace
