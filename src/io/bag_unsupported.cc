// The bag readers a build was made without (src/io/CMakeLists.txt leaves a reader out when its library
// was missing at build time): a bag of that kind is refused with how to get the library.
#include "bag_file.h"

namespace patrolmap::io {

#ifndef PATROLMAP_HAVE_ROSBAG
bool Ros1BagsSupported() { return false; }

Status OpenRos1Bag(const std::string& path, std::unique_ptr<BagFile>*) {
  return Status::InvalidArgument(path +
                                 ": this patrolmap was built without ROS 1 bag support (Debian's "
                                 "librosbag-storage-dev was missing; scripts/install_deps.sh installs it, then "
                                 "rebuild)");
}
#endif

#ifndef PATROLMAP_HAVE_SQLITE3
bool Ros2BagsSupported() { return false; }

Status OpenRos2Bag(const std::string& folder, std::unique_ptr<BagFile>*) {
  return Status::InvalidArgument(folder +
                                 ": this patrolmap was built without ROS 2 bag support (Debian's libsqlite3-dev "
                                 "was missing; scripts/install_deps.sh installs it, then rebuild)");
}
#endif

}  // namespace patrolmap::io
