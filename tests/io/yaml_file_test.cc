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

using testing::TempDir;
using testing::WriteText;

// YAML forbids a key twice in one map, and yaml-cpp would keep one silently: refused at any depth, naming
// the file, line and key (sensor.yaml, meta.yaml and configurations all load this way).
TEST(Yaml, ARepeatedKeyIsRefusedNamingFileLineAndKey) {
  TempDir dir;
  YAML::Node root;
  WriteText(dir / "a.yaml", "rate_hz: 20\nT_BS:\n  rows: 4\n  rows: 5\n");
  Status status = LoadYamlFile(dir / "a.yaml", &root);
  EXPECT_NE(status.message().find("a.yaml:4: key 'rows' appears twice in one map"), std::string::npos)
      << status.message();
  WriteText(dir / "b.yaml", "- {x: 1}\n- {x: 1, x: 2}\n");
  EXPECT_NE(LoadYamlFile(dir / "b.yaml", &root).message().find("b.yaml:2: key 'x' appears twice"), std::string::npos);
  WriteText(dir / "d.yaml", "flow:\n  ? {edges: 1}\n  : 2\n");  // a map as a key (fuzzing found it threw)
  EXPECT_NE(LoadYamlFile(dir / "d.yaml", &root).message().find("d.yaml:2: a key must be a plain name"),
            std::string::npos)
      << LoadYamlFile(dir / "d.yaml", &root).message();
  WriteText(dir / "c.yaml", "a: {x: 1}\nb: {x: 1}\n");  // the same key in two maps is fine
  EXPECT_TRUE(LoadYamlFile(dir / "c.yaml", &root).ok());
}

}  // namespace
}  // namespace patrolmap::io
