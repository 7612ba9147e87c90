#include <gtest/gtest.h>

#include <limits>

#include "orbis/util/error.hpp"
#include "orbis/util/json.hpp"

TEST(JsonWriter, WritesNestedObjectsInOrder) {
  orbis::JsonWriter w;
  w.beginObject().field("rmse", 0.5).field("matched", std::size_t{3}).key("xs").beginArray();
  w.value(1).value(2).endArray().field("name", "a\"b").endObject();
  EXPECT_EQ(w.str(), R"({"rmse":0.5,"matched":3,"xs":[1,2],"name":"a\"b"})");
}

TEST(JsonWriter, NonFiniteBecomesNull) {
  orbis::JsonWriter w;
  w.beginObject().field("x", std::numeric_limits<double>::quiet_NaN()).endObject();
  EXPECT_EQ(w.str(), R"({"x":null})");
}

TEST(Error, NamesSourceAndLocation) {
  const orbis::Error e = orbis::keyError("cam.yaml", "Camera.fx", "missing");
  EXPECT_STREQ(e.what(), "cam.yaml, key Camera.fx: missing");
  EXPECT_EQ(orbis::lineError("gt.txt", 7, "bad").source(), "gt.txt");
}
