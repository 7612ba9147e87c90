// Sensor names: every accepted spelling in any letter case, the canonical name parsing back, and
// an unknown name as an orbis::Error naming its origin and the accepted names.
#include <string>

#include <gtest/gtest.h>

#include "orbis/camera/sensor_kind.hpp"
#include "orbis/util/error.hpp"

namespace orbis {
namespace {

TEST(SensorKindNames, EverySpellingInAnyCase) {
  for (const char* name : {"mono", "monocular", "Mono", "MONOCULAR"}) {
    EXPECT_EQ(parseSensorKind(name), SensorKind::Monocular) << name;
  }
  for (const char* name : {"stereo", "Stereo", "STEREO"}) EXPECT_EQ(parseSensorKind(name), SensorKind::Stereo) << name;
  // The two parsers this one replaced disagreed here: the dataset one refused "rgb-d".
  for (const char* name : {"rgbd", "rgb-d", "RGB-D", "RGBD", "Rgb-D"}) {
    EXPECT_EQ(parseSensorKind(name), SensorKind::Rgbd) << name;
  }
}

TEST(SensorKindNames, CanonicalNameParsesBack) {
  for (SensorKind kind : {SensorKind::Monocular, SensorKind::Stereo, SensorKind::Rgbd}) {
    EXPECT_EQ(parseSensorKind(toString(kind)), kind) << toString(kind);
  }
  EXPECT_EQ(toString(SensorKind::Rgbd), "rgbd");
}

TEST(SensorKindNames, UnknownNameIsAnErrorNamingItsOrigin) {
  for (const char* name : {"lidar", "", "rgb_d", " mono", "stereo2"}) {
    try {
      parseSensorKind(name, "settings.yaml", "key Sensor");
      ADD_FAILURE() << '"' << name << "\" parsed";
    } catch (const Error& e) {
      EXPECT_EQ(e.source(), "settings.yaml");
      EXPECT_EQ(e.where(), "key Sensor");
      const std::string message = e.what();
      EXPECT_NE(message.find("unknown sensor \"" + std::string(name) + "\""), std::string::npos) << message;
      EXPECT_NE(message.find("(expected mono, monocular, stereo, rgbd or rgb-d; any letter case)"), std::string::npos)
          << message;
    }
  }
}

}  // namespace
}  // namespace orbis
