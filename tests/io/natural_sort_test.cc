#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "io/fixtures.h"
#include "log_capture.h"
#include "patrolmap/core/csv.h"
#include "patrolmap/io/natural_sort.h"
#include "patrolmap/io/patrol_sensors.h"
#include "patrolmap/io/readers.h"
#include "patrolmap/io/yaml_file.h"
#include "test_util.h"

namespace patrolmap::io {
namespace {

TEST(NaturalSort, OrdersDigitRunsByValue) {
  std::vector<std::string> names = {"10.png", "2.png", "1.png", "img10.png", "img9.png", "a.png", "002.png"};
  NaturalSort(&names);
  const std::vector<std::string> expected = {"1.png", "002.png", "2.png", "10.png", "a.png", "img9.png", "img10.png"};
  EXPECT_EQ(names, expected);
}

}  // namespace
}  // namespace patrolmap::io
