#include "patrolmap/pipeline/data_files.h"

#include <cstdlib>
#include <filesystem>
#include <vector>

namespace fs = std::filesystem;

namespace patrolmap::pipeline {
namespace {

constexpr const char* kVocabularyName = "default.pmvoc";

fs::path ExecutableFolder() {
  std::error_code error;
  const fs::path executable = fs::read_symlink("/proc/self/exe", error);
  return error ? fs::path() : executable.parent_path();
}

std::vector<fs::path> VocabularyPlaces() {
  std::vector<fs::path> places;
  if (const char* named = std::getenv(kVocabularyVariable); named != nullptr && *named != '\0') {
    places.emplace_back(named);
  }
  const fs::path executable_folder = ExecutableFolder();
  if (!executable_folder.empty()) {
    places.push_back(executable_folder.parent_path() / "share" / "patrolmap" / kVocabularyName);
  }
  places.push_back(fs::path(PATROLMAP_SOURCE_DIR) / "vocab" / kVocabularyName);
  places.push_back(fs::path(PATROLMAP_INSTALL_DATADIR) / "patrolmap" / kVocabularyName);
  return places;
}

}  // namespace

Status FindDefaultVocabulary(std::string* path) {
  std::string looked;
  for (const fs::path& place : VocabularyPlaces()) {
    std::error_code error;
    if (fs::is_regular_file(place, error)) {
      *path = place.string();
      return Status::Ok();
    }
    looked += (looked.empty() ? "" : ", ") + place.string();
  }
  return Status::NotFound(std::string("default vocabulary not found; looked in ") + looked + " (set " +
                          kVocabularyVariable + " or give --vocabulary)");
}

}  // namespace patrolmap::pipeline
