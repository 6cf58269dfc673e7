// Fuzzes the vocabulary file reader and, when a file loads, quantises a few descriptors with it. An input
// whose first byte is odd gets its checksum recomputed first (see map_file_fuzz.cc).
#include <cstddef>
#include <cstdint>
#include <string>

#include <opencv2/core.hpp>

#include "fuzz_files.h"
#include "patrolmap/vocab/vocabulary.h"
#include "recompute_checksums.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto folder = patrolmap::fuzz::FreshFolder();
  std::string bytes(reinterpret_cast<const char*>(data), size);
  if (size > 0 && (data[0] & 1) != 0) {
    bytes[0] = 'P';  // the magic's first byte
    patrolmap::testing::RecomputeVocabularyChecksum(&bytes);
  }
  patrolmap::fuzz::WriteBytes(folder / "in.pmvoc", bytes);
  patrolmap::vocab::Vocabulary vocabulary;
  if (!patrolmap::vocab::Vocabulary::Load((folder / "in.pmvoc").string(), &vocabulary).ok()) return 0;
  cv::Mat descriptors(3, vocabulary.dimension(), CV_32F);
  cv::randu(descriptors, 0.0f, 1.0f);
  patrolmap::vocab::BowVector bow;
  vocabulary.Transform(descriptors, &bow);
  return 0;
}
